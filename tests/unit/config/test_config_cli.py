"""The config verbs as a user types them: exit codes, output, and `error: ...` instead of tracebacks."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from kinema.cli.main import main


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_init_configure_new_show_list_round_trip(capsys, tmp_path: Path):
    workspace = tmp_path / "my_ws"
    code, out, _ = run(capsys, "init", str(workspace))
    assert code == 0 and (workspace / "src").is_dir()
    # Both ways on: a config from one's own URDF first, the bundled lab as the other.
    assert f"kinema new config NAME -w {workspace} --from-urdf URDF" in out
    assert f"kinema configure -w {workspace} -c lab_sim" in out
    code, out, _ = run(capsys, "configure", "-w", str(workspace), "-c", "lab_sim")
    assert code == 0 and "config:    lab_sim" in out
    code, out, _ = run(capsys, "new", "config", "my_cell", "--based-on", "lab_sim", "--no-input")
    assert code == 0, out
    assert (workspace / "src" / "my_cell" / "config" / "config.yaml").is_file()
    code, out, _ = run(capsys, "config", "show", "-c", "my_cell", "--json", "--provenance")
    assert code == 0
    shown = json.loads(out)
    assert shown["chain"] == ["lab_sim", "my_cell"]
    assert shown["config"]["based_on_package"] == "lab_sim"
    assert shown["provenance"]["objectives.objective_library_paths.my_cell_objectives"] == "my_cell"
    assert shown["provenance"]["hardware.robot_description.urdf"] == "lab_sim"
    code, out, _ = run(capsys, "config", "list")
    assert code == 0
    lines = {line.split()[1] if line.startswith("*") else line.split()[0]: line for line in out.splitlines()}
    assert lines["lab_sim"].startswith("*")  # the active config
    assert "my_cell" in lines and "lab_sim" in lines["my_cell"]
    code, out, _ = run(capsys, "config", "chain", "-c", "my_cell")
    assert code == 0 and [line.split()[0] for line in out.splitlines()] == ["lab_sim", "my_cell"]
    code, out, _ = run(capsys, "objective", "list", "-c", "my_cell", "--json")
    assert code == 0
    assert {"Open Gripper", "Close Gripper"} <= {o["id"] for o in json.loads(out)["objectives"]}


def test_config_show_yaml_with_provenance_comments(capsys):
    code, out, _ = run(capsys, "config", "show", "-c", "example_config", "--provenance")
    assert code == 0
    assert out.startswith("# config example_config (chain: lab_sim → example_config)")
    assert "  joint_group_name: manipulator  # lab_sim" in out
    assert "      - kinema::CoreBehaviorsLoader  # lab_sim" in out
    assert (
        "example_objectives: {package_name: example_config, relative_path: objectives}  # example_config"
        in out
    )


def test_config_show_plain_yaml_reads_back(capsys):
    import yaml

    code, out, _ = run(capsys, "config", "show", "-c", "lab_sim")
    assert code == 0
    data = yaml.safe_load(out)
    assert data["objectives"]["waypoints_file"]["relative_path"] == "waypoints/lab_sim_waypoints.yaml"


def test_objective_show_prints_metadata_ports_and_xml(capsys):
    code, out, _ = run(capsys, "objective", "show", "Open and Close Gripper", "-c", "example_config")
    assert code == 0
    assert "open_and_close_gripper.xml:" in out
    assert "favorite:    yes" in out
    assert '<SubTree ID="Open Gripper" />' in out
    code, out, _ = run(capsys, "objective", "show", "Open Gripper", "-c", "lab_sim", "--xml")
    assert code == 0 and out.startswith("<?xml")


def test_verbose_prints_notices(capsys, tmp_path: Path):
    run(capsys, "init", str(tmp_path / "w"))
    code, _, err = run(capsys, "config", "show", "-c", "lab_sim", "-v")
    assert code == 0 and "note:" in err and "not used by Kinema" in err


def test_with_nothing_selected_the_bundled_lab_sim_is_the_config(capsys):
    code, out, _ = run(capsys, "config", "chain")
    assert code == 0 and out.split()[0] == "lab_sim" and len(out.splitlines()) == 1


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("config", "show", "-c", "lab_sm"), "did you mean 'lab_sim'"),
        (("config", "chain", "-c", "nope"), "no config package named 'nope'"),
        (("objective", "show", "Nope", "-c", "lab_sim"), "no objective named 'Nope'"),
        (("objective", "list", "-c", "lab_sim", "-w", "/definitely/not/here"), "does not exist"),
        (
            ("new", "config", "Bad-Name", "-b", "lab_sim", "--no-input", "-o", "/tmp"),
            "not a valid package name",
        ),
        (
            ("new", "config", "fine_name", "-b", "no_parent", "--no-input", "-o", "/tmp"),
            "cannot base 'fine_name' on 'no_parent'",
        ),
        (("new", "config", "fine_name", "--no-input", "-o", "/tmp"), "--based-on PARENT is missing"),
        (("configure", "-w", "", "-c", "no_such_config"), "no config package named 'no_such_config'"),
    ],
)
def test_bad_input_is_one_error_line_and_exit_code_1(capsys, args: tuple[str, ...], words: str):
    code, _, err = run(capsys, *args)
    assert code == 1
    assert err.startswith("error: ")
    assert words in err
    assert "Traceback" not in err


def test_broken_workspace_config_is_an_error_not_a_traceback(capsys, ws):
    package = ws.config("broken")
    (package / "config" / "config.yaml").write_bytes(b"hardware: [\xff\n")
    code, _, err = run(capsys, "config", "show", "-w", str(ws.root), "-c", "broken")
    assert code == 1 and err.startswith("error: ") and "not UTF-8" in err
    (package / "config" / "config.yaml").write_text("hardware: [\n")
    code, _, err = run(capsys, "config", "show", "-w", str(ws.root), "-c", "broken")
    assert code == 1 and "config.yaml:2: invalid YAML" in err
    code, out, _ = run(capsys, "config", "list", "-w", str(ws.root))
    assert code == 0 and "broken" in out and "error:" in out  # one broken package does not hide the list


def test_duplicate_packages_error_names_both_paths(capsys, ws):
    first = ws.config("twin", folder="a/twin")
    second = ws.config("twin", folder="b/twin")
    code, _, err = run(capsys, "config", "list", "-w", str(ws.root))
    assert code == 1 and str(first) in err and str(second) in err


def test_objective_list_reports_broken_files_and_lists_the_rest(capsys, ws):
    ws.config("robot")
    ws.objective("robot", "Fine")
    (ws.root / "src" / "robot" / "objectives" / "bad.xml").write_text("<root>\n<BehaviorTree ID='x'>\n")
    code, out, err = run(capsys, "objective", "list", "-w", str(ws.root), "-c", "robot")
    assert code == 0
    assert "Fine" in out
    assert "bad.xml:3: XML syntax error" in err


def test_init_refuses_an_existing_workspace(capsys, tmp_path: Path):
    assert run(capsys, "init", str(tmp_path / "w"))[0] == 0
    code, _, err = run(capsys, "init", str(tmp_path / "w"))
    assert code == 1 and "already a workspace" in err


def test_configure_prompts_for_missing_values(capsys, monkeypatch: pytest.MonkeyPatch, tmp_path: Path):
    import io

    run(capsys, "init", str(tmp_path / "w"))
    monkeypatch.setattr("sys.stdin", io.StringIO(f"{tmp_path / 'w'}\nexample_config\n"))
    code, out, _ = run(capsys, "configure")
    assert code == 0
    assert "config:    example_config" in out
    from kinema.config import active_selection

    assert active_selection().config == "example_config"
    assert active_selection().workspace == (tmp_path / "w").resolve()


def test_configure_with_only_a_config_keeps_the_workspace(capsys, tmp_path: Path):
    from kinema.config import active_selection

    run(capsys, "init", str(tmp_path / "w"))
    assert run(capsys, "configure", "-w", str(tmp_path / "w"), "-c", "lab_sim")[0] == 0
    code, out, _ = run(capsys, "configure", "-c", "example_config")
    assert code == 0 and "config:    example_config" in out
    assert active_selection().workspace == (tmp_path / "w").resolve()


def test_configure_with_an_empty_workspace_selects_bundled_configs_only(capsys):
    from kinema.config import active_selection

    code, out, _ = run(capsys, "configure", "-w", "", "-c", "example_config")
    assert code == 0 and "(none, bundled configs only)" in out
    assert active_selection().workspace is None
    assert active_selection().config == "example_config"


@pytest.mark.parametrize(
    ("setup", "words"),
    [
        ("cycle", "inheritance cycle: a → b → a"),
        ("missing_file", "description/robot.urdf does not exist"),
        ("wrong_type", "hardware must be a mapping, not a list"),
        ("missing_parent", "which is not a known package"),
        ("huge", "larger than the limit"),
    ],
)
def test_bad_configs_through_the_cli(capsys, ws, setup: str, words: str):
    if setup == "cycle":
        ws.child("a", "b")
        ws.child("b", "a")
    elif setup == "missing_file":
        package = ws.config("a")
        (package / "description" / "robot.urdf").unlink()
    elif setup == "wrong_type":
        ws.config("a", "hardware: [1]\n")
    elif setup == "missing_parent":
        ws.child("a", "nobody")
    else:
        ws.config("a", "# " + "x" * (3 * 1024 * 1024) + "\n")
    for verb in (("config", "show"), ("objective", "list")):
        code, _, err = run(capsys, *verb, "-w", str(ws.root), "-c", "a")
        assert code == 1, verb
        assert err.startswith("error: ") and words in err, err
        assert "Traceback" not in err


def test_init_where_no_folder_can_be_made_is_one_line_not_a_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from kinema.cli.main import main

    blocker = tmp_path / "a_file"
    blocker.write_text("")
    assert main(["init", str(blocker / "ws")]) == 1
    err = capsys.readouterr().err
    assert "cannot create the workspace" in err and "Traceback" not in err


def test_run_with_an_unknown_config_is_refused_before_a_run_folder_or_router_exists(capsys):
    from kinema.runtime.run_folder import runs_dir

    before = sorted(runs_dir().iterdir())
    code, _, err = run(capsys, "run", "-c", "nope", "--headless")
    assert code == 1 and err.startswith("error: ") and "no config package named 'nope'" in err, err
    after = sorted(runs_dir().iterdir())
    assert after == before, f"new run folders: {set(after) - set(before)}"


def test_the_hint_after_new_config_is_a_command_that_finds_the_package(capsys, tmp_path: Path):
    # Inside a workspace's src/ that is not the selected one: the hint names the workspace.
    workspace = tmp_path / "other_ws"
    assert run(capsys, "init", str(workspace))[0] == 0
    code, out, _ = run(
        capsys, "new", "config", "cell_a", "-b", "lab_sim", "--no-input", "-o", str(workspace / "src")
    )
    assert code == 0, out
    hint = next(line for line in out.splitlines() if line.startswith("try: kinema "))
    code, shown, err = run(capsys, *hint.removeprefix("try: kinema ").split())
    assert code == 0 and "chain: lab_sim → cell_a" in shown, (hint, shown, err)
    # Outside any workspace: no command finds it, and the note says so instead of a hint that fails.
    code, out, _ = run(
        capsys, "new", "config", "cell_b", "-b", "lab_sim", "--no-input", "-o", str(tmp_path / "loose")
    )
    assert code == 0, out
    assert "try: kinema" not in out
    assert "not a workspace's src/ folder" in out and "kinema init" in out, out


def test_a_misspelt_config_key_is_a_warning_without_verbose(capsys, tmp_path: Path):
    workspace = tmp_path / "ws"
    assert run(capsys, "init", str(workspace))[0] == 0
    assert (
        run(capsys, "new", "config", "my_cell", "-w", str(workspace), "--based-on", "lab_sim", "--no-input")[
            0
        ]
        == 0
    )
    config_file = workspace / "src" / "my_cell" / "config" / "config.yaml"
    text = config_file.read_text()
    assert "\nobjectives:\n" in text
    config_file.write_text(text.replace("\nobjectives:\n", "\nobjectives:\n  waypoint_file: foo\n", 1))
    line = config_file.read_text().splitlines().index("  waypoint_file: foo") + 1
    expected = f"warning: {config_file}:{line}: unknown key 'waypoint_file' in objectives"
    for verb in (("config", "show"), ("objective", "list", "--no-check")):
        code, _, err = run(capsys, *verb, "-w", str(workspace), "-c", "my_cell")
        assert code == 0 and expected in err and "did you mean 'waypoints_file'" in err, err


def test_with_no_workspace_selected_new_config_names_the_one_you_are_in(
    capsys, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
):
    """`kinema init ws && cd ws && kinema new config ...` without -w: the refusal says `-w .`."""
    monkeypatch.delenv("KINEMA_WORKSPACE", raising=False)
    assert run(capsys, "init", str(tmp_path / "ws"))[0] == 0
    monkeypatch.chdir(tmp_path / "ws")
    code, _out, err = run(capsys, "new", "config", "cell", "--based-on", "lab_sim", "--no-input")
    assert code != 0
    assert f"you are in the workspace {(tmp_path / 'ws').resolve()}: pass -w ." in err
    assert not (tmp_path / "ws" / "src" / "cell").exists()
    # Outside any workspace it says how to select or create one.
    monkeypatch.chdir(tmp_path)
    code, _out, err = run(capsys, "new", "config", "cell", "--based-on", "lab_sim", "--no-input")
    assert code != 0 and "create one with `kinema init PATH`" in err
