"""Kinema's own lab_sim and core objectives (same names as MoveIt Pro's) run on lab_sim."""

from __future__ import annotations

import threading
from typing import Any

import pytest
from compat_cell import Cell
from objective_checks import (
    MOVEIT_PRO_OBJECTIVES,
    arm_at_waypoint,
    joint_positions,
    run_and_expect_success,
    run_pick_and_place_two_placements,
)

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def cell(start_cell) -> Cell:
    return start_cell(objectives=None)


def test_kinemas_libraries_provide_the_moveit_pro_names(cell: Cell) -> None:
    infos = {info.name: info for info in cell.client.objectives()}
    for expected in MOVEIT_PRO_OBJECTIVES:
        assert expected in infos
    # The subtrees MoveIt Pro objectives call have MoveIt Pro's ports.
    ports = {port.name for port in infos["Move to Waypoint"].ports}
    assert ports == {
        "waypoint_name",
        "joint_group_name",
        "link_padding",
        "keep_orientation_tolerance",
        "keep_orientation",
        "velocity_scale_factor",
        "acceleration_scale_factor",
        "controller_names",
        "controller_action_server",
    }
    ports = {port.name for port in infos["Move to Joint State"].ports}
    assert ports == {
        "target_joint_state",
        "joint_group_name",
        "link_padding",
        "orientation_constraint",
        "velocity_scale_factor",
        "acceleration_scale_factor",
        "controller_names",
        "controller_action_server",
    }


def test_close_and_open_gripper_succeed(cell: Cell) -> None:
    run_and_expect_success(cell, "Close Gripper")
    run_and_expect_success(cell, "Open Gripper")


def test_look_at_table_moves_the_arm_to_its_waypoint(cell: Cell) -> None:
    run_and_expect_success(cell, "Look at Table")
    arm_at_waypoint(cell, "Look at Table")


def test_reset_mujoco_robot_puts_the_arm_upright(cell: Cell) -> None:
    run_and_expect_success(cell, "Reset MuJoCo Robot")
    state = joint_positions(cell)
    assert abs(state["shoulder_lift_joint"] + 1.57) < 0.02
    run_and_expect_success(cell, "Look at Table")


def test_pick_and_place_moves_the_cube_to_the_tray_and_back_and_loops(cell: Cell) -> None:
    run_pick_and_place_two_placements(cell)


# A pick as Kinema's lab_sim writes one: down to the waypoint, close with the grasp check, lift.
PICK_AT = """<root BTCPP_format="4" main_tree_to_execute="Pick Test">
  <BehaviorTree ID="Pick Test">
    {body}
  </BehaviorTree>
  <BehaviorTree ID="Pick at Waypoint">
    <Control ID="Sequence">
      <SubTree ID="Move to Waypoint" waypoint_name="{{waypoint}}" />
      <SubTree ID="Close Gripper" require_grasp="true" />
      <SubTree ID="Move to Waypoint" waypoint_name="3 Waypoint Mid Point" />
    </Control>
  </BehaviorTree>
</root>"""


def _pick(waypoint: str, *, forced: bool = False) -> str:
    pick = f'<SubTree ID="Pick at Waypoint" waypoint="{waypoint}" />'
    if forced:
        pick = f'<Decorator ID="ForceSuccess">{pick}</Decorator>'
    body = (
        '<Control ID="Sequence"><SubTree ID="Move to Waypoint" waypoint_name="3 Waypoint Mid Point" />'
        f'<SubTree ID="Open Gripper" />{pick}</Control>'
    )
    return PICK_AT.format(body=body)


def test_a_pick_that_closes_on_nothing_fails_unless_the_objective_forces_success(cell: Cell) -> None:
    # The cube back on the table and the tray empty, whatever an earlier test left.
    run_and_expect_success(cell, "Reset MuJoCo Scene")
    try:
        # The tray ("3 Waypoint Place Pose") is empty: the fingers meet nothing.
        air = cell.client.do_xml(_pick("3 Waypoint Place Pose"), timeout=300)
        assert air.failed, air
        assert "the gripper closed on nothing" in air.error_message, air
        assert joint_positions(cell)["robotiq_85_left_knuckle_joint"] > 0.75
        forced = cell.client.do_xml(_pick("3 Waypoint Place Pose", forced=True), timeout=300)
        assert forced.succeeded, forced
        # Closing an empty gripper on purpose still succeeds (MoveIt Pro's Close Gripper, Push Button).
        run_and_expect_success(cell, "Close Gripper")
        # The cube at "3 Waypoint Pick Pose" stops the fingers: the same pick succeeds and lifts it.
        before = cell.cube()
        cube = cell.client.do_xml(_pick("3 Waypoint Pick Pose"), timeout=300)
        assert cube.succeeded, cube
        assert cell.cube()[2] - before[2] > 0.05, f"the cube went from {before} to {cell.cube()}"
    finally:
        run_and_expect_success(cell, "Reset MuJoCo Scene")


LOOK_AT_TABLE = {
    "linear_rail_joint": -0.1333,
    "shoulder_pan_joint": 0.0,
    "shoulder_lift_joint": -2.08806,
    "elbow_joint": 1.90997,
    "wrist_1_joint": -2.0927,
    "wrist_2_joint": -1.57079,
    "wrist_3_joint": 0.0,
}
TELEOPERATE_JOINT_VALUES = """<root BTCPP_format="4" main_tree_to_execute="Teleoperate Joints">
  <BehaviorTree ID="Teleoperate Joints">
    <SubTree ID="Request Teleoperation" initial_teleop_mode="5" user_interaction_prompt="Move the arm" />
  </BehaviorTree>
</root>"""


def test_teleoperation_moves_the_arm_to_the_joint_values_the_user_gives(cell: Cell) -> None:
    """Mode 5 (MoveIt Pro's joint sliders): RetrieveRobotStateParameter asks the UI, the arm goes there."""
    from kinema.transport import from_dict

    run_and_expect_success(cell, "Reset MuJoCo Scene")
    asked: list[Any] = []
    session_end = threading.Event()
    mode = cell.node.create_publisher("std_msgs/msg/UInt8", "/kinema/teleoperation_mode")

    def serve(request: Any, responder: Any) -> None:
        asked.append(request)
        if request.kind == "teleoperate":
            # The session stays open until the user is done (below); then the objective goes on.
            def end_session() -> None:
                if session_end.wait(110):
                    responder.reply({"accepted": True})

            threading.Thread(target=end_session, daemon=True).start()
        elif len([r for r in asked if r.kind == "joint_state"]) == 1:
            target = {"name": list(LOOK_AT_TABLE), "position": list(LOOK_AT_TABLE.values())}
            responder.reply({"accepted": True, "joint_state": target})
        else:
            # Asked again once the arm is there: the user closes the form and ends the session, as the
            # TUI does (a declined question ends the mode).
            responder.reply({"accepted": False, "message": "done"})
            mode.publish(from_dict("std_msgs/msg/UInt8", {"data": 0}))
            session_end.set()

    server = cell.node.create_service(
        "kinema_msgs/srv/RequestUserInput", "/kinema/user_input", serve, deferred=True, max_concurrent=4
    )
    try:
        result = cell.client.do_xml(TELEOPERATE_JOINT_VALUES, timeout=120)
        assert result.succeeded, result
        first = next(r for r in asked if r.kind == "joint_state")
        assert list(first.initial_joint_state.name) == list(LOOK_AT_TABLE)
        arm_at_waypoint(cell, "Look at Table")
    finally:
        server.close()
        mode.close()
