"""``ObjectiveClient``: start, cancel and watch objectives of a running Kinema (or MoveIt Pro) agent.

::

    from kinema.sdk import ObjectiveClient

    with ObjectiveClient() as client:                  # joins the router at tcp/127.0.0.1:7447
        result = client.execute("Close Gripper")       # blocks; an ObjectiveResult, never None
        handle = client.start("3 Waypoints Pick and Place")
        ...
        handle.cancel()
        print(handle.result())                         # cancelled: error code PREEMPTED (-7)
        for status in client.statuses(timeout=5):      # the 10 Hz heartbeat
            print(status)

Every call that needs the agent raises :class:`~kinema.errors.TransportError` with one clear sentence when
no runtime answers within the client's ``timeout``.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any, Literal, overload

from kinema.errors import NoAnswerError, TransportError
from kinema.runtime import names
from kinema.runtime.overrides import ParameterOverride
from kinema.runtime.result import ObjectiveResult
from kinema.sdk.streams import (
    BlackboardSnapshot,
    LogEntry,
    MessageStream,
    NodeStatusChanges,
    NodeStatusDecoder,
    ServerStatus,
)

if TYPE_CHECKING:
    from kinema.config import Waypoint
    from kinema.config.objective_file import ObjectivePort
    from kinema.transport import ActionClient, ClientGoalHandle, Node, ServiceClient, Session

Overrides = Mapping[str, Any] | Iterable[ParameterOverride] | None

DEFAULT_TIMEOUT = 5.0
# How long start() waits for /kinema/run_objective once the agent is seen (a MoveIt Pro agent has none).
NAME_DOOR_GRACE_S = 1.0

log = logging.getLogger(__name__)


def parameter_messages(overrides: Overrides) -> list[dict[str, Any]]:
    """``BehaviorParameter`` dicts for overrides.

    A mapping value that is a string is sent as YAML text (TYPE_STRING: the server parses it into the
    port's type); a bool, int or float is sent typed; anything else (a list, a dict) is sent as YAML.
    :class:`ParameterOverride` items keep their ``behavior_namespaces``.
    """
    import yaml

    if overrides is None:
        return []
    items: list[ParameterOverride]
    if isinstance(overrides, Mapping):
        items = [ParameterOverride(str(k), v, (), True) for k, v in overrides.items()]
    else:
        items = list(overrides)
    messages = []
    for item in items:
        value = item.value
        base: dict[str, Any] = {"behavior_namespaces": list(item.behavior_namespaces)}
        if isinstance(value, bool):
            messages.append({**base, "description": {"name": item.name, "type": 4}, "bool_value": value})
        elif isinstance(value, int):
            messages.append({**base, "description": {"name": item.name, "type": 3}, "int_value": value})
        elif isinstance(value, float):
            messages.append({**base, "description": {"name": item.name, "type": 2}, "double_value": value})
        else:
            text = value if isinstance(value, str) else yaml.safe_dump(value, default_flow_style=True).strip()
            messages.append({**base, "description": {"name": item.name, "type": 0}, "string_value": text})
    return messages


def _waypoint_from(message: Any) -> Waypoint:
    """A ``moveit_studio_agent_msgs/Waypoint`` message as a :class:`kinema.config.Waypoint`."""
    from kinema.config import Waypoint

    state = message.joint_state
    return Waypoint(
        name=str(message.name),
        joint_names=[str(n) for n in state.name],
        positions=[float(p) for p in state.position],
        joint_group_names=[str(g) for g in message.joint_group_names],
        description=str(message.description),
        favorite=bool(message.favorite),
    )


def _result_from(error_code: Any, error_message: str, objective_name: str) -> ObjectiveResult:
    message = error_message or getattr(error_code, "message", "") or ""
    return ObjectiveResult(int(error_code.val), message, objective_name)


class ObjectiveTimeoutError(TransportError):
    """An objective waited for with a ``timeout`` did not end in time; it was cancelled."""


class ObjectiveHandle:
    """An objective started with :meth:`ObjectiveClient.start`: cancel it, wait for its result."""

    def __init__(self, goal: ClientGoalHandle, objective_name: str) -> None:
        self._goal = goal
        self.objective_name = objective_name

    @property
    def status(self) -> str:
        """The goal's status: ACCEPTED, EXECUTING, CANCELING, SUCCEEDED, CANCELED or ABORTED.

        Read from the agent's status topic, which the client subscribes to at the first read: right
        after that it may still say ACCEPTED for a moment.
        """
        return self._goal.status_name

    @property
    def done(self) -> bool:
        """True once the objective ended."""
        return self._goal.done()

    def cancel(self, timeout: float = DEFAULT_TIMEOUT) -> bool:
        """Ask the agent to halt this objective; True if it was still running."""
        if self._goal.done():
            return False
        return self._goal.cancel(timeout=timeout)

    def result(self, timeout: float | None = None) -> ObjectiveResult:
        """Wait until the objective ends and return how it ended (cancelled runs are PREEMPTED).

        Raises:
            TransportError: ``timeout`` passed, or the agent went away before answering.
        """
        outcome = self._goal.result(timeout)
        result = outcome.result
        return _result_from(result.error_code, result.error_message, self.objective_name)

    def __repr__(self) -> str:
        return f"<ObjectiveHandle {self.objective_name!r} {self.status}>"


def _wait_or_cancel(handle: ObjectiveHandle, timeout: float | None) -> ObjectiveResult:
    """The result of ``handle``; cancels the objective when ``timeout`` passes or the wait is interrupted."""
    try:
        return handle.result(timeout)
    except KeyboardInterrupt:
        _cancel_quietly(handle)
        raise
    except TransportError:
        if handle.done:
            raise  # the agent answered with an error, or went away
        cancelled = _cancel_quietly(handle)
        what = "it was cancelled" if cancelled else "cancelling it failed: it may still run"
        raise ObjectiveTimeoutError(
            f"objective {handle.objective_name!r} did not end within {timeout:g} s; {what}"
        ) from None


def _cancel_quietly(handle: ObjectiveHandle) -> bool:
    """Cancel ``handle``'s objective; False when the agent could not be asked."""
    try:
        handle.cancel()
    except TransportError as error:
        log.warning("cancelling objective %r failed: %s", handle.objective_name, error)
        return False
    return True


class ObjectiveClient:
    """A connection to the agent (the objective server). Use it as a context manager, or call :meth:`close`.

    Args:
        connect: router endpoint(s); default ``KINEMA_ZENOH_CONNECT`` or ``tcp/127.0.0.1:7447``.
        timeout: how long to wait for the router and the agent before raising TransportError.
        session: an open transport session to use instead (not closed by :meth:`close`).
        domain_id: ROS domain id (default ``ROS_DOMAIN_ID`` or 0).
    """

    def __init__(
        self,
        connect: str | None = None,
        *,
        timeout: float = DEFAULT_TIMEOUT,
        session: Session | None = None,
        domain_id: int | None = None,
    ) -> None:
        from kinema.transport import Node, open_session

        self.timeout = timeout
        self._owns_session = session is None
        self.session = (
            session if session is not None else open_session(connect, domain_id, connect_timeout=timeout)
        )
        try:
            self.node: Node = Node(self.session, f"kinema_sdk_{id(self):x}")
        except Exception:
            if self._owns_session:
                self.session.close()
            raise
        self._lock = threading.Lock()
        self._clients: dict[str, ServiceClient] = {}
        self._action: ActionClient | None = None
        self._run_action: ActionClient | None = None
        self._by_name: bool | None = None  # whether the agent serves /kinema/run_objective
        self._ready = False
        self._action_ready = False
        # The last goal sent without overrides, serialised: ((action name, objective name, XML), CDR).
        # Running the same objective again sends these bytes again.
        self._last_goal: tuple[tuple[str, str, str], bytes] | None = None

    # -- plumbing ------------------------------------------------------------------------------------

    def _client(self, srv_type: str, name: str) -> ServiceClient:
        with self._lock:
            client = self._clients.get(name)
            if client is None:
                client = self.node.create_client(srv_type, name)
                self._clients[name] = client
            return client

    def wait_for_runtime(self, timeout: float | None = None) -> None:
        """Block until the agent's services are on the network.

        Raises:
            TransportError: no agent answered within ``timeout`` (default: the client's timeout).
        """
        if self._ready:
            return
        limit = self.timeout if timeout is None else timeout
        client = self._client(names.EXECUTE_OBJECTIVE_TYPE, names.EXECUTE_OBJECTIVE)
        if not client.wait_for_service(limit):
            where = ", ".join(self.session.endpoints) or "this process"
            raise TransportError(
                f"no Kinema runtime answers at {where} within {limit:g} s (start one with `kinema run`)"
            )
        self._ready = True

    # -- objectives ----------------------------------------------------------------------------------

    @overload
    def execute(
        self,
        name: str,
        overrides: Overrides = None,
        *,
        wait: Literal[True] = True,
        timeout: float | None = None,
    ) -> ObjectiveResult: ...

    @overload
    def execute(
        self, name: str, overrides: Overrides = None, *, wait: Literal[False], timeout: float | None = None
    ) -> ObjectiveHandle: ...

    @overload
    def execute(
        self, name: str, overrides: Overrides = None, *, wait: bool, timeout: float | None = None
    ) -> ObjectiveResult | ObjectiveHandle: ...

    def execute(
        self, name: str, overrides: Overrides = None, *, wait: bool = True, timeout: float | None = None
    ) -> ObjectiveResult | ObjectiveHandle:
        """Run the objective ``name`` (a new objective preempts the running one).

        Args:
            name: the objective's ID.
            overrides: parameter overrides (see :func:`parameter_messages`).
            wait: True blocks until it ends and returns its :class:`ObjectiveResult`; False returns an
                :class:`ObjectiveHandle` at once (as :meth:`start`).
            timeout: with ``wait``, how long the objective may take (None: as long as it runs). When it
                passes, the objective is cancelled and :class:`ObjectiveTimeoutError` raised. An
                interrupt (Ctrl-C, ``KeyboardInterrupt``) while waiting cancels it too: the robot never
                keeps moving for a program that stopped waiting.

        Raises:
            ObjectiveTimeoutError: ``timeout`` passed (the objective was cancelled).
            TransportError: the agent is not there, or went away before answering.
        """
        handle = self.start(name, overrides)
        return _wait_or_cancel(handle, timeout) if wait else handle

    def start(self, name: str = "", overrides: Overrides = None, *, xml: str = "") -> ObjectiveHandle:
        """Start an objective and return its handle (name wins over ``xml``).

        A name goes to Kinema's ``/kinema/run_objective`` (what an operator's certificate reaches; a
        MoveIt Pro agent's ``/do_objective`` when there is none), XML to ``/do_objective``: running ad-hoc
        XML is a grant of its own (``kinema security``).
        """
        if not name and not xml:
            raise TransportError("start() needs an objective name or an objective XML string")
        self.wait_for_runtime()
        action = self._action_for(by_name=bool(name))
        try:
            handle = action.send_goal_cdr(self._goal_cdr(action, name, xml, overrides), timeout=self.timeout)
        except NoAnswerError as error:
            if name:
                raise
            # The agent is there (wait_for_runtime) but its XML door did not answer: access rules.
            raise TransportError(
                f"the runtime answers, but not to ad-hoc objective XML on {names.DO_OBJECTIVE}: this "
                "machine's certificate lacks that grant (`kinema security` on the robot lists the roles; "
                "`kinema security init --allow-xml NAME` gives it). Run a library objective by name instead"
            ) from error
        if not handle.accepted:
            raise TransportError(f"the agent rejected objective {name or '<XML>'!r}")
        return ObjectiveHandle(handle, name or _xml_name(xml))

    def _goal_cdr(self, action: ActionClient, name: str, xml: str, overrides: Overrides) -> bytes:
        """The serialised goal of ``action`` (the last one again when nothing changed)."""
        key = (action.name, name, "" if name else xml)
        last = self._last_goal
        if overrides is None and last is not None and last[0] == key:
            return last[1]
        goal = {
            "objective_name": name,
            "objective_xml_string": key[2],
            "parameter_overrides": parameter_messages(overrides),
        }
        cdr = action.serialize_goal(goal)
        if overrides is None:
            self._last_goal = (key, cdr)
        return cdr

    def _action_for(self, *, by_name: bool) -> ActionClient:
        """The action to send a goal to, once its server is on the graph."""
        with self._lock:
            if self._action is None:
                self._action = self.node.create_action_client(names.DO_OBJECTIVE_TYPE, names.DO_OBJECTIVE)
            if self._run_action is None:
                self._run_action = self.node.create_action_client(
                    names.DO_OBJECTIVE_TYPE, names.RUN_OBJECTIVE
                )
            do, run = self._action, self._run_action
        if by_name and self._by_name is None:
            graph = self.session.graph_cache()
            found = graph.wait_for(
                lambda g: g.action_server_ready(run.name) or g.action_server_ready(do.name), self.timeout
            )
            if not found:
                raise TransportError(f"the agent's {names.DO_OBJECTIVE} action is not available")
            # The agent's endpoints appear on the graph one by one: give run_objective a moment.
            self._by_name = run.wait_for_server(NAME_DOOR_GRACE_S)
        if by_name and self._by_name:
            return run
        if not self._action_ready:
            if not do.wait_for_server(self.timeout):
                raise TransportError(f"the agent's {names.DO_OBJECTIVE} action is not available")
            self._action_ready = True
        return do

    @overload
    def do_xml(
        self,
        xml: str,
        overrides: Overrides = None,
        *,
        wait: Literal[True] = True,
        timeout: float | None = None,
    ) -> ObjectiveResult: ...

    @overload
    def do_xml(
        self, xml: str, overrides: Overrides = None, *, wait: Literal[False], timeout: float | None = None
    ) -> ObjectiveHandle: ...

    @overload
    def do_xml(
        self, xml: str, overrides: Overrides = None, *, wait: bool, timeout: float | None = None
    ) -> ObjectiveResult | ObjectiveHandle: ...

    def do_xml(
        self, xml: str, overrides: Overrides = None, *, wait: bool = True, timeout: float | None = None
    ) -> ObjectiveResult | ObjectiveHandle:
        """Run an objective given as a BT.CPP v4 XML string (its main tree); see :meth:`execute`."""
        handle = self.start(overrides=overrides, xml=xml)
        return _wait_or_cancel(handle, timeout) if wait else handle

    def cancel(self) -> bool:
        """Cancel whatever objective runs; False when none was running."""
        self.wait_for_runtime()
        client = self._client(names.CANCEL_OBJECTIVE_TYPE, names.CANCEL_OBJECTIVE)
        response = client.call({}, timeout=self.timeout)
        return bool(response.status.success)

    def objectives(self, subcategory: str = "") -> list[Any]:
        """The loaded objectives with their metadata (``kinema_msgs/msg/ObjectiveInfo`` messages)."""
        self.wait_for_runtime()
        client = self._client(names.LIST_OBJECTIVES_TYPE, names.LIST_OBJECTIVES)
        response = client.call({"subcategory": subcategory}, timeout=self.timeout)
        if not response.status.success:
            raise TransportError(response.status.error_message)
        return list(response.objectives)

    def parameters(self, name: str) -> list[ObjectivePort]:
        """What ``overrides`` can set when running ``name``: its input ports, types and defaults.

        The same list as ``kinema objective show NAME`` and the terminal UI's override form (see
        :mod:`kinema.config.objective_parameters` for the rule).

        Raises:
            ObjectiveError: no objective has that name (the message suggests the closest ones).
            TransportError: the agent did not answer.
        """
        from kinema.config.objective_file import ObjectivePort
        from kinema.errors import ObjectiveError, did_you_mean

        infos = {str(info.name): info for info in self.objectives()}
        info = infos.get(name)
        if info is None:
            raise ObjectiveError(f"no objective named {name!r}; {did_you_mean(name, infos)}")
        directions = {0: "input", 1: "output", 2: "inout"}
        ports = [
            ObjectivePort(
                str(port.name),
                directions.get(int(port.direction), "input"),
                str(port.default_value) if port.default_value else None,
                str(port.description),
                str(port.type_name),
            )
            for port in info.ports
        ]
        return [port for port in ports if port.direction != "output"]

    # -- waypoints -----------------------------------------------------------------------------------

    def waypoints(self) -> list[Waypoint]:
        """The config's saved waypoints (``kinema.config.Waypoint``: name, joints, positions, groups)."""
        response = self._call_service(names.GET_WAYPOINTS_TYPE, names.GET_WAYPOINTS, {})
        return [_waypoint_from(message) for message in response.waypoints]

    def save_waypoint(self, name: str, joint_group_names: Iterable[str] = ()) -> Waypoint:
        """Save the robot's current joint positions as waypoint ``name`` (replacing one of that name).

        ``joint_group_names``: the planning groups it is for (default: the config's planning group).

        Raises:
            ObjectiveError: the agent refused (no joint states yet, a bad name; its message says).
        """
        request = {"operation": 0, "waypoint_name": name, "joint_group_names": list(joint_group_names)}
        response = self._call_service(names.EDIT_WAYPOINTS_TYPE, names.EDIT_WAYPOINTS, request)
        return _waypoint_from(response.new_waypoint)

    def rename_waypoint(self, name: str, new_name: str) -> Waypoint:
        """Rename waypoint ``name`` to ``new_name``; raises ObjectiveError naming the valid ones."""
        request = {"operation": 1, "waypoint_name": name, "existing_waypoint_new_name": new_name}
        response = self._call_service(names.EDIT_WAYPOINTS_TYPE, names.EDIT_WAYPOINTS, request)
        return _waypoint_from(response.new_waypoint)

    def erase_waypoint(self, name: str) -> None:
        """Delete waypoint ``name``; raises ObjectiveError naming the valid ones."""
        request = {"operation": 2, "waypoint_name": name}
        self._call_service(names.EDIT_WAYPOINTS_TYPE, names.EDIT_WAYPOINTS, request)

    def objective_xml(self, name: str) -> str:
        """The XML file that defines objective ``name``, as saved in the agent's library (``$(config ...)``
        left as written).

        Raises:
            ObjectiveError: the agent has no such objective (its message names the close ones).
        """
        response = self._call_service(
            names.GET_OBJECTIVE_XML_TYPE, names.GET_OBJECTIVE_XML, {"objective_name": name}
        )
        return str(response.xml)

    def _call_service(self, srv_type: str, service: str, request: dict[str, Any]) -> Any:
        """Call one of the agent's services; a response whose ``status`` says it refused raises
        ObjectiveError with the agent's message."""
        from kinema.errors import ObjectiveError

        self.wait_for_runtime()
        response = self._client(srv_type, service).call(request, timeout=self.timeout)
        status = getattr(response, "status", None)
        if status is not None and not status.success:
            raise ObjectiveError(str(status.error_message) or f"{service} refused the request")
        return response

    # -- streams -------------------------------------------------------------------------------------

    def status(self, timeout: float | None = None) -> ServerStatus:
        """The agent's current status (its latest heartbeat).

        Raises:
            TransportError: no heartbeat within ``timeout`` (default: the client's timeout).
        """
        limit = self.timeout if timeout is None else timeout
        with self.statuses(timeout=limit) as stream:
            for status in stream:
                return status
        where = ", ".join(self.session.endpoints) or "this process"
        raise TransportError(f"no Kinema runtime answers at {where} within {limit:g} s (no heartbeat)")

    def statuses(self, *, timeout: float | None = None) -> MessageStream[ServerStatus]:
        """Iterate over heartbeats (10 Hz, plus one per status change); ends after ``timeout`` of silence."""
        return MessageStream(
            lambda cb: self.node.create_subscription(names.HEARTBEAT_TYPE, names.HEARTBEAT, cb, latched=True),
            ServerStatus.from_message,
            timeout=timeout,
        )

    def blackboard(self, *, timeout: float | None = None) -> MessageStream[BlackboardSnapshot]:
        """Iterate over blackboard snapshots (latched: the current one comes first)."""
        return MessageStream(
            lambda cb: self.node.create_subscription(
                names.BLACKBOARD_TYPE, names.BLACKBOARD, cb, latched=True
            ),
            BlackboardSnapshot.from_message,
            timeout=timeout,
        )

    def blackboard_snapshot(
        self, objective: str | None = None, *, timeout: float | None = None
    ) -> BlackboardSnapshot:
        """The blackboard of the running or last objective, now (``snapshot["sum"]`` reads a value).

        Args:
            objective: wait for a snapshot of this objective (the latched one may be of an earlier run).
            timeout: how long to wait (default: the client's timeout).

        Raises:
            TransportError: no snapshot (of ``objective``) arrived within ``timeout``.
        """
        limit = self.timeout if timeout is None else timeout
        with self.blackboard(timeout=limit) as snapshots:
            for snapshot in snapshots:
                if objective is None or snapshot.objective_name == objective:
                    return snapshot
        which = f" of objective {objective!r}" if objective else ""
        raise TransportError(f"no blackboard snapshot{which} within {limit:g} s")

    def logs(self, *, timeout: float | None = None) -> MessageStream[LogEntry]:
        """Iterate over the agent's log messages (behavior toasts, reload events, failures)."""
        return MessageStream(
            lambda cb: self.node.create_subscription(names.LOG_TYPE, names.LOG, cb),
            LogEntry.from_message,
            timeout=timeout,
        )

    def node_statuses(self, *, timeout: float | None = None) -> MessageStream[NodeStatusChanges]:
        """Iterate over the node status changes of running objectives, a batch per message (usually
        one tick): :class:`~kinema.sdk.streams.NodeStatusChanges` of
        :class:`~kinema.sdk.streams.NodeStatusChange` (stamp, uid, path, registration ID, name,
        previous and new status). Decoded from ``/objective_server/node_status`` with the run's
        node table (``/objective_server/node_table``), see :class:`~kinema.sdk.streams.NodeStatusDecoder`.
        """
        return MessageStream(
            lambda push: NodeStatusSubscription(self.node, push), lambda batch: batch, timeout=timeout
        )

    # -- lifecycle -----------------------------------------------------------------------------------

    def close(self) -> None:
        """Close the node and, if this client opened it, the session."""
        self.node.close()
        if self._owns_session:
            self.session.close()

    def __enter__(self) -> ObjectiveClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<ObjectiveClient {self.session!r}>"


def _xml_name(xml: str) -> str:
    from kinema.sdk.quick import xml_objective_name

    return xml_objective_name(xml)


class NodeStatusSubscription:
    """Both node status topics of a runtime, decoded: ``on_changes(NodeStatusChanges)`` per message.

    The node table of a run is one latched message. When changes name a table that has not arrived (a
    large table can be dropped on a congested link, as any message can), the table topic is subscribed
    again, which reads the runtime's latched copy; at most once a second, from a thread of its own.
    """

    REFETCH_AFTER_S = 1.0
    REFETCH_FOR_S = 30.0

    def __init__(self, node: Any, on_changes: Any) -> None:
        self._node = node
        self._on_changes = on_changes
        self.decoder = NodeStatusDecoder()
        self._lock = threading.Lock()
        self._closed = threading.Event()
        self._refetching = False
        self._last_refetch = 0.0
        self._tables = node.create_subscription(
            names.NODE_TABLE_TYPE, names.NODE_TABLE, self._on_table, latched=True
        )
        try:
            self._codes = node.create_subscription(names.NODE_STATUS_TYPE, names.NODE_STATUS, self._on_codes)
        except BaseException:
            self._tables.close()
            raise

    def _on_table(self, message: Any) -> None:
        for ready in self.decoder.on_table(message):
            self._on_changes(ready)

    def _on_codes(self, message: Any) -> None:
        decoded = self.decoder.on_codes(message)
        if decoded is not None:
            self._on_changes(decoded)
            return
        with self._lock:
            if self._closed.is_set() or self._refetching:
                return
            self._refetching = True
        threading.Thread(target=self._refetch_while_waiting, name="kinema-node-table", daemon=True).start()

    def _refetch_while_waiting(self) -> None:
        # Read the latched table again, at most once a second, for as long as changes wait for a table
        # (up to REFETCH_FOR_S): the last changes of a run may be the only ones that name it, so waiting
        # for more changes to try again could wait forever.
        deadline = time.monotonic() + self.REFETCH_FOR_S
        try:
            while True:
                pause = self._last_refetch + self.REFETCH_AFTER_S - time.monotonic()
                if pause > 0 and self._closed.wait(pause):
                    return
                if not self.decoder.waiting or time.monotonic() > deadline:
                    return
                self._last_refetch = time.monotonic()
                try:
                    fresh = self._node.create_subscription(
                        names.NODE_TABLE_TYPE, names.NODE_TABLE, self._on_table, latched=True
                    )
                except Exception:
                    return  # the node is closing
                with self._lock:
                    if self._closed.is_set():
                        old = fresh
                    else:
                        old, self._tables = self._tables, fresh
                old.close()
                if self._closed.is_set():
                    return
        finally:
            with self._lock:
                self._refetching = False

    def close(self) -> None:
        """Unsubscribe both topics."""
        with self._lock:
            self._closed.set()
            tables = self._tables
        self._codes.close()
        tables.close()
