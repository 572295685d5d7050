"""The agent: the objective server served on the transport, with its streams and library services.

Serves (names in :mod:`kinema.runtime.names`): ``/execute_objective``, ``/cancel_objective``,
``/do_objective`` (action; by name or XML), ``/kinema/run_objective`` (the same action by name only: what
an operator's certificate reaches), the objective list and XML services, ``/get_saved_waypoints`` and
``/edit_waypoints``. Publishes the heartbeat (10 Hz and on every change, latched), node status changes,
a latched blackboard snapshot (at most 10 Hz, only when it changed) and the behaviors' log messages
(toasts, plus hot-reload events).

Build one with :meth:`Agent.for_config` (what ``kinema run`` does, through ``python -m
kinema.runtime.agent``) or directly from an :class:`ObjectiveServer` for tests and embedding.
"""

from __future__ import annotations

import logging
import threading
import time
import weakref
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinema.drivers.mujoco.names import JOINT_STATES_TOPIC, JOINT_STATES_TYPE
from kinema.errors import KinemaError, ObjectiveError, did_you_mean
from kinema.process.log_files import PLUGIN_LOGGER
from kinema.runtime import names
from kinema.runtime.background_work import HandOff
from kinema.runtime.blackboard_text import render_value
from kinema.runtime.error_codes import MoveItErrorCode
from kinema.runtime.heartbeat_cdr import HeartbeatEncoder
from kinema.runtime.heartbeat_cdr import generic_serializer as heartbeat_serializer
from kinema.runtime.node_status_cdr import NodeStatusCodesEncoder, generic_serializer, time_parts
from kinema.runtime.objective_server import (
    ObjectiveRequest,
    ObjectiveRun,
    ObjectiveServer,
)
from kinema.runtime.objective_status import ObjectiveStatus
from kinema.runtime.overrides import ParameterOverride
from kinema.runtime.result import ObjectiveResult

if TYPE_CHECKING:
    from kinema.behaviors.logger import LogMessage, LogSink
    from kinema.bt import Clock
    from kinema.config import ObjectiveInfo, WaypointStore
    from kinema.plugins import BehaviorHost, ReloadEvent
    from kinema.runtime.node_status import NodeStatusBatch
    from kinema.runtime.objective_source import LibraryTreeSource
    from kinema.transport import Node, Session

log = logging.getLogger("kinema.agent")
# Plugin load and hot-reload outcomes have a logger of their own: `kinema run` echoes it in its terminal.
plugin_log = logging.getLogger(PLUGIN_LOGGER)

LOG_ERROR, LOG_WARN, LOG_INFO = 1, 2, 3
DO_OBJECTIVE_RESULT_KEEP_S = 60.0
# How long close() lets running goals answer their clients.
GOALS_ANSWER_AT_CLOSE_S = 2.0
# Ad-hoc XML is a grant of its own (kinema.transport.security_folder): the name-only doors refuse it.
NO_XML_HERE = (
    "{door} runs library objectives by name only; ad-hoc objective XML goes to /do_objective or the "
    "start_xml key, a separate grant (`kinema security` lists who may use it)"
)


# Most node status changes in one ``/objective_server/node_status`` message (4 bytes each: 200 kB).
NODE_STATUS_CHUNK = 50_000
# How long a run's end waits for the blackboard worker to finish a snapshot it is in before publishing
# the final one itself; past that the worker publishes it.
BLACKBOARD_SETTLE_WAIT_S = 0.25


def _stamp(seconds: float) -> dict[str, int]:
    sec, nanosec = time_parts(seconds)
    return {"sec": sec, "nanosec": nanosec}


def overrides_from_messages(parameters: Sequence[Any]) -> tuple[ParameterOverride, ...]:
    """Turn ``BehaviorParameter`` messages into overrides (string values are YAML text).

    Raises:
        ObjectiveError: a parameter without a name, or of an unknown type.
    """
    result = []
    for parameter in parameters:
        name = parameter.description.name
        kind = int(parameter.description.type)
        namespaces = tuple(str(n) for n in parameter.behavior_namespaces)
        if not name:
            raise ObjectiveError("a parameter override has an empty name")
        if kind == 0:
            result.append(ParameterOverride(name, parameter.string_value, namespaces))
        elif kind == 1:
            result.append(ParameterOverride(name, parameter.pose_value, namespaces, from_yaml=False))
        elif kind == 2:
            result.append(ParameterOverride(name, float(parameter.double_value), namespaces, from_yaml=False))
        elif kind == 3:
            result.append(ParameterOverride(name, int(parameter.int_value), namespaces, from_yaml=False))
        elif kind == 4:
            result.append(ParameterOverride(name, bool(parameter.bool_value), namespaces, from_yaml=False))
        elif kind == 5:
            result.append(ParameterOverride(name, parameter.joint_state_value, namespaces, from_yaml=False))
        else:
            raise ObjectiveError(
                f"parameter override {name!r} has type {kind}; valid: 0 (string, YAML), 1 (pose), "
                f"2 (double), 3 (int), 4 (bool), 5 (joint state)"
            )
    return tuple(result)


class _Streams:
    """Publishes what the server reports (a :class:`ServerListener`, called on the tick thread).

    Blackboard snapshots are rendered and published by a worker thread (:class:`HandOff`): the tick
    thread only hands the entries over, the newest replacing one not yet published.
    """

    def __init__(self, node: Node, clock: Clock | None, server: ObjectiveServer) -> None:
        self._node = node
        self._clock = clock
        self._server = server
        self._heartbeat = node.create_publisher(names.HEARTBEAT_TYPE, names.HEARTBEAT, latched=True)
        self._health = node.create_publisher(names.HEALTH_TYPE, names.HEALTH, latched=True)
        self._last_warnings: tuple[str, ...] = ()
        self._node_status = node.create_publisher(names.NODE_STATUS_TYPE, names.NODE_STATUS)
        self._node_table = node.create_publisher(names.NODE_TABLE_TYPE, names.NODE_TABLE, latched=True)
        self._table_id = 0
        self._node_table_class: Any = None
        self._encoder: NodeStatusCodesEncoder | None = None
        self._blackboard = node.create_publisher(names.BLACKBOARD_TYPE, names.BLACKBOARD, latched=True)
        self._log = node.create_publisher(names.LOG_TYPE, names.LOG)
        self._status: tuple[ObjectiveStatus, str] = (ObjectiveStatus.IDLE, "")
        # Status changes whose heartbeat is not out yet (see on_status), oldest first.
        self._owed: list[tuple[ObjectiveStatus, str]] = []
        # The objective whose "Running" line is not logged yet (see _pay_owed).
        self._running_unlogged: str | None = None
        # The last snapshot published: its objective and its rendered entries.
        self._last_blackboard: tuple[str, list[tuple[str, str, str, str]]] | None = None
        self._render_cache: dict[int, tuple[Any, str]] = {}
        # The objective whose empty snapshot was the last handed to the worker (another empty one of the
        # same objective would change nothing).
        self._handed_empty: str | None = None
        self._lock = threading.Lock()
        # Built once: a status change publishes a heartbeat from the tick thread.
        from kinema.transport.messages import load_interfaces

        registry = load_interfaces()
        self._heartbeat_encoder = HeartbeatEncoder(heartbeat_serializer(registry, names.HEARTBEAT_TYPE))
        self._health_class = registry.message_class(names.HEALTH_TYPE)
        self._time_class = registry.message_class("builtin_interfaces/msg/Time")
        # Also tells the clients waiting for a run (set by the Agent).
        self.on_warning: Callable[[str], None] | None = None
        self._work = HandOff("kinema-blackboard")

    def close(self) -> None:
        """Publish what was handed over, then stop the worker thread."""
        self._work.close()

    def publish_heartbeat(self, *, health: bool = True) -> None:
        """Publish the heartbeat and, with ``health``, the watchdog's report (the periodic beat does; a
        status change, on the tick thread, sends the heartbeat alone: the latched report stands)."""
        report = self._server.health() if health else None
        # The status is read where it is published, under the lock on_status takes to change it: a beat
        # read before a run ended and sent after it would tell subscribers the run restarted. Changes
        # not yet published go out in order, the last of them being the current status.
        if not self._pay_owed():
            with self._lock:
                self._publish_beat(*self._status)
        if report is None:
            return
        self._log_running()
        with self._lock:
            stamp = self._time_class(*time_parts(time.time()))
            self._health.publish(
                self._health_class(
                    stamp=stamp,
                    tick_thread_alive=report.tick_thread_alive,
                    tick_thread_replacements=report.replacements,
                    warnings=list(report.warnings),
                )
            )
            seen = {_topic(old) for old in self._last_warnings}
            new = [warning for warning in report.warnings if _topic(warning) not in seen]
            self._last_warnings = report.warnings
        for warning in new:
            # Once per problem on the log topic too, so `kinema run`'s terminal and the TUI's log show it.
            self.publish_log(LOG_WARN, f"watchdog: {warning}")

    def _publish_beat(self, status: ObjectiveStatus, name: str) -> None:
        """Publish one heartbeat saying ``status`` (the lock held)."""
        now = time.time()
        clock_now = self._clock.now() if self._clock is not None and not _is_wall(self._clock) else now
        stamp = time_parts(now)
        ros_stamp = stamp if clock_now == now else time_parts(clock_now)
        self._heartbeat.publish_raw(self._heartbeat_encoder.encode(stamp, ros_stamp, name, str(status)))

    def _pay_owed(self) -> bool:
        """Publish the heartbeats of the status changes that wait, in order, and log them; False when
        none waited."""
        with self._lock:
            owed, self._owed = self._owed, []
            for status, name in owed:
                self._publish_beat(status, name)
                if status is ObjectiveStatus.RUNNING:
                    # Logged once the run still runs a heartbeat period or a tick later (_log_running): a
                    # run that ends sooner gets only its result's line, a file write less per run.
                    self._running_unlogged = name
        for status, name in owed:
            if status is not ObjectiveStatus.RUNNING:
                log.debug("objective %r: %s", name, status)
        return bool(owed)

    def _log_running(self) -> None:
        with self._lock:
            name, self._running_unlogged = self._running_unlogged, None
        if name is not None:
            log.info("objective %r: %s", name, ObjectiveStatus.RUNNING)

    def publish_log(self, level: int, text: str) -> None:
        from kinema.transport.messages import msg

        try:
            self._log.publish(msg(names.LOG_TYPE, message=text, log_level=level))
        except KinemaError:
            log.debug("log publisher closed", exc_info=True)

    # ServerListener
    def on_status(self, status: ObjectiveStatus, objective_name: str) -> None:
        with self._lock:
            self._status = (status, objective_name)
            self._owed.append((status, objective_name))
        if status in (ObjectiveStatus.LOADING, ObjectiveStatus.RUNNING):
            # Published with the run's first node changes or its end, whichever comes first (a run that
            # ends in its first tick has answered its client by then), or by the next periodic beat: a
            # long build or first tick still shows within a heartbeat period.
            return
        self._pay_owed()

    def on_node_status(self, objective_name: str, changes: NodeStatusBatch) -> None:
        if self._owed:
            self._pay_owed()
        table = changes.table
        if table.id == self._table_id:
            self._log_running()  # a later tick of the run
        else:
            # Once per run, latched, before its first changes: subscribers name nodes with it.
            table_class = self._node_table_class
            if table_class is None:
                from kinema.transport.messages import load_interfaces

                table_class = self._node_table_class = load_interfaces().message_class(names.NODE_TABLE_TYPE)
            self._node_table.publish(
                table_class(
                    objective_name=objective_name,
                    table_id=table.id,
                    uids=table.uid_array,
                    node_paths=list(table.paths),
                    node_ids=list(table.node_ids),
                    node_names=list(table.names),
                )
            )
            self._table_id = table.id
        # In messages of at most NODE_STATUS_CHUNK changes: the stream is best effort (rmw_zenoh's
        # KEEP_LAST: dropped when the link is congested), and a very large message can be lost whole on a
        # loaded machine; in chunks, what gets through is applied. Laid out directly as CDR: the generic
        # serializer's fixed cost was most of this on every tick of a small tree.
        encode = self._node_status_encoder().encode
        for part in changes.split(NODE_STATUS_CHUNK):
            self._node_status.publish_raw(
                encode(objective_name, table.id, part.stamps, part.starts, part.code_array())
            )

    def _node_status_encoder(self) -> NodeStatusCodesEncoder:
        encoder = self._encoder
        if encoder is None:
            from kinema.transport.messages import load_interfaces

            encoder = self._encoder = NodeStatusCodesEncoder(generic_serializer(load_interfaces()))
        return encoder

    def on_blackboard(self, objective_name: str, entries: list[tuple[str, str, str, Any]]) -> None:
        if not entries and self._handed_empty == objective_name:
            return  # the worker would find nothing changed: do not wake it
        self._handed_empty = None if entries else objective_name
        self._work.submit(lambda: self._publish_blackboard(objective_name, entries), key="blackboard")

    def settle_blackboard(self) -> None:
        """Publish the snapshot handed over last now, on this thread (the tick thread, as a run ends):
        its client must find this run's snapshot latched once it has the result, and the worker would
        publish it only after a wake. Rendering stays bounded (large values render as their size)."""
        self._work.run_queued_here(BLACKBOARD_SETTLE_WAIT_S)

    def _publish_blackboard(self, objective_name: str, entries: list[tuple[str, str, str, Any]]) -> None:
        from kinema.transport.messages import msg

        # Messages (trajectories, joint states) are rendered once per object: every subtree scope keeps
        # its own, and re-rendering them all at each snapshot starves the tick thread.
        cache, self._render_cache = self._render_cache, {}
        rendered = []
        for scope, key, type_name, value in entries:
            cached = cache.get(id(value))
            if cached is not None and cached[0] is value:
                text = cached[1]
            else:
                text = render_value(value)
            if hasattr(value, "__msgtype__"):
                self._render_cache[id(value)] = (value, text)
            rendered.append((scope, key, type_name, text))
        if self._last_blackboard == (objective_name, rendered):
            return
        self._last_blackboard = (objective_name, rendered)
        self._blackboard.publish(
            msg(
                names.BLACKBOARD_TYPE,
                stamp=_stamp(time.time()),
                objective_name=objective_name,
                entries=[
                    {"scope": scope, "key": key, "type_name": type_name, "value_yaml": value}
                    for scope, key, type_name, value in rendered
                ],
            )
        )

    def on_stale_code(self, run: ObjectiveRun, note: str) -> None:
        text = f"objective {run.objective_name!r} runs older code: {note}"
        log.warning("%s", text)
        self.publish_log(LOG_WARN, text)
        if self.on_warning is not None:
            self.on_warning(text)

    def on_run_finished(self, run: ObjectiveRun, result: ObjectiveResult) -> None:
        with self._lock:
            self._running_unlogged = None
        if result.succeeded:
            log.info("%s", result)
        elif result.cancelled:
            log.info("%s", result)
            self.publish_log(LOG_WARN, str(result))
        else:
            log.error("%s", result)
            self.publish_log(LOG_ERROR, str(result))


def _topic(warning: str) -> str:
    """A watchdog warning without its growing number of seconds (the same problem, a later beat)."""
    return warning.split(" for ", 1)[0]


def _is_wall(clock: Clock) -> bool:
    return bool(getattr(clock, "realtime", False))


def result_message(result: ObjectiveResult) -> dict[str, Any]:
    """A ``MoveItErrorCodes`` dict for a result."""
    return {"val": int(result.error_code), "message": result.error_message, "source": names.NODE_NAME}


class Agent:
    """Serves an :class:`ObjectiveServer` on a transport node.

    Args:
        session: the transport session (the agent creates its node on it).
        server: the objective server (the agent starts and stops it).
        source: the tree source, for the objective list services (optional).
        waypoints: the waypoint store served by the waypoint services (optional).
        log_sink: the behaviors' log sink; its messages are published as toasts (optional).
        clock: the runtime clock, for the heartbeat's ``ros_timestamp``.
        waypoint_groups: the planning groups a waypoint saved without any is recorded for (the config's
            planning group), so that UIs list its group.
        robot_groups: the robot's planning groups (its SRDF's), which a saved waypoint's groups must be.
    """

    def __init__(
        self,
        session: Session,
        server: ObjectiveServer,
        *,
        source: LibraryTreeSource | None = None,
        waypoints: WaypointStore | None = None,
        log_sink: LogSink | None = None,
        clock: Clock | None = None,
        node: Node | None = None,
        waypoint_groups: Sequence[str] = (),
        robot_groups: Callable[[], Sequence[str]] | None = None,
    ) -> None:
        from kinema.transport import Node

        self.waypoint_groups = list(waypoint_groups)
        self._robot_groups = robot_groups
        self.session = session
        self.server = server
        self.source = source
        self.waypoints = waypoints
        self.clock = clock
        self.node = node if node is not None else Node(session, names.NODE_NAME)
        registry = session.registry
        self._goal_result_class = registry.message_class(registry.action(names.DO_OBJECTIVE_TYPE).result)
        self._error_codes_class = registry.message_class("moveit_msgs/msg/MoveItErrorCodes")
        self._streams = _Streams(self.node, clock, server)
        self._streams.on_warning = lambda text: self._tell_quick_clients("warn", text)
        server.add_listener(self._streams)
        self._goal_runs: dict[bytes, ObjectiveRun] = {}
        self._quick_runs: weakref.WeakValueDictionary[int, ObjectiveRun] = weakref.WeakValueDictionary()
        self._quick: list[Any] = []
        # The JSON start queries of runs not yet ended: their clients also get the behaviors' toasts.
        self._quick_listeners: dict[int, Any] = {}
        self._goal_lock = threading.Condition()
        self._stop = threading.Event()
        self._joint_state: Any = None
        self._unsubscribe: list[Any] = []
        # Called once the server stopped (tree listeners that hold files or sockets: Groot2, recordings).
        self.on_close: list[Callable[[], None]] = []
        if log_sink is not None:
            self._unsubscribe.append(log_sink.subscribe(self._on_behavior_log))
        self._heartbeat_thread = threading.Thread(
            target=self._heartbeat_loop, name="kinema-heartbeat", daemon=True
        )
        self._drivers: dict[str, Any] = {}
        self._drivers_watch: Any = None
        self._declare()
        self._watch_drivers()

    def _declare(self) -> None:
        node = self.node
        node.create_service(
            names.EXECUTE_OBJECTIVE_TYPE, names.EXECUTE_OBJECTIVE, self._on_execute, deferred=True
        )
        node.create_service(names.CANCEL_OBJECTIVE_TYPE, names.CANCEL_OBJECTIVE, self._on_cancel)
        node.create_action_server(
            names.DO_OBJECTIVE_TYPE,
            names.DO_OBJECTIVE,
            self._on_do_objective,
            cancel_callback=self._on_cancel_goal,
            # Ended goals stay in the (latched) status array this long: long enough for a client to
            # fetch a result, short enough that a busy server does not publish thousands of them.
            result_timeout=DO_OBJECTIVE_RESULT_KEEP_S,
            deferred=True,
        )
        node.create_action_server(
            names.DO_OBJECTIVE_TYPE,
            names.RUN_OBJECTIVE,
            self._on_run_objective,
            cancel_callback=self._on_cancel_goal,
            result_timeout=DO_OBJECTIVE_RESULT_KEEP_S,
            deferred=True,
        )
        node.create_service(names.LIST_OBJECTIVES_TYPE, names.LIST_OBJECTIVES, self._on_list_objectives)
        node.create_service(names.GET_OBJECTIVE_XML_TYPE, names.GET_OBJECTIVE_XML, self._on_get_objective_xml)
        node.create_service(names.GET_WAYPOINTS_TYPE, names.GET_WAYPOINTS, self._on_get_waypoints)
        node.create_service(names.EDIT_WAYPOINTS_TYPE, names.EDIT_WAYPOINTS, self._on_edit_waypoints)
        if self.waypoints is not None:
            # Kept as received and decoded only when a waypoint is saved: a simulation at full speed
            # publishes thousands a second, and decoding each cost the tick thread and planning the GIL.
            node.create_subscription(JOINT_STATES_TYPE, JOINT_STATES_TOPIC, self._on_joint_states, raw=True)
        from kinema.runtime import quick_protocol as quick

        domain = self.session.domain_id
        self._quick = [
            self.session.zenoh.declare_queryable(quick.key(domain, op), handler, complete=True)
            for op, handler in (
                (quick.START, self._on_quick_start),
                (quick.START_XML, self._on_quick_start_xml),
                (quick.CANCEL, self._on_quick_cancel),
                (quick.STATUS, self._on_quick_status),
            )
        ]

    def _watch_drivers(self) -> None:
        """A driver that goes away (its process died, its link dropped) fails the running objective,
        naming it: a motion whose controller vanished did not succeed, and nobody cancelled it."""
        from kinema.runtime.cell import DRIVER, PRESENCE_PREFIX
        from kinema.transport.dispatch import channel, dispatch

        try:
            self._drivers_watch = self.session.zenoh.liveliness().declare_subscriber(
                f"{PRESENCE_PREFIX}/{self.session.domain_id}/*/{DRIVER}/**", channel(), history=True
            )
        except Exception:
            log.warning("cannot watch the drivers' presence; a driver's death ends objectives late")
            return
        self.session._track_dispatcher(dispatch(self._drivers_watch, self._on_driver_presence, "-drivers"))

    def _on_driver_presence(self, sample: Any) -> None:
        import zenoh

        from kinema.runtime.cell import parse_presence

        key = str(sample.key_expr)
        member = parse_presence(key)
        if member is None:
            return
        if sample.kind != zenoh.SampleKind.DELETE:
            self._drivers[key] = member
            return
        self._drivers.pop(key, None)
        status, name = self.server.status
        if status not in (ObjectiveStatus.RUNNING, ObjectiveStatus.LOADING) or self._stop.is_set():
            log.info("%s went away", member.describe())
            return
        reason = (
            f"objective {name!r} aborted: {member.describe()} went away while it ran (its process ended "
            "or its link dropped); the robot's controllers are gone"
        )
        log.error("%s", reason)
        self.server.abort(reason, timeout=0)  # never blocks the transport's thread

    # -- lifecycle -----------------------------------------------------------------------------------

    def start(self) -> None:
        """Start ticking and publishing the heartbeat."""
        self.server.start()
        self._streams.publish_heartbeat()
        self._heartbeat_thread.start()

    def close(
        self, reason: str = "the agent stopped (kinema down, Ctrl-C, or its supervisor stopped it)"
    ) -> None:
        """Stop the server (a running objective ends as FAILURE with ``reason``) and withdraw every
        endpoint."""
        self._stop.set()
        for unsubscribe in self._unsubscribe:
            unsubscribe()
        if self._drivers_watch is not None:
            try:
                self._drivers_watch.undeclare()
            except Exception:
                log.debug("driver watch already gone", exc_info=True)
        self.server.stop(reason=reason)
        with self._goal_lock:
            # Goals answer their clients (the stopped run's FAILURE) before the endpoints go.
            self._goal_lock.wait_for(lambda: not self._goal_runs, GOALS_ANSWER_AT_CLOSE_S)
        self._streams.close()
        for close in self.on_close:
            try:
                close()
            except Exception:
                log.exception("closing %r raised", close)
        for queryable in self._quick:
            queryable.undeclare()
        if self._heartbeat_thread.is_alive():
            self._heartbeat_thread.join(1.0)
        self.node.close()

    def __enter__(self) -> Agent:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _heartbeat_loop(self) -> None:
        while not self._stop.wait(names.HEARTBEAT_PERIOD_S):
            try:
                self._streams.publish_heartbeat()
            except KinemaError:
                if self._stop.is_set():
                    return
                log.debug("heartbeat not published", exc_info=True)

    # -- objectives ----------------------------------------------------------------------------------

    def _on_execute(self, request: Any, responder: Any) -> None:
        try:
            overrides = overrides_from_messages(request.parameter_overrides)
        except ObjectiveError as error:
            result = ObjectiveResult.failure(str(error), request.objective_name)
            responder.reply({"error_code": result_message(result)})
            return
        if not request.objective_name:
            result = ObjectiveResult.failure("ExecuteObjective needs an objective_name")
            responder.reply({"error_code": result_message(result)})
            return
        run = self.server.submit(ObjectiveRequest(request.objective_name, "", overrides, "execute_objective"))

        def reply(result: ObjectiveResult) -> None:
            try:
                responder.reply({"error_code": result_message(result)})
            except Exception:
                log.debug("could not answer /execute_objective (client gone?)", exc_info=True)

        run.add_done_callback(reply)

    def _on_cancel(self, request: Any) -> dict[str, Any]:
        cancelled = self.server.cancel(reason="cancelled by /cancel_objective")
        if cancelled:
            return {"status": {"success": True, "error_message": ""}}
        return {"status": {"success": False, "error_message": "no objective is running"}}

    def _on_run_objective(self, handle: Any) -> None:
        goal = handle.goal
        if goal.objective_xml_string:
            refused = ObjectiveResult.failure(NO_XML_HERE.format(door=names.RUN_OBJECTIVE), "<objective XML>")
            handle.abort({"error_code": result_message(refused), "error_message": refused.error_message})
            return
        self._on_do_objective(handle)

    def _on_do_objective(self, handle: Any) -> None:
        """Queue the goal's objective; its run's end ends the goal (on the tick thread).

        Runs on the thread that accepted the goal (a deferred action server): it never blocks, and no
        thread waits per goal.
        """
        goal = handle.goal
        try:
            overrides = overrides_from_messages(goal.parameter_overrides)
        except ObjectiveError as error:
            refused = ObjectiveResult.failure(str(error), goal.objective_name)
            handle.abort({"error_code": result_message(refused), "error_message": refused.error_message})
            return
        request = ObjectiveRequest(goal.objective_name, goal.objective_xml_string, overrides, "do_objective")

        def registered(run: ObjectiveRun) -> None:
            # Before the tick thread sees the run: a cancel of the goal finds it from the start.
            with self._goal_lock:
                self._goal_runs[handle.goal_id] = run
            # EXECUTING once the run ticks on (a run that ends in its first tick is published once, ended).
            run.add_running_callback(handle.execute)

        run = self.server.submit(request, before_start=registered)
        if handle.is_cancel_requested:
            self.server.cancel(run, reason="goal cancelled", timeout=0)
        run.add_done_callback(lambda result: self._end_goal(handle, result))

    def _end_goal(self, handle: Any, result: ObjectiveResult) -> None:
        """Answer a goal's clients with how its run ended (a done callback of the run: the tick thread)."""
        try:
            # Built from the classes: from_dict's checks of each field cost more than the rest of the
            # answer, on the tick thread, once per goal.
            payload = self._goal_result_class(
                error_code=self._error_codes_class(
                    val=int(result.error_code), message=result.error_message, source=names.NODE_NAME
                ),
                error_message=result.error_message,
            )
            if result.succeeded:
                handle.succeed(payload)
            elif result.cancelled:
                handle.canceled(payload)
            else:
                handle.abort(payload)
        except KinemaError:
            log.exception("could not end the goal of objective %r", result.objective_name)
        finally:
            # Only once the result is handed over: close() waits for this to answer waiting clients.
            with self._goal_lock:
                self._goal_runs.pop(handle.goal_id, None)
                self._goal_lock.notify_all()

    def _on_cancel_goal(self, handle: Any) -> bool:
        with self._goal_lock:
            run = self._goal_runs.get(handle.goal_id)
            if run is None:
                # Not queued yet: set under the lock that queuing takes, so _on_do_objective sees it.
                handle.cancel_requested_event.set()
                return True
        # Accepted only while the outcome is open: an accepted cancel never ends as SUCCESS.
        accepted = run.request_cancel("goal cancelled")
        if accepted:
            # Non-blocking: the tick thread halts the tree right away; the execute thread reports it.
            self.server.cancel(run, reason="goal cancelled", timeout=0)
        return accepted

    # -- the private JSON endpoints (kinema.runtime.quick_protocol) ----------------------------------------

    def _on_quick_start(self, query: Any) -> None:
        self._quick_start(query, xml=False)

    def _on_quick_start_xml(self, query: Any) -> None:
        self._quick_start(query, xml=True)

    def _quick_start(self, query: Any, *, xml: bool) -> None:
        from kinema.runtime import quick_protocol as quick

        try:
            body = quick.decode(query.payload.to_bytes() if query.payload is not None else b"")
            if body.get("objective_xml") and not xml:
                raise ValueError(NO_XML_HERE.format(door=quick.key(self.session.domain_id, quick.START)))
            overrides = tuple(
                ParameterOverride(
                    str(item["name"]),
                    item["value"],
                    tuple(item.get("behavior_namespaces", ())),
                    from_yaml=isinstance(item["value"], str),
                )
                for item in body.get("overrides", ())
            )
            request = ObjectiveRequest(
                str(body.get("objective_name", "")), str(body.get("objective_xml", "")), overrides, "json"
            )
        except (ValueError, KeyError, TypeError) as error:
            with query:
                query.reply_err(f"bad request: {error}".encode())
            return

        def listen(run: ObjectiveRun) -> None:
            # Before the run is queued: a behavior that logs on the first tick must find its listener.
            query.reply(query.key_expr, quick.encode({"event": "accepted", "run_id": run.id}))
            with self._goal_lock:
                self._quick_listeners[run.id] = query

        run = self.server.submit(request, before_start=listen)

        def finish(result: ObjectiveResult) -> None:
            with self._goal_lock:
                self._quick_listeners.pop(run.id, None)
            payload = {
                "event": "result",
                "run_id": run.id,
                "error_code": int(result.error_code),
                "error_message": result.error_message,
                "objective_name": result.objective_name,
            }
            try:
                query.reply(query.key_expr, quick.encode(payload))
            except Exception:
                log.debug("the JSON client of run %d is gone", run.id, exc_info=True)
            finally:
                query.drop()

        with self._goal_lock:
            self._quick_runs[run.id] = run
        run.add_done_callback(finish)

    def _on_quick_cancel(self, query: Any) -> None:
        from kinema.runtime import quick_protocol as quick

        with query:
            try:
                body = quick.decode(query.payload.to_bytes() if query.payload is not None else b"")
            except ValueError as error:
                query.reply_err(f"bad request: {error}".encode())
                return
            run_id = body.get("run_id")
            name = self.server.status[1]
            with self._goal_lock:
                run = self._quick_runs.get(run_id) if run_id is not None else None
            if run_id is not None and run is None:
                cancelled = False
            else:
                cancelled = self.server.cancel(run, reason="cancelled by a client")
            query.reply(query.key_expr, quick.encode({"cancelled": cancelled, "objective_name": name}))

    def _on_quick_status(self, query: Any) -> None:
        from kinema.runtime import quick_protocol as quick

        status, name = self.server.status
        warnings = list(self.server.health().warnings)
        with query:
            query.reply(
                query.key_expr,
                quick.encode({"status": str(status), "objective_name": name, "warnings": warnings}),
            )

    # -- library -----------------------------------------------------------------------------------

    def _on_list_objectives(self, request: Any) -> dict[str, Any]:
        if self.source is None:
            names_only = self.server._source.objective_names()
            return {
                "status": {"success": True},
                "objectives": [{"name": n, "runnable": True} for n in names_only],
            }
        infos = self.source.objectives()
        if request.subcategory:
            infos = [info for info in infos if info.subcategory == request.subcategory]
        return {
            "status": {"success": True, "error_message": ""},
            "objectives": [_info_dict(i, self._parameters(i)) for i in infos],
        }

    def _parameters(self, info: ObjectiveInfo) -> list[Any]:
        from kinema.config.objective_parameters import objective_interface

        assert self.source is not None
        try:
            factory = self.source.factory()
        except KinemaError:
            factory = None
        return objective_interface(info, factory)

    def _on_get_objective_xml(self, request: Any) -> dict[str, Any]:
        if self.source is None:
            return {"status": {"success": False, "error_message": "this agent has no objective library"}}
        for info in self.source.objectives():
            if info.id == request.objective_name:
                try:
                    return {"status": {"success": True}, "xml": Path(info.file).read_text(encoding="utf-8")}
                except OSError as error:
                    return {"status": {"success": False, "error_message": f"{info.file}: {error}"}}

        known = [info.id for info in self.source.objectives()]
        message = (
            f"no objective named {request.objective_name!r}; {did_you_mean(request.objective_name, known)}"
        )
        return {"status": {"success": False, "error_message": message}}

    # -- waypoints ---------------------------------------------------------------------------------

    def _on_joint_states(self, payload: bytes) -> None:
        self._joint_state = payload

    def _on_get_waypoints(self, request: Any) -> dict[str, Any]:
        if self.waypoints is None:
            return {"status": {"success": False, "error_message": "the config has no waypoints file"}}
        try:
            waypoints = self.waypoints.all()
        except KinemaError as error:
            return {"status": {"success": False, "error_message": str(error)}}
        return {"status": {"success": True}, "waypoints": [_waypoint_dict(w) for w in waypoints]}

    def _on_edit_waypoints(self, request: Any) -> dict[str, Any]:
        if self.waypoints is None:
            return {"status": {"success": False, "error_message": "the config has no waypoints file"}}
        operation = int(request.operation)
        copy_existed = self.waypoints.path.exists()
        try:
            response = self._edit_waypoints(operation, request)
        finally:
            if self.waypoints.notice and not copy_existed and self.waypoints.path.exists():
                # The first change of inherited waypoints: say once where they are kept from now on.
                log.warning("waypoints: %s", self.waypoints.notice)
                self._streams.publish_log(LOG_WARN, f"Waypoints: {self.waypoints.notice}")
        return response

    def _edit_waypoints(self, operation: int, request: Any) -> dict[str, Any]:
        assert self.waypoints is not None
        try:
            if operation == 0:
                waypoint = self._save_current(request.waypoint_name, list(request.joint_group_names))
                return {"status": {"success": True}, "new_waypoint": _waypoint_dict(waypoint)}
            if operation == 1:
                self.waypoints.rename(request.waypoint_name, request.existing_waypoint_new_name)
                renamed = self.waypoints.get(request.existing_waypoint_new_name)
                return {"status": {"success": True}, "new_waypoint": _waypoint_dict(renamed)}
            if operation == 2:
                self.waypoints.erase(request.waypoint_name)
                return {"status": {"success": True}}
        except KinemaError as error:
            return {"status": {"success": False, "error_message": str(error)}}
        return {
            "status": {
                "success": False,
                "error_message": f"unknown operation {operation}; valid: 0 (SAVE), 1 (RENAME), 2 (ERASE)",
            }
        }

    def _save_current(self, name: str, groups: list[str]) -> Any:
        from kinema.config import Waypoint

        assert self.waypoints is not None
        known = list(self._robot_groups()) if self._robot_groups is not None else []
        for group in groups:
            if known and group not in known:
                raise ObjectiveError(
                    f"cannot save waypoint {name!r}: {group!r} is no planning group of the robot; "
                    f"{did_you_mean(group, known)}"
                )
        payload = self._joint_state
        if payload is None:
            raise ObjectiveError(f"cannot save waypoint {name!r}: no /joint_states received yet")
        state = self.session.registry.deserialize(payload, JOINT_STATES_TYPE)
        waypoint = Waypoint(
            name=name,
            joint_names=[str(n) for n in state.name],
            positions=[float(p) for p in state.position],
            joint_group_names=groups or list(self.waypoint_groups),
        )
        self.waypoints.save(waypoint)
        return waypoint

    # -- logs ----------------------------------------------------------------------------------------

    def _on_behavior_log(self, message: LogMessage) -> None:
        level = {"info": LOG_INFO, "warn": LOG_WARN, "failure": LOG_ERROR}.get(str(message.level), LOG_INFO)
        where = message.node_path or message.node_name or message.behavior_id
        if str(message.level) == "failure" and message.node_path:
            self.server.note_failure(message.node_path, message.text)
        text = f"[{where}] {message.text}" if where else message.text
        self._streams.publish_log(level, text)
        self._tell_quick_clients(str(message.level), text)

    def _tell_quick_clients(self, level: str, text: str) -> None:
        """Send a toast to the JSON clients waiting for a run (``kinema objective run`` prints it)."""
        from kinema.runtime import quick_protocol as quick

        with self._goal_lock:
            listeners = list(self._quick_listeners.items())
        for run_id, query in listeners:
            try:
                query.reply(query.key_expr, quick.encode({"event": "log", "level": level, "text": text}))
            except Exception:
                log.debug("could not send a toast to the JSON client of run %d", run_id, exc_info=True)

    def warn_reload(self, message: str) -> None:
        """A warning about files watched for hot reload, where its outcomes go: the plugin log (``kinema
        logs``; ``kinema run``'s terminal echoes it) and a toast."""
        plugin_log.warning("%s", message)
        self._streams.publish_log(LOG_WARN, message)

    def report_cell_conflict(self, message: str) -> None:
        """Two agents or two drivers share this network (see :mod:`kinema.runtime.cell`): log and toast."""
        log.error("%s", message)
        self._streams.publish_log(LOG_ERROR, message)

    def on_reload_event(self, event: ReloadEvent) -> None:
        """Report a hot-reload outcome: a toast, and the agent's log (``kinema logs``, the run terminal).

        Subscribe it to the behavior host.
        """
        if str(event.kind) == "objectives_changed" and self.source is not None:
            # Before the notice goes out: a client that asks for the list as soon as it reads the notice
            # (the TUI does) must get the new one, and no later notice comes while the files stay as they are.
            self.source.invalidate_objectives()
        plugin_log.log(logging.INFO if event.ok else logging.ERROR, "%s", event)
        self._streams.publish_log(LOG_INFO if event.ok else LOG_ERROR, str(event))
        if str(event.kind) == "objectives_changed" and self.source is not None:
            self._check_changed_objectives(event.paths)

    def _check_changed_objectives(self, paths: Sequence[str]) -> None:
        """Say now what `kinema build` would say about objective files saved while the runtime runs (a port
        that is not there, an unknown behavior), not only when one runs: a warning each, with file:line."""
        from pathlib import Path

        from kinema.bt.validation import validate_files

        assert self.source is not None
        files: list[str | Path] = [path for path in paths if path.endswith(".xml") and Path(path).is_file()]
        if not files:
            return
        try:
            problems: list[object] = list(validate_files(files, self.source.factory()))
        except KinemaError as error:
            problems = [error]
        for problem in problems:
            text = f"{problem} (the objective fails there when it runs; `kinema build` lists every problem)"
            plugin_log.warning("%s", text)
            self._streams.publish_log(LOG_WARN, text)


def _info_dict(info: ObjectiveInfo, parameters: Sequence[Any] | None = None) -> dict[str, Any]:
    """The ObjectiveInfo message of ``info``; its ports are ``parameters`` (the overridable ones) if given."""
    directions = {"input": 0, "output": 1, "inout": 2}
    ports = []
    for port in info.ports if parameters is None else parameters:
        direction = getattr(port.direction, "value", port.direction)
        ports.append(
            {
                "name": port.name,
                "direction": directions.get(str(direction).lower(), 0)
                if not isinstance(direction, int)
                else direction,
                "default_value": port.default or "",
                "description": port.description or "",
                "type_name": getattr(port, "type_name", "") or "",
            }
        )
    return {
        "name": info.id,
        "description": info.description or "",
        "subcategory": info.subcategory or "",
        "runnable": bool(info.runnable),
        "favorite": bool(info.favorite),
        "package": info.package or "",
        "file_path": str(info.file),
        "ports": ports,
    }


def _waypoint_dict(waypoint: Any) -> dict[str, Any]:
    return {
        "name": waypoint.name,
        "description": waypoint.description,
        "favorite": waypoint.favorite,
        "joint_group_names": list(waypoint.joint_group_names),
        "joint_state": {
            "name": list(waypoint.joint_names),
            "position": [float(p) for p in waypoint.positions],
            "velocity": [float(v) for v in waypoint.velocities],
            "effort": [float(e) for e in waypoint.efforts],
        },
    }


def error_code_of(result_msg: Any) -> int:
    """The ``val`` of a MoveItErrorCodes message (0 when absent)."""
    return int(getattr(result_msg, "val", MoveItErrorCode.UNDEFINED))


def build_host(resolved: Any) -> BehaviorHost:
    """Load the behavior plugins a resolved config activates; failures are logged, not fatal."""
    from kinema.plugins import BehaviorHost

    host = BehaviorHost.for_config(resolved)
    report = host.load()
    for warning in report.warnings:
        plugin_log.warning("%s", warning)
    for error in report.errors:
        plugin_log.error("%s", error)
    return host
