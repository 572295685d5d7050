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

Names are imported on first use: ``kinema.transport.session`` (say, for the endpoint a CLI verb joins) does
not load numpy or the ROS type system.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from kinema.lazy_exports import LazyExports

_EXPORTS = {
    "DEFAULT_ENDPOINT": "session",
    "KEEP_ALL_QOS": "keys",
    "LATCHED_QOS": "keys",
    "STATUS_ABORTED": "action",
    "STATUS_ACCEPTED": "action",
    "STATUS_CANCELED": "action",
    "STATUS_CANCELING": "action",
    "STATUS_EXECUTING": "action",
    "STATUS_NAMES": "action",
    "STATUS_SUCCEEDED": "action",
    "STATUS_UNKNOWN": "action",
    "ActionClient": "action",
    "ActionServer": "action",
    "Attachment": "attachment",
    "ClientGoalHandle": "action",
    "GoalResult": "action",
    "Graph": "graph",
    "GraphCache": "graph",
    "MessageInfo": "pubsub",
    "Node": "node",
    "Publisher": "pubsub",
    "QoS": "keys",
    "Responder": "service",
    "ServerGoalHandle": "action",
    "ServiceClient": "service",
    "ServiceServer": "service",
    "Session": "session",
    "Subscription": "pubsub",
    "free_endpoint": "session",
    "from_dict": "messages",
    "host_or_join": "session",
    "host_router": "session",
    "msg": "messages",
    "open_session": "session",
    "parse_yaml_flow": "messages",
    "query_graph": "graph",
    "resolve_domain_id": "session",
    "resolve_endpoints": "session",
    "to_dict": "messages",
    "to_yaml": "messages",
    "type_of": "messages",
}
_lazy = LazyExports(__name__, _EXPORTS)

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

if TYPE_CHECKING:
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


def __getattr__(name: str) -> Any:
    return _lazy.attribute(name)
