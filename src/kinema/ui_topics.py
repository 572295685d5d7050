"""The names between behaviors and Kinema's UIs: the 3D view (``kinema view``) and the terminal UI.

Behaviors run in the agent and publish on these topics (the view and the TUI subscribe), or call the TUI's
approval service. The names are defined here, below both, so a behavior reaches a UI without loading it and
a UI listens without loading the behavior SDK. This module imports nothing. (The agent's own names are
:mod:`kinema.runtime.names`, the drivers' :mod:`kinema.drivers.mujoco.names`.)
"""

from __future__ import annotations

# The joint trajectory a planning behavior just produced (and ExecuteTrajectory is about to run); the view
# draws the end effector's path along it.
PLANNED_TRAJECTORY_TOPIC = "/kinema/planned_trajectory"
PLANNED_TRAJECTORY_TYPE = "trajectory_msgs/msg/JointTrajectory"

# RViz's marker topics (VisualizePose publishes on the array topic).
MARKER_ARRAY_TOPIC = "/visualization_marker_array"
MARKER_ARRAY_TYPE = "visualization_msgs/msg/MarkerArray"
MARKER_TOPIC = "/visualization_marker"
MARKER_TYPE = "visualization_msgs/msg/Marker"

# ROS's transform topic: PublishTF sends the frames it publishes here; the view places markers in them.
TF_TOPIC = "/tf"
TF_TYPE = "tf2_msgs/msg/TFMessage"

# The task PlanMTCTask plans, stage by stage, while it plans (the TUI's task panel).
TASK_PLANNING_TOPIC = "/kinema/task_planning"
TASK_PLANNING_TYPE = "kinema_msgs/msg/TaskPlanningStatus"

# Served by the terminal UI while it runs: a behavior asking the operator (GetUserApproval and friends)
# calls it, and fails over to its headless rule when nobody serves it.
APPROVAL_SERVICE = "/kinema/user_approval"
APPROVAL_TYPE = "kinema_msgs/srv/RequestApproval"

# Served by the terminal UI too: a behavior asking the operator for a value (RetrievePoseParameter: a pose;
# GetPointsFromUser: points on an image; DoTeleoperateAction: a teleoperation session) calls it, and follows
# the same headless rule as the approvals when nobody serves it.
USER_INPUT_SERVICE = "/kinema/user_input"
USER_INPUT_TYPE = "kinema_msgs/srv/RequestUserInput"
# While a teleoperation session is open the UI publishes the mode the user picks (std_msgs/UInt8, the values
# of moveit_studio_sdk_msgs/TeleoperationMode); DoTeleoperateAction writes it to its current_teleop_mode.
TELEOPERATION_MODE_TOPIC = "/kinema/teleoperation_mode"
TELEOPERATION_MODE_TYPE = "std_msgs/msg/UInt8"
