"""The topics the 3D view draws from, besides the driver's and the agent's own.

This module imports nothing, so behaviors can publish on these names without loading the viewer.
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

# The agent's planning scene (collision objects objectives added), latched; the view draws its objects.
PLANNING_SCENE_TOPIC = "/monitored_planning_scene"
PLANNING_SCENE_TYPE = "moveit_msgs/msg/PlanningScene"
