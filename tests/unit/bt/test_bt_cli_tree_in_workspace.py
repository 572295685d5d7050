"""``kinema tree validate`` in a workspace checks against the config's behaviors and subtrees by default."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from kinema.cli.main import cli

OBJECTIVE = """<root BTCPP_format="4" main_tree_to_execute="Go Home Twice">
  <BehaviorTree ID="Go Home Twice">
    <Sequence>
      <SubTree ID="Move to Waypoint" waypoint_name="Home" _autoremap="true"/>
      <SubTree ID="My Wave"/>
      <LogMessage message="done"/>
    </Sequence>
  </BehaviorTree>
</root>
"""

WAVE = """<root BTCPP_format="4">
  <BehaviorTree ID="My Wave"><AlwaysSuccess/></BehaviorTree>
</root>
"""


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    """A workspace whose config my_cell (based on lab_sim) adds an objective library with a subtree."""
    cell = tmp_path / "ws" / "src" / "my_cell"
    (cell / "config").mkdir(parents=True)
    (cell / "objectives").mkdir()
    (cell / "package.xml").write_text("<package><name>my_cell</name></package>\n")
    (cell / "config" / "config.yaml").write_text(
        'based_on_package: "lab_sim"\n'
        "objectives:\n"
        "  objective_library_paths:\n"
        "    my_cell_objectives: {package_name: my_cell, relative_path: objectives}\n"
    )
    (cell / "objectives" / "wave.xml").write_text(WAVE)
    (cell / "objectives" / "go_home_twice.xml").write_text(OBJECTIVE)
    return tmp_path / "ws"


def _validate(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(cli, ["tree", "validate", *args])
    return result.exit_code, result.output


def test_a_file_of_the_workspace_is_checked_against_its_config(workspace: Path) -> None:
    path = workspace / "src" / "my_cell" / "objectives" / "go_home_twice.xml"
    code, out = _validate("-c", "my_cell", str(path))
    assert code == 0, out
    assert f"{path}: OK (1 trees)" in out
    assert f"checking against config my_cell (workspace {workspace})" in out  # stderr, mixed in by the runner
    # A bundled config is not the workspace's, even when one is selected.
    code, out = _validate("-w", str(workspace), "-c", "lab_sim", str(path))
    assert "checking against config lab_sim (bundled with Kinema)" in out, out


def test_the_config_is_the_default_inside_a_workspace_and_no_config_turns_it_off(
    workspace: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("KINEMA_CONFIG", "my_cell")
    path = workspace / "src" / "my_cell" / "objectives" / "go_home_twice.xml"
    code, out = _validate(str(path))
    assert code == 0, out
    code, out = _validate("--no-config", str(path))
    assert code == 1
    assert "SubTree ID 'Move to Waypoint'" in out or "Node not recognized: LogMessage" in out


def test_outside_a_workspace_only_the_built_in_nodes_are_known(tmp_path: Path) -> None:
    path = tmp_path / "loose.xml"
    path.write_text(OBJECTIVE)
    code, out = _validate(str(path))
    assert code == 1 and "checking against config" not in out
    assert "note: only the built-in nodes were known; -c NAME" in out
    code, out = _validate("-c", "lab_sim", str(path))
    assert "checking against config lab_sim" in out and "Move to Waypoint" not in out, out
