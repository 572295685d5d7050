"""The message port types the core behaviors use, named once (see :mod:`kinema.behaviors.message_type`)."""

from __future__ import annotations

from kinema.behaviors.message_type import MessageTypeMeta, message_type, ros_type_of_port_type

__all__ = ["MessageTypeMeta", "message_type", "ros_type_of_port_type"]

POSE_STAMPED = message_type("geometry_msgs/msg/PoseStamped")
POSE = message_type("geometry_msgs/msg/Pose")
POINT = message_type("geometry_msgs/msg/Point")
QUATERNION = message_type("geometry_msgs/msg/Quaternion")
VECTOR3 = message_type("geometry_msgs/msg/Vector3")
TWIST = message_type("geometry_msgs/msg/Twist")
TWIST_STAMPED = message_type("geometry_msgs/msg/TwistStamped")
WRENCH = message_type("geometry_msgs/msg/Wrench")
WRENCH_STAMPED = message_type("geometry_msgs/msg/WrenchStamped")
HEADER = message_type("std_msgs/msg/Header")
STRING = message_type("std_msgs/msg/String")
COLOR_RGBA = message_type("std_msgs/msg/ColorRGBA")
JOINT_STATE = message_type("sensor_msgs/msg/JointState")
MULTI_DOF_JOINT_STATE = message_type("sensor_msgs/msg/MultiDOFJointState")
IMAGE = message_type("sensor_msgs/msg/Image")
POINT_CLOUD2 = message_type("sensor_msgs/msg/PointCloud2")
JOINT_TRAJECTORY = message_type("trajectory_msgs/msg/JointTrajectory")
ROBOT_STATE = message_type("moveit_msgs/msg/RobotState")
COLLISION_OBJECT = message_type("moveit_msgs/msg/CollisionObject")
OBJECT_TYPE = message_type("object_recognition_msgs/msg/ObjectType")
SOLID_PRIMITIVE = message_type("shape_msgs/msg/SolidPrimitive")
MESH = message_type("shape_msgs/msg/Mesh")
PLANE = message_type("shape_msgs/msg/Plane")
GRASPABLE_OBJECT = message_type("moveit_studio_vision_msgs/msg/GraspableObject")
