"""A waypoint an objective names literally but the config has not saved is a warning before any run: an
objective copied from another MoveIt Pro config validated, then failed where it ran ("unknown waypoint")."""

from __future__ import annotations

import json
from pathlib import Path

from click.testing import CliRunner

from kinema.cli.main import cli
from kinema.config import resolve_config
from kinema.config.waypoint_location import waypoint_store_for
from kinema.config.waypoint_uses import config_waypoint_warnings, waypoint_names_used

COPIED = """<root BTCPP_format="4" main_tree_to_execute="Cycle">
  <BehaviorTree ID="Cycle">
    <Sequence>
      <SubTree ID="Move to Waypoint" waypoint_name="Grasp Left" />
      <SubTree ID="Move to Waypoint" waypoint_name="Look at Table" />
      <Action ID="RetrieveWaypoint" waypoint_name="{chosen}" waypoint_joint_state="{state}" />
      <SubTree ID="Move to Waypoint" waypoint_name="{chosen}" />
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="Cycle">
      <input_port name="waypoint_name" default="Arm Forwrd" />
    </SubTree>
  </TreeNodesModel>
</root>
"""


def test_literal_names_and_declared_defaults_are_checked_blackboard_entries_are_not(tmp_path: Path) -> None:
    path = tmp_path / "cycle.xml"
    path.write_text(COPIED)
    assert [(location.line, name) for location, name in waypoint_names_used(path)] == [
        (4, "Grasp Left"),
        (5, "Look at Table"),
        (12, "Arm Forwrd"),
    ]
    warnings = config_waypoint_warnings([path], resolve_config("lab_sim"))
    assert len(warnings) == 2, warnings
    assert warnings[0].startswith(f"{path}:4: waypoint 'Grasp Left' is not one of config lab_sim's waypoints")
    assert "kinema waypoint save 'Grasp Left'" in warnings[0]
    count = len(waypoint_store_for(resolve_config("lab_sim")).names())  # type: ignore[union-attr]
    assert f"(it has {count}: `kinema waypoint list -c lab_sim`)" in warnings[0]
    assert warnings[1].startswith(f"{path}:12: waypoint 'Arm Forwrd'")


def test_tree_validate_and_objective_check_warn_and_still_validate(tmp_path: Path) -> None:
    folder = tmp_path / "objectives"
    folder.mkdir()
    (folder / "cycle.xml").write_text(COPIED)
    validated = CliRunner().invoke(cli, ["tree", "validate", "-c", "lab_sim", str(folder / "cycle.xml")])
    assert validated.exit_code == 0, validated.output
    assert "warning: " in validated.output and "waypoint 'Grasp Left' is not one of" in validated.output
    checked = CliRunner().invoke(cli, ["objective", "check", str(folder), "-c", "lab_sim", "--json"])
    report = json.loads(checked.stdout)
    (entry,) = report["files"]
    assert entry["problem"] is None and len(entry["warnings"]) == 2
    # The warning names the user's file and config, not the check's temporary copies.
    assert entry["warnings"][0].startswith(f"{folder / 'cycle.xml'}:4: ")
    assert "config lab_sim's waypoints" in entry["warnings"][0]
