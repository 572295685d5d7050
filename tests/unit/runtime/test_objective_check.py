"""``kinema objective check FOLDER``: how many of a folder's objective files validate against a config (the
part that needs no runtime; tests/sim/lab_sim_library runs a whole library with --run)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

SHARED = Path(__file__).resolve().parents[3].parent / "shared" / "compat" / "moveit_pro"

BROKEN = """<root BTCPP_format="4" main_tree_to_execute="Broken">
  <BehaviorTree ID="Broken">
    <Sequence>
      <Action ID="NoSuchBehavior" />
      <Action ID="NorThisOne" />
    </Sequence>
  </BehaviorTree>
</root>
"""
SUBTREE_ONLY = """<root BTCPP_format="4" main_tree_to_execute="Helper">
  <BehaviorTree ID="Helper"><AlwaysSuccess /></BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="Helper"><MetadataFields><Metadata runnable="false" /></MetadataFields></SubTree>
  </TreeNodesModel>
</root>
"""
USES_HELPER = """<root BTCPP_format="4" main_tree_to_execute="Uses Helper">
  <BehaviorTree ID="Uses Helper"><SubTree ID="Helper" /></BehaviorTree>
</root>
"""


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    """A package with MoveIt Pro's seven compat objectives, a broken file, and a runnable one whose SubTree
    is elsewhere."""
    if not (SHARED / "objectives").is_dir():
        pytest.skip(f"MoveIt Pro's compat objectives are not at {SHARED / 'objectives'}")
    checked = tmp_path / "package"
    shutil.copytree(SHARED / "objectives", checked / "objectives")
    (checked / "objectives" / "broken.xml").write_text(BROKEN)
    (checked / "objectives" / "uses_helper.xml").write_text(USES_HELPER)
    # A package's own XML files are no objectives: its package.xml and its MuJoCo scene are not counted.
    (checked / "package.xml").write_text("<package format='3'><name>package</name></package>")
    (checked / "description").mkdir()
    (checked / "description" / "scene.xml").write_text("<mujoco/>")
    (tmp_path / "helpers").mkdir()
    (tmp_path / "helpers" / "helper.xml").write_text(SUBTREE_ONLY)
    return checked


def test_check_counts_the_files_that_validate_and_says_why_the_others_do_not(folder: Path) -> None:
    from kinema.cli.main import cli

    result = CliRunner().invoke(cli, ["objective", "check", str(folder), "-c", "lab_sim"])
    assert result.exit_code == 1, result.output  # not everything validates
    lines = result.output.splitlines()
    broken = next(line for line in lines if "broken.xml" in line)
    # The problem names the user's file (not the temporary copy) and the unknown behavior.
    assert str(folder / "objectives" / "broken.xml") in broken and "NoSuchBehavior" in broken, broken
    # One line per file, counting the rest (a missing parameter file hid nine more in a MoveIt Pro file).
    assert "(and 1 more problem: `kinema tree validate` lists them all)" in broken, broken
    assert any("uses_helper.xml" in line and "Helper" in line for line in lines), result.output
    assert "7 of 9 objective files validate against lab_sim" in lines[-1], result.output


def test_subtree_folders_are_reached_but_not_counted(folder: Path) -> None:
    from kinema.cli.main import cli

    helpers = folder.parent / "helpers"
    result = CliRunner().invoke(
        cli, ["objective", "check", str(folder), "--subtrees", str(helpers), "--json"]
    )
    report = json.loads(result.output)
    assert report["config"] == "lab_sim"  # nothing selected: lab_sim
    assert report["counts"] == {"files": 9, "valid": 8, "runnable": 8}, report["counts"]
    assert report["runs"] is None
    problems = {entry["file"]: entry["problem"] for entry in report["files"]}
    assert problems["uses_helper.xml"] is None and "NoSuchBehavior" in problems["broken.xml"]
    assert not list(folder.rglob("*kinema_objective_check*")), "the folder itself is never written"


def test_only_needs_run() -> None:
    from kinema.cli.main import cli

    result = CliRunner().invoke(cli, ["objective", "check", ".", "--only", "Close Gripper"])
    assert result.exit_code == 2 and "--only names objectives to run" in result.output


def test_a_node_whose_old_name_is_a_subtree_today_brings_that_subtree_into_the_check(tmp_path: Path) -> None:
    """MoveIt Studio's `<Action ID="ExecuteMTCTask"/>` loads as the "Execute MTC Solution" objective; a file
    checked alone said that SubTree was unknown (its closure was read from the SubTree elements only)."""
    from kinema.config import ObjectiveLibrary, resolve_config
    from kinema.plugins import BehaviorHost
    from kinema.runtime.library_check import file_problem

    old = tmp_path / "old.xml"
    old.write_text(
        '<root BTCPP_format="4" main_tree_to_execute="Old"><BehaviorTree ID="Old">'
        '<Action ID="ExecuteMTCTask" solution="{solution}"/></BehaviorTree></root>'
    )
    resolved = resolve_config("lab_sim")
    host = BehaviorHost.for_config(resolved)
    host.load().raise_for_errors()
    assert file_problem(ObjectiveLibrary.load(resolved), old, host.registry.create_factory()) is None
