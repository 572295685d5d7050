"""Kinema's transport: a ROS-2-like node API on zenoh, speaking rmw_zenoh's wire format.

Quick tour::

    from kinema.transport import Node, open_session, msg

    with open_session() as session:                       # joins the router at tcp/127.0.0.1:7447
        node = Node(session, "demo")
        pub = node.create_publisher("std_msgs/msg/String", "/chatter")
        pub.publish(msg("std_msgs/msg/String", data="hello"))
        client = node.create_client("example_interfaces/srv/AddTwoInts", "/add_two_ints")
        print(client.call({"a": 1, "b": 2}, timeout=2.0).sum)

Keys, attachments, tokens and CDR payloads are those of rmw_zenoh, so ROS 2 nodes running
``rmw_zenoh_cpp`` on the same zenoh network see Kinema's topics, services and actions and vice versa.
"""

from __future__ import annotations

from kinema.transport.action import (
    STATUS_ABORTED,
    STATUS_ACCEPTED,
    STATUS_CANCELED,
    STATUS_CANCELING,
    STATUS_EXECUTING,
    STATUS_NAMES,
    STATUS_SUCCEEDED,
    STATUS_UNKNOWN,
    ActionClient,
    ActionServer,
    ClientGoalHandle,
    GoalResult,
    ServerGoalHandle,
)
from kinema.transport.attachment import Attachment
from kinema.transport.graph import Graph, GraphCache, query_graph
from kinema.transport.keys import KEEP_ALL_QOS, LATCHED_QOS, QoS
from kinema.transport.messages import from_dict, msg, parse_yaml_flow, to_dict, to_yaml, type_of
from kinema.transport.node import Node
from kinema.transport.pubsub import MessageInfo, Publisher, Subscription
from kinema.transport.service import Responder, ServiceClient, ServiceServer
from kinema.transport.session import (
    DEFAULT_ENDPOINT,
    Session,
    free_endpoint,
    host_or_join,
    host_router,
    open_session,
    resolve_domain_id,
    resolve_endpoints,
)

__all__ = [
    "DEFAULT_ENDPOINT",
    "KEEP_ALL_QOS",
    "LATCHED_QOS",
    "STATUS_ABORTED",
    "STATUS_ACCEPTED",
    "STATUS_CANCELED",
    "STATUS_CANCELING",
    "STATUS_EXECUTING",
    "STATUS_NAMES",
    "STATUS_SUCCEEDED",
    "STATUS_UNKNOWN",
    "ActionClient",
    "ActionServer",
    "Attachment",
    "ClientGoalHandle",
    "GoalResult",
    "Graph",
    "GraphCache",
    "MessageInfo",
    "Node",
    "Publisher",
    "QoS",
    "Responder",
    "ServerGoalHandle",
    "ServiceClient",
    "ServiceServer",
    "Session",
    "Subscription",
    "free_endpoint",
    "from_dict",
    "host_or_join",
    "host_router",
    "msg",
    "open_session",
    "parse_yaml_flow",
    "query_graph",
    "resolve_domain_id",
    "resolve_endpoints",
    "to_dict",
    "to_yaml",
    "type_of",
]
