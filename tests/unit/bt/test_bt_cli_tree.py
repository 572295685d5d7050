"""``kinema tree run / validate / nodes`` as a user types them."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from kinema.cli.main import cli
from kinema.resources import bundled_dir

HELLO = bundled_dir("objectives") / "examples" / "hello_tree.xml"
COMPAT = Path(__file__).resolve().parents[4] / "shared" / "compat" / "moveit_pro" / "objectives"


def run_cli(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(cli, list(args))
    return result.exit_code, result.output


def test_run_the_bundled_example() -> None:
    code, out = run_cli("tree", "run", str(HELLO), "--blackboard")
    assert code == 0, out
    assert "count up/add one" in out and "IDLE -> SUCCESS" in out
    assert "count (int) = 3" in out and "'hello, tree'" in out
    assert out.rstrip().endswith("final status: SUCCESS")


def test_every_runnable_example_runs_to_success_and_its_steps_are_not_offered() -> None:
    """What `kinema objective list` marks runnable (R) in the bundled examples succeeds when run alone; a
    step of another objective (Count Up needs Hello Tree's counter) is marked not runnable."""
    from kinema.config.objective_file import parse_objective_file

    infos = parse_objective_file(HELLO).objectives
    assert {info.id: info.runnable for info in infos} == {"Hello Tree": True, "Count Up": False}
    for info in infos:
        if info.runnable:
            code, out = run_cli("tree", "run", str(HELLO), "--tree", info.id, "-q")
            assert code == 0, f"{info.id}: {out}"


def test_run_exits_1_on_failure_and_respects_tree(tmp_path: Path) -> None:
    path = tmp_path / "two.xml"
    path.write_text(
        '<root BTCPP_format="4" main_tree_to_execute="Good"><BehaviorTree ID="Good"><AlwaysSuccess/>'
        '</BehaviorTree><BehaviorTree ID="Bad"><AlwaysFailure/></BehaviorTree></root>'
    )
    assert run_cli("tree", "run", str(path), "-q")[0] == 0
    code, out = run_cli("tree", "run", str(path), "--tree", "Bad", "--quiet")
    assert code == 1 and out.strip() == "final status: FAILURE"


def test_run_timeout_halts(tmp_path: Path) -> None:
    path = tmp_path / "slow.xml"
    path.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="M"><Sleep msec="100000"/></BehaviorTree></root>'
    )
    code, out = run_cli("tree", "run", str(path), "--timeout", "0.1", "-q")
    assert code == 1 and "final status: RUNNING" in out


def test_run_reports_errors_with_file_and_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.xml"
    path.write_text('<root BTCPP_format="4">\n<BehaviorTree ID="M">\n<Nope/>\n</BehaviorTree>\n</root>\n')
    from kinema.cli.main import main

    assert main(["tree", "run", str(path)]) == 1


def test_validate_reports_every_problem(tmp_path: Path) -> None:
    path = tmp_path / "bad.xml"
    path.write_text(
        '<root BTCPP_format="4">\n'
        '  <BehaviorTree ID="M">\n'
        "    <Sequence>\n"
        "      <Sequense/>\n"
        '      <Repeat num_cycle="2"><AlwaysSuccess/></Repeat>\n'
        '      <Script code="x := "/>\n'
        '      <AlwaysSuccess _skipIf="a ==="/>\n'
        '      <SubTree ID="Missing"/>\n'
        '      <Repeat num_cycles="many"><AlwaysSuccess/></Repeat>\n'
        "    </Sequence>\n"
        "  </BehaviorTree>\n"
        "</root>\n"
    )
    code, out = run_cli("tree", "validate", str(path))
    assert code == 1
    lines = out.strip().splitlines()
    assert any(
        line.startswith(f"{path}:4: Node not recognized: Sequense; did you mean 'Sequence'") for line in lines
    )
    assert any(line.startswith(f"{path}:5: port [num_cycle]") and "num_cycles" in line for line in lines)
    assert any(line.startswith(f"{path}:6: Script code=") for line in lines)
    assert any(line.startswith(f"{path}:7: script in _skipIf") for line in lines)
    assert any(line.startswith(f"{path}:8: SubTree ID 'Missing'") for line in lines)
    assert any(line.startswith(f"{path}:9: port [num_cycles]") and "int" in line for line in lines)


def test_validate_ok_and_syntax_error(tmp_path: Path) -> None:
    code, out = run_cli("tree", "validate", str(HELLO))
    assert code == 0 and "OK (2 trees)" in out
    broken = tmp_path / "broken.xml"
    broken.write_text("<root>\n<BehaviorTree ID='M'>\n<AlwaysSuccess>\n</root>\n")
    code, out = run_cli("tree", "validate", str(broken))
    assert code == 1 and out.startswith(f"{broken}:")


def test_validate_catches_build_time_problems(tmp_path: Path) -> None:
    path = tmp_path / "loop.xml"
    path.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="A"><SubTree ID="B"/></BehaviorTree>'
        '<BehaviorTree ID="B"><SubTree ID="A"/></BehaviorTree></root>'
    )
    code, out = run_cli("tree", "validate", str(path))
    assert code == 1 and "Recursive behavior tree cycle" in out


@pytest.mark.skipif(
    not COMPAT.is_dir(), reason="the MoveIt Pro compatibility files are not beside the checkout"
)
def test_validate_moveit_pro_objectives_reports_unknown_behaviors() -> None:
    files = sorted(str(p) for p in COMPAT.glob("*.xml"))
    code, out = run_cli("tree", "validate", *files)
    assert code == 1
    assert "close_gripper.xml:14: Node not recognized: MoveGripperAction" in out
    assert "move_to_joint_state.xml:8: Node not recognized: SwitchController" in out
    assert "look_at_table.xml: OK" in out  # its SubTree is defined in move_to_waypoint.xml
    assert "Traceback" not in out


def test_nodes_prints_the_model() -> None:
    code, out = run_cli("tree", "nodes")
    assert code == 0 and "<TreeNodesModel" in out and "Sequence" not in out
    code, out = run_cli("tree", "nodes", "--builtin")
    assert code == 0 and '<Control ID="Sequence"/>' in out


@pytest.mark.skipif(
    not COMPAT.is_dir(), reason="the MoveIt Pro compatibility files are not beside the checkout"
)
def test_validate_moveit_pro_objectives_against_the_bundled_behaviors() -> None:
    files = sorted(str(p) for p in COMPAT.glob("*.xml"))
    code, out = run_cli("tree", "validate", "--behaviors", *files)
    assert "Node not recognized" not in out
    assert code == 0, out


def test_validate_reads_moveit_pros_old_names_and_warns_on_stderr(tmp_path: Path) -> None:
    path = tmp_path / "old.xml"
    path.write_text(
        '<root BTCPP_format="4">\n'
        '  <BehaviorTree ID="Old">\n'
        '    <Action ID="CreateStampedWrench" force_xyz="0;0;1" stamped_wrench="{wrench}"/>\n'
        "  </BehaviorTree>\n"
        "</root>\n"
    )
    result = CliRunner().invoke(cli, ["tree", "validate", "--behaviors", str(path)])
    assert result.exit_code == 0, result.output
    assert f"{path}: OK (1 trees)" in result.stdout
    assert (
        f"warning: {path}:3: CreateStampedWrench is MoveIt Pro's old name of CreateWrenchStamped "
        "(its port stamped_wrench is wrench_stamped)"
    ) in result.stderr
