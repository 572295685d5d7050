"""Core and MuJoCo behaviors against lab_sim's running driver: plan, execute, grip, switch, reset, wait."""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import tick_behavior

pytestmark = pytest.mark.slow

ARM = [
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
]
LOOK_AT_TABLE = [-0.1333, 0.0, -2.08806, 1.90997, -2.0927, -1.57079, 0.0]


def _arm(behavior: Any, context: BehaviorContext) -> np.ndarray:
    run = tick_behavior(behavior("GetJointState"), {"planning_group_name": "manipulator"}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    state = run.outputs["joint_state"]
    assert list(state.name) == ARM
    return np.array(state.position)


def _settled_arm(behavior: Any, context: BehaviorContext, timeout: float = 60.0) -> np.ndarray:
    """The arm's positions once it has stopped moving (an earlier test's motion may still be settling).

    Settled: two readings 0.25 s of simulated time apart agree within 0.2 mrad.
    """
    deadline = time.monotonic() + timeout
    seen = [_arm(behavior, context)]
    while time.monotonic() < deadline:
        until = context.clock.now() + 0.25
        while context.clock.now() < until and time.monotonic() < deadline:
            time.sleep(0.005)
        seen.append(_arm(behavior, context))
        if np.max(np.abs(seen[-1] - seen[-2])) < 2e-4:
            return seen[-1]
    pytest.fail(f"the arm did not settle within {timeout} s; last readings: {seen[-5:]}")


def _goal(positions: list[float]) -> Any:
    from kinema.transport import from_dict

    return from_dict("sensor_msgs/msg/JointState", {"name": ARM, "position": positions})


def _plan_and_execute(behavior: Any, context: BehaviorContext, positions: list[float]) -> Any:
    plan = tick_behavior(
        behavior("PlanToJointGoal"), {"joint_goal": _goal(positions)}, context=context, timeout=30
    )
    assert plan.status == NodeStatus.SUCCESS, plan.toasts
    return tick_behavior(
        behavior("ExecuteTrajectory"),
        {"joint_trajectory_msg": plan.outputs["joint_trajectory_msg"]},
        context=context,
    )


def test_planned_trajectories_bring_the_arm_to_the_goal(behavior: Any, context: BehaviorContext) -> None:
    run = _plan_and_execute(behavior, context, LOOK_AT_TABLE)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    # Read once the arm has stopped: on a loaded machine the joint state read right after the result
    # could be one sent while the arm was still on its way.
    np.testing.assert_allclose(_settled_arm(behavior, context), LOOK_AT_TABLE, atol=0.01)


def test_a_trajectory_with_unknown_joint_names_is_rejected(behavior: Any, context: BehaviorContext) -> None:
    from kinema.transport import from_dict

    before = _settled_arm(behavior, context)
    names = ["linear_rail_joint", "elbow_jiont"]
    trajectory = from_dict(
        "trajectory_msgs/msg/JointTrajectory",
        {
            "joint_names": names,
            "points": [
                {"positions": [0.0, 1.0], "time_from_start": {"sec": 0}},
                {"positions": [0.1, 1.2], "time_from_start": {"sec": 1}},
            ],
        },
    )
    run = tick_behavior(behavior("ExecuteTrajectory"), {"joint_trajectory_msg": trajectory}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert "elbow_jiont" in run.toasts[-1] and "elbow_joint" in run.toasts[-1], run.toasts
    after = _settled_arm(behavior, context)
    np.testing.assert_allclose(after, before, atol=1e-3, err_msg="the rejected trajectory moved the arm")


def test_the_gripper_closes_and_opens(behavior: Any, context: BehaviorContext) -> None:
    closed = tick_behavior(behavior("MoveGripperAction"), {"position": 0.7929}, context=context)
    assert closed.status == NodeStatus.SUCCESS, closed.toasts
    state = tick_behavior(behavior("GetJointState"), {"planning_group_name": "gripper"}, context=context)
    assert state.outputs["joint_state"].position[0] > 0.7
    opened = tick_behavior(behavior("MoveGripperAction"), {"position": 0.0}, context=context)
    assert opened.status == NodeStatus.SUCCESS, opened.toasts


def _active_command_controllers(behavior: Any, context: BehaviorContext) -> set[str]:
    listing = tick_behavior(
        behavior("ListControllers"), {"type": "command", "state": "active"}, context=context
    )
    return set(listing.outputs["controller_list"])


def test_execution_activates_its_controller_when_it_is_inactive(
    behavior: Any, context: BehaviorContext
) -> None:
    assert _active_command_controllers(behavior, context) == {
        "joint_trajectory_controller",
        "robotiq_gripper_controller",
    }
    off = tick_behavior(
        behavior("SwitchController"),
        {"deactivate_controllers": "joint_trajectory_controller"},
        context=context,
    )
    assert off.status == NodeStatus.SUCCESS, off.toasts
    assert _active_command_controllers(behavior, context) == {"robotiq_gripper_controller"}
    start = _arm(behavior, context).tolist()
    target = list(start)
    target[1] += 0.3
    run = _plan_and_execute(behavior, context, target)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert "ExecuteTrajectory: activated joint_trajectory_controller to execute" in run.toasts, run.toasts
    np.testing.assert_allclose(_settled_arm(behavior, context), target, atol=0.01)

    # The admittance controller's action takes the arm over from the trajectory controller, as lab_sim's
    # "Pick All Bottles with AprilTags" expects right after "Pick from Pose".
    plan = tick_behavior(
        behavior("PlanToJointGoal"), {"joint_goal": _goal(start)}, context=context, timeout=30
    )
    assert plan.status == NodeStatus.SUCCESS, plan.toasts
    back = tick_behavior(
        behavior("ExecuteTrajectory"),
        {
            "joint_trajectory_msg": plan.outputs["joint_trajectory_msg"],
            "controller_action_name": "/joint_trajectory_admittance_controller/follow_joint_trajectory",
        },
        context=context,
    )
    assert back.status == NodeStatus.SUCCESS, back.toasts
    assert (
        "ExecuteTrajectory: activated joint_trajectory_admittance_controller instead of "
        "joint_trajectory_controller to execute"
    ) in back.toasts, back.toasts
    assert _active_command_controllers(behavior, context) == {
        "joint_trajectory_admittance_controller",
        "robotiq_gripper_controller",
    }
    np.testing.assert_allclose(_settled_arm(behavior, context), start, atol=0.01)
    restored = tick_behavior(
        behavior("SwitchController"), {"activate_controllers": "joint_trajectory_controller"}, context=context
    )
    assert restored.status == NodeStatus.SUCCESS, restored.toasts


def test_set_mujoco_state_jumps_the_arm(behavior: Any, context: BehaviorContext) -> None:
    upright = [0.0, 0.0, -1.57, 0.0, 0.0, 0.0, 0.0]
    state = tick_behavior(
        behavior("CreateRobotState"), {"joint_names": ARM, "positions": upright}, context=context
    ).outputs["robot_state"]
    run = tick_behavior(behavior("SetMujocoState"), {"robot_state": state}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    np.testing.assert_allclose(_arm(behavior, context), upright, atol=0.02)
    home = tick_behavior(
        behavior("SetMujocoState"), {"keyframe": "home", "robot_state": None}, context=context
    )
    assert home.status == NodeStatus.SUCCESS, home.toasts
    np.testing.assert_allclose(
        _arm(behavior, context), [0.0, 0.0, -2.0, 2.0, -1.5708, -1.5708, 0.0], atol=0.02
    )


def test_wait_for_duration_counts_sim_time(behavior: Any, context: BehaviorContext) -> None:
    before = context.clock.now()
    # 3 s of sim time: the wall-clock bound is for a hang only (a loaded machine runs the sim slower).
    run = tick_behavior(behavior("WaitForDuration"), {"delay_duration": 3.0}, context=context, timeout=120)
    assert run.status == NodeStatus.SUCCESS
    # 6.61 + 3.0 == 9.61 but 9.61 - 6.61 < 3.0 in floating point: compare with the deadline's rounding.
    assert context.clock.now() - before >= 3.0 - 1e-9
