"""The names and types the MuJoCo driver serves, for clients (behaviors, CLI, viewer) to import.

This module imports nothing heavy, so a client can use the names without loading mujoco.
"""

from __future__ import annotations

CLOCK_TOPIC = "/clock"
CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
JOINT_STATES_TOPIC = "/joint_states"
JOINT_STATES_TYPE = "sensor_msgs/msg/JointState"

FOLLOW_JOINT_TRAJECTORY_ACTION = "/joint_trajectory_controller/follow_joint_trajectory"
FOLLOW_JOINT_TRAJECTORY_TYPE = "control_msgs/action/FollowJointTrajectory"
GRIPPER_COMMAND_ACTION = "/robotiq_gripper_controller/gripper_cmd"
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

JOINT_TRAJECTORY_CONTROLLER = "joint_trajectory_controller"
# The wrist force/torque sensor and the controllers using it (MoveIt Pro's lab_sim names).
JOINT_TRAJECTORY_ADMITTANCE_CONTROLLER = "joint_trajectory_admittance_controller"
FOLLOW_JOINT_TRAJECTORY_ADMITTANCE_ACTION = "/joint_trajectory_admittance_controller/follow_joint_trajectory"
VELOCITY_FORCE_CONTROLLER = "velocity_force_controller"
VELOCITY_FORCE_COMMAND_TOPIC = "/velocity_force_controller/command"
VELOCITY_FORCE_COMMAND_TYPE = "moveit_pro_controllers_msgs/msg/VelocityForceCommand"
ZERO_FTS_SERVICE = "/velocity_force_controller/zero_fts"
TRIGGER_TYPE = "std_srvs/srv/Trigger"
FORCE_TORQUE_SENSOR_BROADCASTER = "force_torque_sensor_broadcaster"
WRENCH_TOPIC = "/force_torque_sensor_broadcaster/wrench"
WRENCH_TYPE = "geometry_msgs/msg/WrenchStamped"
GRIPPER_CONTROLLER = "robotiq_gripper_controller"
JOINT_STATE_BROADCASTER = "joint_state_broadcaster"

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
