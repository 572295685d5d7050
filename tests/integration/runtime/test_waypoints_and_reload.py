"""Waypoints served by the agent (GetWaypoints / EditWaypoints); objective files picked up live."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import pytest
import yaml

from kinema.drivers.mujoco import names as driver_names
from kinema.errors import ObjectiveError
from kinema.runtime import names


def test_waypoints_are_saved_from_the_joint_states_renamed_and_erased(
    lively_agent: Any, tmp_path: Path
) -> None:
    from kinema.transport import Node, open_session

    with open_session(lively_agent.endpoint) as session:
        node = Node(session, "waypoint_user")
        get = node.create_client(names.GET_WAYPOINTS_TYPE, names.GET_WAYPOINTS)
        edit = node.create_client(names.EDIT_WAYPOINTS_TYPE, names.EDIT_WAYPOINTS)
        assert get.call({}, timeout=10).waypoints == []
        refused = edit.call({"operation": 0, "waypoint_name": "Home"}, timeout=10)
        assert not refused.status.success and "/joint_states" in refused.status.error_message

        joints = node.create_publisher(driver_names.JOINT_STATES_TYPE, driver_names.JOINT_STATES_TOPIC)
        state = {"name": ["shoulder_pan_joint", "elbow_joint"], "position": [0.5, -1.0]}
        deadline = time.monotonic() + 10
        while True:
            joints.publish(state)
            saved = edit.call(
                {"operation": 0, "waypoint_name": "Home", "joint_group_names": ["manipulator"]}, timeout=10
            )
            if saved.status.success or time.monotonic() > deadline:
                break
            time.sleep(0.05)
        assert saved.status.success, saved.status.error_message
        assert list(saved.new_waypoint.joint_state.position) == [0.5, -1.0]
        stored = yaml.safe_load((tmp_path / "waypoints.yaml").read_text())
        assert stored[0]["name"] == "Home" and stored[0]["joint_group_names"] == ["manipulator"]

        renamed = edit.call(
            {"operation": 1, "waypoint_name": "Home", "existing_waypoint_new_name": "Park"}, timeout=10
        )
        assert renamed.status.success and renamed.new_waypoint.name == "Park"
        assert [w.name for w in get.call({}, timeout=10).waypoints] == ["Park"]
        missing = edit.call({"operation": 2, "waypoint_name": "Home"}, timeout=10)
        assert not missing.status.success and "valid: Park" in missing.status.error_message
        assert edit.call({"operation": 2, "waypoint_name": "Park"}, timeout=10).status.success
        assert get.call({}, timeout=10).waypoints == []
        unknown = edit.call({"operation": 7, "waypoint_name": "x"}, timeout=10)
        assert not unknown.status.success and "valid: 0 (SAVE)" in unknown.status.error_message


def test_a_new_objective_file_can_run_without_a_restart(lively_agent: Any, tmp_path: Path) -> None:
    from kinema.sdk import ObjectiveClient

    with ObjectiveClient(lively_agent.endpoint, timeout=10) as client:
        assert client.execute("Brand New").failed
        (tmp_path / "objectives" / "brand_new.xml").write_text(
            '<root BTCPP_format="4"><BehaviorTree ID="Brand New"><AlwaysSuccess/></BehaviorTree></root>'
        )
        deadline = time.monotonic() + 15
        while "Brand New" not in {info.name for info in client.objectives()}:
            assert time.monotonic() < deadline, "the new objective never appeared"
            time.sleep(0.1)
        assert client.execute("Brand New").succeeded
        # The SDK reads an objective's file back as saved (what the TUI's Tree tab shows).
        assert client.objective_xml("Brand New") == (tmp_path / "objectives" / "brand_new.xml").read_text()
        with pytest.raises(ObjectiveError, match=r"no objective named 'Brand Nw'.*Brand New"):
            client.objective_xml("Brand Nw")
