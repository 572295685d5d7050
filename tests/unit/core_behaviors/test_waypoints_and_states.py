"""RetrieveWaypoint, GetJointState and CreateRobotState against fake runtime services and topics."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import publish_repeatedly, tick_behavior

ARM = [
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
]
GRIPPER = "robotiq_85_left_knuckle_joint"


def _waypoint(name: str, positions: list[float]) -> dict[str, Any]:
    return {
        "name": name,
        "joint_group_names": ["manipulator", "gripper"],
        "joint_state": {"name": [GRIPPER, *ARM], "position": positions},
    }


def _serve_waypoints(node: Any, waypoints: list[dict[str, Any]], success: bool = True) -> None:
    def answer(_request: Any) -> dict[str, Any]:
        if not success:
            return {"status": {"success": False, "error_message": "the config has no waypoints file"}}
        return {"status": {"success": True}, "waypoints": waypoints}

    node.create_service("moveit_studio_agent_msgs/srv/GetWaypoints", "/get_saved_waypoints", answer)


def test_retrieve_waypoint_keeps_the_groups_joints(behavior: Any, context: BehaviorContext) -> None:
    _serve_waypoints(context.node, [_waypoint("Pick", [0.5, 0.1, 0.2, -1.0, 1.5, -2.0, -1.57, 0.3])])
    run = tick_behavior(behavior("RetrieveWaypoint"), {"waypoint_name": "Pick"}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    state = run.outputs["waypoint_joint_state"]
    assert list(state.name) == ARM  # the gripper joint is not part of "manipulator"
    assert list(state.position) == [0.1, 0.2, -1.0, 1.5, -2.0, -1.57, 0.3]


def test_retrieve_waypoint_gripper_group(behavior: Any, context: BehaviorContext) -> None:
    _serve_waypoints(context.node, [_waypoint("Pick", [0.5, 0.1, 0.2, -1.0, 1.5, -2.0, -1.57, 0.3])])
    run = tick_behavior(
        behavior("RetrieveWaypoint"),
        {"waypoint_name": "Pick", "joint_group_name": "gripper"},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS
    assert list(run.outputs["waypoint_joint_state"].name) == [GRIPPER]


def test_an_unknown_waypoint_fails_naming_the_close_ones(behavior: Any, context: BehaviorContext) -> None:
    _serve_waypoints(context.node, [_waypoint("3 Waypoint Pick Pose", [0.0] * 8)])
    run = tick_behavior(
        behavior("RetrieveWaypoint"), {"waypoint_name": "3 Waypoint Pick Pos"}, context=context
    )
    assert run.status == NodeStatus.FAILURE
    assert "unknown waypoint '3 Waypoint Pick Pos'" in run.toasts[-1]
    assert "3 Waypoint Pick Pose" in run.toasts[-1]


def test_a_waypoint_naming_a_joint_the_robot_lacks_fails_instead_of_moving_the_others(
    behavior: Any, context: BehaviorContext
) -> None:
    # Edited by hand while the runtime ran: "elbo_joint" for "elbow_joint".
    waypoint = _waypoint("Bad", [0.5, 0.1, 0.2, -1.0, 1.5, -2.0, -1.57, 0.3])
    waypoint["joint_state"]["name"] = [
        n.replace("elbow_joint", "elbo_joint") for n in waypoint["joint_state"]["name"]
    ]
    _serve_waypoints(context.node, [waypoint])
    run = tick_behavior(behavior("RetrieveWaypoint"), {"waypoint_name": "Bad"}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert "waypoint 'Bad' names joint 'elbo_joint'" in run.toasts[-1]
    assert "did you mean 'elbow_joint'" in run.toasts[-1]
    assert "waypoint_joint_state" not in run.outputs


def test_an_unknown_group_fails_with_the_valid_groups(behavior: Any, context: BehaviorContext) -> None:
    _serve_waypoints(context.node, [_waypoint("Pick", [0.0] * 8)])
    run = tick_behavior(
        behavior("RetrieveWaypoint"), {"waypoint_name": "Pick", "joint_group_name": "arm"}, context=context
    )
    assert run.status == NodeStatus.FAILURE
    assert "unknown planning group 'arm'" in run.toasts[-1] and "manipulator" in run.toasts[-1]


def test_retrieve_waypoint_reports_the_services_error(behavior: Any, context: BehaviorContext) -> None:
    _serve_waypoints(context.node, [], success=False)
    run = tick_behavior(behavior("RetrieveWaypoint"), {"waypoint_name": "Pick"}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert "no waypoints file" in run.toasts[-1]


def test_get_joint_state_takes_a_fresh_state_for_a_group(behavior: Any, context: BehaviorContext) -> None:
    state = {"name": [*ARM, GRIPPER], "position": [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.05]}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        run = tick_behavior(behavior("GetJointState"), {"planning_group_name": "gripper"}, context=context)
        everything = tick_behavior(behavior("GetJointState"), context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert list(run.outputs["joint_state"].name) == [GRIPPER]
    assert list(run.outputs["joint_state"].position) == [0.05]
    assert list(everything.outputs["joint_state"].name) == [*ARM, GRIPPER]


def test_get_joint_state_without_a_driver_fails_with_advice(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(behavior("GetJointState"), {"timeout": 0.2}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert "no joint state received on /joint_states" in run.toasts[-1]


def test_create_robot_state(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(
        behavior("CreateRobotState"),
        {"joint_names": ["elbow_joint", "wrist_1_joint"], "positions": [0.5, -0.25]},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS
    state = run.outputs["robot_state"].joint_state
    assert list(state.name) == ["elbow_joint", "wrist_1_joint"]
    assert list(state.position) == [0.5, -0.25]


def test_create_robot_state_checks_names_and_counts(behavior: Any, context: BehaviorContext) -> None:
    mismatch = tick_behavior(
        behavior("CreateRobotState"),
        {"joint_names": ["elbow_joint"], "positions": [0.5, 1.0]},
        context=context,
    )
    assert mismatch.status == NodeStatus.FAILURE
    assert "1 joint names but 2 positions" in mismatch.toasts[-1]
    unknown = tick_behavior(
        behavior("CreateRobotState"), {"joint_names": ["elbow_jiont"], "positions": [0.5]}, context=context
    )
    assert unknown.status == NodeStatus.FAILURE
    assert "unknown joint 'elbow_jiont'" in unknown.toasts[-1] and "elbow_joint" in unknown.toasts[-1]
