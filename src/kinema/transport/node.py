"""A node: a named participant of the ROS graph that owns publishers, subscriptions, services, actions."""

from __future__ import annotations

import logging
import re
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, overload

from kinema.errors import TransportError
from kinema.interfaces.definition import (
    ActionDefinition,
    FeedbackT,
    GoalT,
    RequestT,
    ResponseT,
    ResultT,
    ServiceDefinition,
    interface_type_name,
)
from kinema.transport.action import ActionClient, ActionServer, CancelCallback, ExecuteCallback, GoalCallback
from kinema.transport.graph import Graph, query_graph
from kinema.transport.keys import LATCHED_QOS, QoS, fully_qualified, node_token, normalize_namespace
from kinema.transport.pubsub import Publisher, Subscription
from kinema.transport.service import DeferredHandler, Handler, ServiceClient, ServiceServer

if TYPE_CHECKING:
    from kinema.transport.session import Session

log = logging.getLogger(__name__)

_NODE_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class Node:
    """A graph participant on a :class:`~kinema.transport.session.Session`.

    Example::

        with open_session() as session:
            node = Node(session, "adder")
            node.create_service("example_interfaces/srv/AddTwoInts", "/add_two_ints",
                                lambda req: {"sum": req.a + req.b})

    Names are resolved as in ROS: relative names join the node's namespace, ``~/x`` the node's own.
    Closing the node (or its session) withdraws everything it declared.
    """

    def __init__(self, session: Session, name: str, namespace: str = "") -> None:
        if not _NODE_NAME.match(name):
            raise TransportError(
                f"invalid node name {name!r}: use letters, digits and '_' (not starting with a digit)"
            )
        if session.closed:
            raise TransportError("cannot create a node on a closed session")
        self.session = session
        self.name = name
        self.namespace = normalize_namespace(namespace)
        self.node_id = session.next_entity_id()
        self._entities: list[Any] = []
        self._lock = threading.Lock()
        self._closed = False
        self._token = session.zenoh.liveliness().declare_token(
            node_token(session.domain_id, session.zid, self.node_id, self.namespace, name)
        )
        session._register_closer(self)

    @property
    def fully_qualified_name(self) -> str:
        """``/namespace/name``."""
        return f"{self.namespace}/{self.name}"

    def resolve(self, name: str) -> str:
        """Fully qualified form of a topic/service/action name for this node."""
        return fully_qualified(name, self.namespace, self.name)

    # -- entity bookkeeping (called by the entities) ---------------------------------------------

    def _adopt(self, entity: Any) -> None:
        with self._lock:
            if entity not in self._entities:
                self._entities.append(entity)

    def _forget(self, entity: Any) -> None:
        with self._lock:
            if entity in self._entities:
                self._entities.remove(entity)

    def _check_open(self) -> None:
        if self._closed:
            raise TransportError(f"node {self.fully_qualified_name} is closed")

    # -- topics ----------------------------------------------------------------------------------

    def create_publisher(
        self, msg_type: str, topic: str, qos: QoS | None = None, *, latched: bool = False
    ) -> Publisher:
        """Publish ``msg_type`` (``pkg/msg/Name``) on ``topic``.

        ``latched=True`` (ROS transient local, depth 1 unless ``qos`` says otherwise) keeps the last
        message for subscriptions that join later.
        """
        self._check_open()
        return Publisher(self, msg_type, self.resolve(topic), _qos(qos, latched))

    def create_subscription(
        self,
        msg_type: str,
        topic: str,
        callback: Callable[..., Any],
        qos: QoS | None = None,
        *,
        latched: bool = False,
        raw: bool = False,
        with_info: bool = False,
    ) -> Subscription:
        """Call ``callback(message)`` for every message of ``msg_type`` on ``topic``.

        ``latched=True`` also delivers the last message of latched publishers already running.
        ``raw=True`` passes the CDR bytes instead of a message; ``with_info=True`` calls
        ``callback(message, info)`` with a :class:`~kinema.transport.pubsub.MessageInfo`.
        """
        self._check_open()
        return Subscription(
            self, msg_type, self.resolve(topic), callback, _qos(qos, latched), raw=raw, with_info=with_info
        )

    # -- services --------------------------------------------------------------------------------

    def create_service(
        self,
        srv_type: str,
        name: str,
        handler: Handler | DeferredHandler,
        *,
        max_concurrent: int = 1,
        deferred: bool = False,
    ) -> ServiceServer:
        """Serve ``srv_type`` (``pkg/srv/Name``) at ``name`` with ``handler(request) -> response``.

        The response may be a message or a dict of its fields. See :class:`ServiceServer` for
        ``max_concurrent`` (parallel handlers) and ``deferred`` (answer later through a responder).
        """
        self._check_open()
        service = self.session.registry.service(srv_type)
        return ServiceServer(
            self, service, self.resolve(name), handler, max_concurrent=max_concurrent, deferred=deferred
        )

    @overload
    def create_client(
        self, srv_type: type[ServiceDefinition[RequestT, ResponseT]], name: str
    ) -> ServiceClient[RequestT, ResponseT]: ...

    @overload
    def create_client(self, srv_type: str, name: str) -> ServiceClient[Any, Any]: ...

    def create_client(
        self, srv_type: str | type[ServiceDefinition[Any, Any]], name: str
    ) -> ServiceClient[Any, Any]:
        """A client of the service ``name`` of type ``srv_type``; ``.call(request, timeout)``.

        ``srv_type`` is ``pkg/srv/Name`` or, for a typed client, the interface's definition class
        (``kinema.interfaces.typed.AddTwoInts``): ``call`` then returns an ``AddTwoInts.Response``.
        """
        self._check_open()
        service = self.session.registry.service(_type_name(srv_type, "srv"))
        return ServiceClient(self, service, self.resolve(name))

    # -- actions ---------------------------------------------------------------------------------

    def create_action_server(
        self,
        action_type: str,
        name: str,
        execute_callback: ExecuteCallback,
        *,
        goal_callback: GoalCallback | None = None,
        cancel_callback: CancelCallback | None = None,
        result_timeout: float = 900.0,
        max_finished_goals: int = 100,
        deferred: bool = False,
    ) -> ActionServer:
        """Serve the action ``name`` of ``action_type`` (``pkg/action/Name``).

        ``execute_callback(goal_handle)`` runs on a thread of its own for each accepted goal. Results of
        finished goals stay available for ``result_timeout`` seconds (at most ``max_finished_goals``).
        With ``deferred=True`` it runs on the accepting thread instead, must not block, and ends the goal
        later through the handle, which stays ACCEPTED until ``execute()`` is called on it (see
        :class:`~kinema.transport.action.ActionServer`).
        """
        self._check_open()
        return ActionServer(
            self,
            action_type,
            name,
            execute_callback,
            goal_callback=goal_callback,
            cancel_callback=cancel_callback,
            result_timeout=result_timeout,
            max_finished_goals=max_finished_goals,
            deferred=deferred,
        )

    @overload
    def create_action_client(
        self, action_type: type[ActionDefinition[GoalT, ResultT, FeedbackT]], name: str
    ) -> ActionClient[GoalT, ResultT, FeedbackT]: ...

    @overload
    def create_action_client(self, action_type: str, name: str) -> ActionClient[Any, Any, Any]: ...

    def create_action_client(
        self, action_type: str | type[ActionDefinition[Any, Any, Any]], name: str
    ) -> ActionClient[Any, Any, Any]:
        """A client of the action ``name``; ``.send_goal(goal, feedback_callback)``.

        ``action_type`` is ``pkg/action/Name`` or, for a typed client, the interface's definition
        class (``kinema.interfaces.typed.Fibonacci``), which types goals, feedback and results.
        """
        self._check_open()
        return ActionClient(self, _type_name(action_type, "action"), name)

    # -- graph -----------------------------------------------------------------------------------

    def graph(self, timeout: float | None = None) -> Graph:
        """The ROS graph: the live cache, or (with ``timeout``) a fresh query of the whole network."""
        if timeout is not None:
            return query_graph(self.session, timeout)
        return self.session.graph_cache().snapshot()

    def close(self) -> None:
        """Withdraw the node and everything it declared; safe to call twice."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            entities = list(reversed(self._entities))
        for entity in entities:
            try:
                entity.close()
            except Exception:
                log.exception("error while closing %r", entity)
        try:
            self._token.undeclare()
        except Exception:
            log.debug("node token already gone", exc_info=True)
        self.session._unregister_closer(self)

    def __enter__(self) -> Node:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<Node {self.fully_qualified_name}>"


def _type_name(interface: Any, kind: str) -> str:
    try:
        return interface_type_name(interface, kind)
    except TypeError as error:
        raise TransportError(str(error)) from None


def _qos(qos: QoS | None, latched: bool) -> QoS:
    if qos is None:
        return LATCHED_QOS if latched else QoS()
    if latched and not qos.transient_local:
        return QoS(reliable=qos.reliable, transient_local=True, keep_all=qos.keep_all, depth=qos.depth)
    return qos
