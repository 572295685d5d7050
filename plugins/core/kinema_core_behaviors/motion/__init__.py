"""Motion: planning, execution, trajectories, the joint state and the gripper."""

from __future__ import annotations

from .execute_trajectory import ExecuteTrajectory
from .get_joint_state import GetJointState
from .move_gripper_action import MoveGripperAction
from .plan_cartesian_path import PlanCartesianPath
from .plan_to_joint_goal import PlanToJointGoal

BEHAVIORS = (ExecuteTrajectory, GetJointState, MoveGripperAction, PlanCartesianPath, PlanToJointGoal)
