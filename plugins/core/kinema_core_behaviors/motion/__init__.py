"""Motion: planning, execution, trajectories, the joint state and the gripper."""

from __future__ import annotations

from .compute_inverse_kinematics import ComputeInverseKinematics
from .create_stationary_trajectory import CreateStationaryTrajectory
from .execute_trajectory import ExecuteTrajectory
from .execute_trajectory_with_admittance import ExecuteTrajectoryWithAdmittance
from .generate_coverage_path import GenerateCoveragePath
from .generate_point_to_point_trajectory import GeneratePointToPointTrajectory
from .get_joint_state import GetJointState
from .get_robot_state_from_trajectory import GetRobotStateFromTrajectory
from .move_gripper_action import MoveGripperAction
from .plan_cartesian_path import PlanCartesianPath
from .plan_to_joint_goal import PlanToJointGoal
from .save_current_state import SaveCurrentState
from .validate_trajectory import ValidateTrajectory

BEHAVIORS = (
    ComputeInverseKinematics,
    CreateStationaryTrajectory,
    ExecuteTrajectory,
    ExecuteTrajectoryWithAdmittance,
    GetJointState,
    GetRobotStateFromTrajectory,
    MoveGripperAction,
    PlanCartesianPath,
    PlanToJointGoal,
    ValidateTrajectory,
    GenerateCoveragePath,
    GeneratePointToPointTrajectory,
    SaveCurrentState,
)
