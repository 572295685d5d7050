"""The plugin verbs as a user types them: kinema plugins, behaviors, new behavior, build, test."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from kinema.cli.main import main

# Based on example_config, but with lab_sim's and example_config's objective libraries replaced by this
# package's own, so what is validated is exactly what the tests put there (plus Kinema's core library).
CONFIG_YAML = """\
based_on_package: "example_config"
objectives:
  objective_library_paths:
    lab_sim_objectives:
      package_name: "my_config"
      relative_path: "objectives"
    example_objectives:
      package_name: "my_config"
      relative_path: "objectives"
"""
# Plugins of this environment the generated tests do not use; leaving them out halves each run's start-up.
LEAN_PYTEST = [
    "-p",
    "no:cacheprovider",
    "-p",
    "no:hypothesispytest",
    "-p",
    "no:textual-snapshot",
    "-p",
    "no:benchmark",
]
BROKEN_OBJECTIVE = """<root BTCPP_format="4">
  <BehaviorTree ID="Broken">
    <Sequence>
      <MyBehavior int_1="2" int_3="4"/>
      <NoSuchBehavior/>
    </Sequence>
  </BehaviorTree>
</root>
"""


@pytest.fixture
def ws(workspace: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A workspace with config package my_config (based on example_config), selected through the env."""
    config = workspace / "src" / "my_config"
    (config / "config").mkdir(parents=True)
    (config / "objectives").mkdir()
    (config / "config" / "config.yaml").write_text(CONFIG_YAML)
    (config / "package.xml").write_text("<package><name>my_config</name></package>\n")
    monkeypatch.setenv("KINEMA_WORKSPACE", str(workspace))
    monkeypatch.setenv("KINEMA_CONFIG", "my_config")
    return workspace


def test_plugins_lists_each_plugin_with_its_source_and_behaviors(ws: Path, capsys) -> None:
    assert main(["new", "behavior", "my_adder", "--type", "async"]) == 0
    out = capsys.readouterr().out
    assert "updated" in out and "my_adder::MyAdderBehaviorsLoader" in out
    assert main(["plugins", "--json"]) == 0
    plugins = {p["name"]: p for p in json.loads(capsys.readouterr().out)}
    assert plugins["kinema::ExampleBehaviorsLoader"]["source"] == "bundled"
    assert plugins["kinema::ExampleBehaviorsLoader"]["behaviors"] == ["MyBehavior", "MyServiceClient"]
    assert plugins["my_adder::MyAdderBehaviorsLoader"]["source"] == "workspace"
    assert plugins["my_adder::MyAdderBehaviorsLoader"]["behaviors"] == ["MyAdder"]


def test_behaviors_json_has_ports_and_metadata(ws: Path, capsys) -> None:
    assert main(["behaviors", "--json", "MyServiceClient"]) == 0
    (behavior,) = json.loads(capsys.readouterr().out)
    assert behavior["id"] == "MyServiceClient" and behavior["class"] == "MyAddTwoIntsServiceClient"
    assert behavior["metadata"]["subcategory"] == "Example Behaviors"
    ports = {port["name"]: port for port in behavior["ports"]}
    assert ports["service_name"] == {
        "name": "service_name",
        "direction": "input",
        "type": "std::string",
        "default": "/add_two_ints",
        "description": "The AddTwoInts service to call.",
    }
    assert ports["result"]["direction"] == "output"
    assert main(["behaviors", "MyServiceClint"]) == 1
    assert "did you mean 'MyServiceClient'" in capsys.readouterr().err


def test_a_plugin_that_fails_to_load_makes_plugins_exit_1_with_its_line(ws: Path, capsys) -> None:
    assert main(["new", "behavior", "my_adder"]) == 0
    module = ws / "src" / "my_adder" / "my_adder" / "my_adder.py"
    module.write_text(module.read_text() + "\ndef broken(:\n    pass\n")
    capsys.readouterr()
    assert main(["plugins"]) == 1
    err = capsys.readouterr().err
    assert f"{module}:" in err and "SyntaxError" in err


def test_build_validates_objectives_and_writes_the_model(ws: Path, capsys) -> None:
    assert main(["build"]) == 0
    out = capsys.readouterr().out
    model = ws / "build" / "kinema" / "my_config" / "tree_nodes_model.xml"
    assert f"TreeNodesModel for Groot2: {model}" in out
    assert '<Action ID="MyServiceClient">' in model.read_text()

    broken = ws / "src" / "my_config" / "objectives" / "broken.xml"
    broken.write_text(BROKEN_OBJECTIVE)
    assert main(["build"]) == 1
    err = capsys.readouterr().err
    assert f"{broken}:4:" in err and "int_3" in err
    assert f"{broken}:5:" in err and "NoSuchBehavior" in err


def test_build_accepts_moveit_pros_old_names_and_warns_with_the_current_ones(ws: Path, capsys) -> None:
    old = ws / "src" / "my_config" / "objectives" / "old_names.xml"
    old.write_text(
        '<root BTCPP_format="4">\n'
        '  <BehaviorTree ID="Old Names">\n'
        "    <Sequence>\n"
        '      <Action ID="CreateStampedPose" reference_frame="world" stamped_pose="{pose}"/>\n'
        '      <Action ID="GetImage" topic_name="/wrist_camera/color" timeout_sec="2"/>\n'
        "    </Sequence>\n"
        "  </BehaviorTree>\n"
        "</root>\n"
    )
    assert main(["build", "--skip-install"]) == 0
    err = capsys.readouterr().err
    assert (
        f"warning: {old}:4: CreateStampedPose is MoveIt Pro's old name of CreatePoseStamped "
        "(its port stamped_pose is pose_stamped); read as CreatePoseStamped, write that instead"
    ) in err, err
    assert (
        f"warning: {old}:5: GetImage's port timeout_sec is MoveIt Pro's old name of message_timeout_sec"
        in err
    )


@pytest.mark.parametrize(
    ("waypoints_file", "content", "said"),
    [
        ("config/waypoints.yaml", "- name: [unclosed\n  joints: {", "waypoints.yaml"),
        ("config/waypoints.yaml", "just some words\n", "waypoints.yaml"),
        ("../../../../etc/passwd", None, "leaves package 'my_config'"),
        ("/etc/passwd", None, "leaves package 'my_config'"),
    ],
)
def test_build_reads_the_waypoints_file_and_refuses_paths_outside_the_package(
    ws: Path, capsys, waypoints_file: str, content: str | None, said: str
) -> None:
    """It said '0 problems' for a garbage waypoints file and a waypoints_file of ../../../../etc/passwd."""
    config = ws / "src" / "my_config"
    if content is not None:
        (config / waypoints_file).write_text(content)
    reference = f'  waypoints_file:\n    package_name: "my_config"\n    relative_path: "{waypoints_file}"\n'
    (config / "config" / "config.yaml").write_text(CONFIG_YAML + reference)
    assert main(["build", "--skip-install"]) == 1
    err = capsys.readouterr().err
    assert said in err and "Traceback" not in err, err


def test_build_packages_select_names_the_valid_packages(ws: Path, capsys) -> None:
    assert main(["new", "behavior", "my_adder"]) == 0
    assert main(["build", "--packages-select", "my_added"]) == 1
    assert "did you mean 'my_adder'" in capsys.readouterr().err
    assert main(["build", "--packages-select", "my_adder", "--skip-install"]) == 0


def test_test_runs_the_packages_tests(ws: Path, capsys) -> None:
    assert main(["new", "behavior", "my_adder"]) == 0
    assert main(["test", "--packages-select", "my_adder", "--", "-q", *LEAN_PYTEST]) == 0
    module = ws / "src" / "my_adder" / "my_adder" / "my_adder.py"
    module.write_text(module.read_text().replace("int_1 + int_2", "int_1 - int_2"))
    assert main(["test", "--", "-q", *LEAN_PYTEST]) == 1
    assert "tests failed in: my_adder" in capsys.readouterr().err


def test_test_without_pytest_says_which_command_installs_it(ws: Path, capsys, monkeypatch) -> None:
    import importlib.util
    import sys

    real_find_spec = importlib.util.find_spec

    def no_pytest(name: str, *args: object):  # type: ignore[no-untyped-def]
        return None if name == "pytest" else real_find_spec(name, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(importlib.util, "find_spec", no_pytest)
    assert main(["test"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert f"install it with: {sys.executable} -m pip install 'pytest>=8'" in err, err


def test_pytest_comes_with_kinema() -> None:
    from importlib import metadata

    requirements = metadata.requires("kinema") or []
    assert any(r.split(";")[0].strip().startswith("pytest>=") and "extra" not in r for r in requirements)
