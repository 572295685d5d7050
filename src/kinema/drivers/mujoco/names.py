"""The names and types the MuJoCo driver serves, for clients (behaviors, CLI, viewer) to import.

This module imports nothing heavy, so a client can use the names without loading mujoco.
"""

from __future__ import annotations

CLOCK_TOPIC = "/clock"
CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
JOINT_STATES_TOPIC = "/joint_states"
JOINT_STATES_TYPE = "sensor_msgs/msg/JointState"

FOLLOW_JOINT_TRAJECTORY_TYPE = "control_msgs/action/FollowJointTrajectory"
GRIPPER_COMMAND_TYPE = "control_msgs/action/GripperCommand"

# The node serving the controller manager's services (ros2_control's name).
CONTROLLER_MANAGER_NODE = "controller_manager"
LIST_CONTROLLERS_SERVICE = "/controller_manager/list_controllers"
LIST_CONTROLLERS_TYPE = "controller_manager_msgs/srv/ListControllers"
# ros2_control's controller_manager names the service in the singular; the plural spelling is served too
# because MoveIt Pro documents it that way.
SWITCH_CONTROLLERS_SERVICE = "/controller_manager/switch_controller"
SWITCH_CONTROLLERS_ALIAS = "/controller_manager/switch_controllers"
SWITCH_CONTROLLERS_TYPE = "controller_manager_msgs/srv/SwitchController"

SET_STATE_SERVICE = "/mujoco/set_state"
SET_STATE_TYPE = "kinema_msgs/srv/SetMujocoState"
BODIES_SERVICE = "/mujoco/bodies"
BODIES_TYPE = "kinema_msgs/srv/GetSimBodies"
KEYFRAMES_SERVICE = "/mujoco/keyframes"
KEYFRAMES_TYPE = "kinema_msgs/srv/ListKeyframes"
SCENE_STATE_TOPIC = "/mujoco/scene_state"
SCENE_STATE_TYPE = "kinema_msgs/msg/SceneState"

# ros2_control's conventional controller names (a config may name its controllers otherwise: what each
# controller is comes from the config, kinema.config.cell). A controller serves its interfaces under its
# own name, as ros2_control's do.
JOINT_TRAJECTORY_CONTROLLER = "joint_trajectory_controller"
JOINT_TRAJECTORY_ADMITTANCE_CONTROLLER = "joint_trajectory_admittance_controller"
VELOCITY_FORCE_CONTROLLER = "velocity_force_controller"
FORCE_TORQUE_SENSOR_BROADCASTER = "force_torque_sensor_broadcaster"
JOINT_STATE_BROADCASTER = "joint_state_broadcaster"
VELOCITY_FORCE_COMMAND_TYPE = "moveit_pro_controllers_msgs/msg/VelocityForceCommand"
FOLLOW_JOINT_TRAJECTORY_WITH_ADMITTANCE_TYPE = (
    "moveit_pro_controllers_msgs/action/FollowJointTrajectoryWithAdmittance"
)
TRIGGER_TYPE = "std_srvs/srv/Trigger"
WRENCH_TYPE = "geometry_msgs/msg/WrenchStamped"


def follow_joint_trajectory_action(controller: str) -> str:
    """A trajectory controller's FollowJointTrajectory action: ``/<controller>/follow_joint_trajectory``."""
    return f"/{controller}/follow_joint_trajectory"


def gripper_command_action(controller: str) -> str:
    """A gripper controller's GripperCommand action: ``/<controller>/gripper_cmd``."""
    return f"/{controller}/gripper_cmd"


def wrench_topic(broadcaster: str) -> str:
    """A force/torque sensor broadcaster's WrenchStamped topic: ``/<broadcaster>/wrench``."""
    return f"/{broadcaster}/wrench"


def velocity_force_command_topic(controller: str) -> str:
    """A velocity-force controller's command topic: ``/<controller>/command``."""
    return f"/{controller}/command"


def zero_fts_service(controller: str) -> str:
    """A velocity-force controller's sensor-zeroing service: ``/<controller>/zero_fts``."""
    return f"/{controller}/zero_fts"


def admittance_zero_fts_service(controller: str, sensor_frame: str) -> str:
    """An admittance controller's sensor-zeroing service: ``/<controller>/zero_fts/<sensor frame>``."""
    return f"/{controller}/zero_fts/{sensor_frame}"


# The names of ros2_control's conventional controllers, for clients that use those.
FOLLOW_JOINT_TRAJECTORY_ACTION = follow_joint_trajectory_action(JOINT_TRAJECTORY_CONTROLLER)
FOLLOW_JOINT_TRAJECTORY_ADMITTANCE_ACTION = follow_joint_trajectory_action(
    JOINT_TRAJECTORY_ADMITTANCE_CONTROLLER
)
VELOCITY_FORCE_COMMAND_TOPIC = velocity_force_command_topic(VELOCITY_FORCE_CONTROLLER)
ZERO_FTS_SERVICE = zero_fts_service(VELOCITY_FORCE_CONTROLLER)
WRENCH_TOPIC = wrench_topic(FORCE_TORQUE_SENSOR_BROADCASTER)

# Each MuJoCo camera is served as MoveIt Pro's lab_sim serves it: /<camera>/color, /<camera>/depth,
# /<camera>/camera_info and /<camera>/points (an organised cloud in the camera's optical frame).
IMAGE_TYPE = "sensor_msgs/msg/Image"
CAMERA_INFO_TYPE = "sensor_msgs/msg/CameraInfo"
POINT_CLOUD_TYPE = "sensor_msgs/msg/PointCloud2"
CAMERA_STREAMS = {
    "color": IMAGE_TYPE,
    "depth": IMAGE_TYPE,
    "camera_info": CAMERA_INFO_TYPE,
    "points": POINT_CLOUD_TYPE,
}


def camera_topic(camera: str, stream: str) -> str:
    """The topic of ``stream`` (color, depth, camera_info, points) of ``camera``: ``/<camera>/<stream>``."""
    return f"/{camera}/{stream}"
