"""The names the agent serves and publishes (MoveIt Pro's where they exist, Kinema's otherwise).

Clients (the SDK, the TUI, ``kinema objective``) import this module only; it imports nothing but
:mod:`kinema.waypoint_services` (which imports nothing).
"""

from __future__ import annotations

NODE_NAME = "objective_server"

EXECUTE_OBJECTIVE = "/execute_objective"
EXECUTE_OBJECTIVE_TYPE = "moveit_studio_sdk_msgs/srv/ExecuteObjective"
CANCEL_OBJECTIVE = "/cancel_objective"
CANCEL_OBJECTIVE_TYPE = "moveit_studio_sdk_msgs/srv/CancelObjective"
DO_OBJECTIVE = "/do_objective"
DO_OBJECTIVE_TYPE = "moveit_studio_sdk_msgs/action/DoObjectiveSequence"
# /do_objective without its XML: library objectives by name (with overrides) only. An operator's
# certificate reaches this one; ad-hoc XML through /do_objective is a separate grant (kinema security).
RUN_OBJECTIVE = "/kinema/run_objective"

HEARTBEAT = "/objective_server_heartbeat"
HEARTBEAT_TYPE = "moveit_studio_agent_msgs/msg/ObjectiveServerStatus"
HEARTBEAT_PERIOD_S = 0.1
# Published with every heartbeat: the watchdog's view (stuck behaviors, replaced tick threads).
HEALTH = "/objective_server/health"
HEALTH_TYPE = "kinema_msgs/msg/ObjectiveServerHealth"

# Node status changes travel column-wise (an integer per change) and name nodes by their index in the
# run's node table, which is published once per run, latched (see kinema.sdk.node_status).
NODE_STATUS = "/objective_server/node_status"
NODE_STATUS_TYPE = "kinema_msgs/msg/NodeStatusCodes"
NODE_TABLE = "/objective_server/node_table"
NODE_TABLE_TYPE = "kinema_msgs/msg/NodeTable"
BLACKBOARD = "/objective_server/blackboard"
BLACKBOARD_TYPE = "kinema_msgs/msg/BlackboardSnapshot"
LOG = "/objective_server/log"
LOG_TYPE = "moveit_studio_agent_msgs/msg/Log"
# The agent's planning scene, as MoveIt's move_group serves it: published (latched) on every change, and
# answered on request (kinema.runtime.planning_scene_service).
PLANNING_SCENE = "/monitored_planning_scene"
PLANNING_SCENE_TYPE = "moveit_msgs/msg/PlanningScene"
GET_PLANNING_SCENE = "/get_planning_scene"
GET_PLANNING_SCENE_TYPE = "moveit_msgs/srv/GetPlanningScene"

LIST_OBJECTIVES = "/objective_server/list_objectives"
LIST_OBJECTIVES_TYPE = "kinema_msgs/srv/ListObjectives"
GET_OBJECTIVE_XML = "/objective_server/get_objective_xml"
GET_OBJECTIVE_XML_TYPE = "kinema_msgs/srv/GetObjectiveXml"

# The waypoint services are defined below the runtime (kinema.waypoint_services), where behaviors reach them.
from kinema.waypoint_services import EDIT_WAYPOINTS_SERVICE as EDIT_WAYPOINTS  # noqa: E402, F401
from kinema.waypoint_services import EDIT_WAYPOINTS_TYPE as EDIT_WAYPOINTS_TYPE  # noqa: E402
from kinema.waypoint_services import GET_WAYPOINTS_SERVICE as GET_WAYPOINTS  # noqa: E402, F401
from kinema.waypoint_services import GET_WAYPOINTS_TYPE as GET_WAYPOINTS_TYPE  # noqa: E402

# Time (/clock) and the robot's state (/joint_states) are the drivers': kinema.drivers.mujoco.names.
