"""Every node the MoveIt Pro objectives use exists with every port they set; Kinema's objectives validate."""

from __future__ import annotations

from pathlib import Path

import pytest

from kinema.bt.xmlsource import parse_xml_file
from kinema.plugins import BehaviorRegistry

BUILTINS = {"Sequence", "KeepRunningUntilFailure", "ForceSuccess", "Fallback", "Parallel"}
# Behaviors the brief promises beyond those the compat objectives use, with ports MoveIt Pro's
# lab_sim objectives set (reference inventory §5.3).
PROMISED_PORTS = {
    "PlanCartesianPath": {
        "joint_trajectory_msg",
        "path",
        "planning_group_name",
        "position_only",
        "tip_links",
    },
    "GetJointState": {"joint_state", "planning_group_name"},
    "CreatePoseStamped": {"reference_frame", "pose_stamped", "position_xyz", "orientation_xyzw"},
    "TransformPose": {
        "output_pose",
        "input_pose",
        "translation_xyz",
        "quaternion_xyzw",
        "marker_text",
        "visualize_pose",
        "marker_lifetime",
        "marker_size",
    },
    "LogMessage": {"log_level", "message"},
    "WaitForDuration": {"delay_duration"},
    "VisualizePose": {"pose", "marker_name", "marker_lifetime", "marker_size", "marker_text"},
    "RetrieveWaypoint": {"waypoint_joint_state", "waypoint_name", "joint_group_name"},
    "MoveGripperAction": {"gripper_command_action_name", "position", "timeout"},
    "ListControllers": {"type", "controller_list", "state"},
    "CreateRobotState": {"joint_names", "positions"},
    "ExecuteTrajectory": {
        "joint_trajectory_msg",
        "goal_duration_tolerance",
        "controller_action_name",
        "execution_pipeline",
        "goal_position_tolerance",
        "path_position_tolerance",
    },
    "SwitchController": {
        "activate_controllers",
        "deactivate_controllers",
        "controller_switch_action_name",
        "timeout",
        "activate_asap",
        "strictness",
        "controller_list_action_name",
        "automatic_deactivation",
        "automatic_activation",
    },
    "SetMujocoState": set(),
    "PlanToJointGoal": {
        "joint_goal",
        "link_padding",
        "orientation_constraint",
        "acceleration_scale_factor",
        "velocity_scale_factor",
        "planning_group_name",
    },
}


def _ports(registry: BehaviorRegistry, behavior_id: str) -> set[str]:
    return {port.name for port in registry[behavior_id].ports}


@pytest.mark.parametrize("behavior_id", sorted(PROMISED_PORTS))
def test_each_promised_behavior_declares_moveit_pros_ports(
    registry: BehaviorRegistry, behavior_id: str
) -> None:
    assert behavior_id in registry
    missing = PROMISED_PORTS[behavior_id] - _ports(registry, behavior_id)
    assert not missing, f"{behavior_id} lacks ports {sorted(missing)}"


def test_the_compat_objectives_set_only_declared_ports(registry: BehaviorRegistry, shared_dir: Path) -> None:
    files = sorted((shared_dir / "compat" / "moveit_pro" / "objectives").glob("*.xml"))
    assert files
    seen = set()
    for file in files:
        root = parse_xml_file(file)
        for element in root.iter("Action", "Decorator", "Control", "Condition"):
            behavior_id = element.get("ID")
            if behavior_id in BUILTINS:
                continue
            seen.add(behavior_id)
            assert behavior_id in registry, f"{file.name}:{element.sourceline}: no behavior {behavior_id}"
            attributes = {name for name in element.attrib if name not in ("ID", "name")}
            unknown = attributes - _ports(registry, behavior_id)
            assert not unknown, f"{file.name}:{element.sourceline}: {behavior_id} has no port(s) {unknown}"
    assert {"RetrieveWaypoint", "MoveGripperAction", "SwitchController", "ListControllers"} <= seen
    assert {"PlanToJointGoal", "ExecuteTrajectory", "CreateRobotState", "SetMujocoState"} <= seen


def test_output_ports_default_to_moveit_pros_blackboard_keys(registry: BehaviorRegistry) -> None:
    # Objectives rely on default wiring: RetrieveWaypoint -> PlanToJointGoal -> ExecuteTrajectory and
    # CreateRobotState -> SetMujocoState meet on these keys without naming them.
    defaults = {
        (port.name, port.default_str)
        for behavior_id in ("RetrieveWaypoint", "PlanToJointGoal", "ExecuteTrajectory")
        for port in registry[behavior_id].ports
    }
    assert ("waypoint_joint_state", "{target_joint_state}") in defaults
    assert ("joint_goal", "{target_joint_state}") in defaults
    assert ("joint_trajectory_msg", "{joint_trajectory_msg}") in defaults
    robot_state = {
        port.default_str
        for behavior_id in ("CreateRobotState", "SetMujocoState")
        for port in registry[behavior_id].ports
        if port.name == "robot_state"
    }
    # 'Load MuJoCo Robot State' loads into {joint_state_msg} and runs SetMujocoState by default wiring.
    assert robot_state == {"{joint_state_msg}"}


def test_every_bundled_objective_builds_against_the_behaviors(registry: BehaviorRegistry) -> None:
    from kinema.behaviors import BehaviorContext
    from kinema.config import ObjectiveLibrary, resolve_config

    resolved = resolve_config("lab_sim")
    library = ObjectiveLibrary.load(resolved)
    factory = registry.create_factory(BehaviorContext.offline())
    for path in library.files():
        factory.register_behavior_tree_from_file(path)
    names = set(factory.registered_behavior_trees())
    for name in (
        "3 Waypoints Pick and Place",
        "Close Gripper",
        "Open Gripper",
        "Look at Table",
        "Reset MuJoCo Robot",
        "Move to Waypoint",
        "Move to Joint State",
    ):
        assert name in names
        factory.create_tree(name)
