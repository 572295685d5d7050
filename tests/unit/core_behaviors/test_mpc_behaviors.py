"""The MPC behaviors' edges: MoveIt Pro's ports and lab_sim's defaults, and where each plan is streamed."""

from __future__ import annotations

import importlib
from typing import Any

import pytest

from kinema.errors import ObjectiveError

MPC = ("MPCPoseTracking", "MPCSphereClearance", "MPCPointCloudClearance")


def test_the_plans_go_to_the_trajectory_controllers_streaming_topic(registry: Any) -> None:
    family = registry["MPCPoseTracking"].cls.__module__.rsplit(".", 1)[0]
    streaming_topic = importlib.import_module(f"{family}.control_loop").streaming_topic

    assert streaming_topic("/joint_trajectory_controller/follow_joint_trajectory") == (
        "/joint_trajectory_controller/joint_trajectory"
    )
    assert (
        streaming_topic("my_arm_controller/follow_joint_trajectory") == "/my_arm_controller/joint_trajectory"
    )
    for bad in ("/joint_trajectory_controller", "/a/b/follow_joint_trajectory", "/x/gripper_cmd", ""):
        with pytest.raises(ObjectiveError, match="/<controller>/follow_joint_trajectory"):
            streaming_topic(bad)


@pytest.mark.parametrize("behavior", MPC)
def test_ports_are_moveit_pros_with_the_cell_and_lab_sim_defaults(registry: Any, behavior: str) -> None:
    ports = {port.name: port for port in registry[behavior].ports}
    assert {
        "target_pose",
        "target_twist",
        "planning_group",
        "gripper_site_name",
        "horizon",
        "timestep",
    } <= set(ports)
    assert ports["total_return"].direction.name == "OUTPUT"
    # Robot-specific names come from the config, never from a default in code.
    for name in ("planning_group", "gripper_site_name", "follow_joint_trajectory_topic"):
        assert "Default: the config's" in ports[name].description, name
    assert "not used" in ports["sampling_exploration"].description or "without using" in (
        ports["sampling_exploration"].description
    )
    if behavior != "MPCPoseTracking":
        assert ports["safe_distance"].default_str == "0.250000"
        assert "link_sites" in ports
