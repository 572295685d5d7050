"""Core behaviors: waypoints, planning, execution, controllers, gripper, poses, logging, waiting.

Loaded by ``kinema::CoreBehaviorsLoader`` (alias ``moveit_pro::behaviors::CoreBehaviorsLoader``). IDs and
ports are MoveIt Pro's, so its objectives run unchanged. Planning runs in the agent (``kinema.motion``);
execution goes to the driver's controllers over the transport.
"""

from __future__ import annotations

from kinema.plugins import RegisterBehavior, hookimpl

from .create_pose_stamped import CreatePoseStamped
from .create_robot_state import CreateRobotState
from .execute_trajectory import ExecuteTrajectory
from .get_joint_state import GetJointState
from .list_controllers import ListControllers
from .log_message import LogMessage
from .move_gripper_action import MoveGripperAction
from .plan_cartesian_path import PlanCartesianPath
from .plan_to_joint_goal import PlanToJointGoal
from .retrieve_waypoint import RetrieveWaypoint
from .switch_controller import SwitchController
from .transform_pose import TransformPose
from .visualize_pose import VisualizePose
from .wait_for_duration import WaitForDuration

BEHAVIORS = (
    CreatePoseStamped,
    CreateRobotState,
    ExecuteTrajectory,
    GetJointState,
    ListControllers,
    LogMessage,
    MoveGripperAction,
    PlanCartesianPath,
    PlanToJointGoal,
    RetrieveWaypoint,
    SwitchController,
    TransformPose,
    VisualizePose,
    WaitForDuration,
)


@hookimpl
def register_behaviors(register: RegisterBehavior) -> None:
    """Register the core behaviors under their class names (MoveIt Pro's IDs)."""
    for behavior in BEHAVIORS:
        register(behavior)
