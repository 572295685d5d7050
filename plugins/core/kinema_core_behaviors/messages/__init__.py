"""Messages: create ROS messages from ports and unpack them into ports.

Also home of the one way message-typed ports are declared and read (:mod:`.ports`, :mod:`.types`) and of
the conversions between messages and numpy (:mod:`.conversions`), which every family uses.
"""

from __future__ import annotations

from .pose_stamped import CreatePoseStamped
from .robot_state import CreateRobotState

BEHAVIORS = (CreatePoseStamped, CreateRobotState)
