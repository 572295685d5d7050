"""The agent's services on the config's waypoints, with MoveIt Pro's names and types.

The runtime serves them (:mod:`kinema.runtime.names` re-exports them); behaviors (RetrieveWaypoint) and
the UIs call them. Defined here, below both, so a behavior reaches them without importing the runtime.
This module imports nothing.
"""

from __future__ import annotations

GET_WAYPOINTS_SERVICE = "/get_saved_waypoints"
GET_WAYPOINTS_TYPE = "moveit_studio_agent_msgs/srv/GetWaypoints"
EDIT_WAYPOINTS_SERVICE = "/edit_waypoints"
EDIT_WAYPOINTS_TYPE = "moveit_studio_agent_msgs/srv/EditWaypoints"
