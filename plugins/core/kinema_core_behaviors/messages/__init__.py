"""Messages: create ROS messages from ports and unpack them into ports.

Also home of the one way message-typed ports are declared and read (:mod:`.ports`, :mod:`.types`) and of
the conversions between messages and numpy (:mod:`.conversions`), which every family uses.
"""

from __future__ import annotations

from .collision_object import (
    CreateCollisionObjectMessage,
    CreateGraspableObjectMessage,
    UnpackCollisionObjectMessage,
    UnpackGraspableObjectMessage,
)
from .joint_state import UnpackJointStateMessage
from .pose import CreatePointMessage, CreatePoseMessage, UnpackPointMessage, UnpackPoseMessage
from .pose_stamped import CreatePoseStamped, UnpackPoseStampedMessage
from .robot_state import CreateRobotState, UnpackRobotStateMessage
from .string_message import CreateStringMessage, UnpackStringMessage
from .twist_wrench import (
    CreateTwistStamped,
    CreateWrenchStamped,
    UnpackTwistStampedMessage,
    UnpackWrenchStampedMessage,
)

BEHAVIORS = (
    CreatePoseStamped,
    UnpackPoseStampedMessage,
    CreatePoseMessage,
    UnpackPoseMessage,
    CreatePointMessage,
    UnpackPointMessage,
    CreateTwistStamped,
    UnpackTwistStampedMessage,
    CreateWrenchStamped,
    UnpackWrenchStampedMessage,
    CreateStringMessage,
    UnpackStringMessage,
    CreateRobotState,
    UnpackRobotStateMessage,
    UnpackJointStateMessage,
    CreateCollisionObjectMessage,
    UnpackCollisionObjectMessage,
    CreateGraspableObjectMessage,
    UnpackGraspableObjectMessage,
)
