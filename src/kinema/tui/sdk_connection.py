"""The TUI's connection to a real runtime, through :class:`kinema.sdk.ObjectiveClient` and its transport node.

It subscribes to what any SDK client can see (heartbeat, node status changes, blackboard snapshots, logs,
``/clock``) and calls the agent's public services; nothing here is private to the TUI. A supervisor thread
keeps it connected: it joins the router (retrying while there is none), declares the subscriptions,
reports the runtime as disconnected when heartbeats stop, and starts over with a fresh session when they
stay away, so a restarted runtime is picked up without restarting the app.
"""

from __future__ import annotations

import logging
import re
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinema.errors import KinemaError, ObjectiveError, TransportError
from kinema.tui.connection import (
    ApprovalRequested,
    BehaviorSummary,
    BlackboardEntry,
    BlackboardSnapshot,
    ClockSample,
    ConnectionChanged,
    ConnectionState,
    EventListener,
    Heartbeat,
    ImageListener,
    LogEntry,
    LogLevel,
    NodeStatus,
    NodeStatusBatch,
    NodeStatusUpdate,
    ObjectivesChanged,
    ObjectiveSummary,
    PortSummary,
    ReloadNotice,
    RuntimeEvent,
    SolutionStep,
    TaskPlanning,
    TaskStage,
    UserInputAnswer,
    UserInputRequested,
    WaypointSummary,
)
from kinema.ui_topics import (
    APPROVAL_SERVICE,
    APPROVAL_TYPE,
    TASK_PLANNING_TOPIC,
    TASK_PLANNING_TYPE,
    TELEOPERATION_MODE_TOPIC,
    TELEOPERATION_MODE_TYPE,
    USER_INPUT_SERVICE,
    USER_INPUT_TYPE,
)

if TYPE_CHECKING:
    from kinema.config import ResolvedConfig, Waypoint, Workspace
    from kinema.sdk import ObjectiveClient
    from kinema.sdk.streams import NodeStatusChanges

log = logging.getLogger("kinema.tui")

#: The runtime counts as gone when no heartbeat (10 Hz) arrived for this long. Generous: a runtime busy
#: planning on a loaded machine delays heartbeats by a second or more without being gone.
HEARTBEAT_TIMEOUT_S = 3.0
#: How long image_topics() waits for the network's answer about its topics.
GRAPH_QUERY_S = 1.0
#: After this long without heartbeats the session is dropped and a new one is opened.
RECONNECT_AFTER_S = 6.0
RETRY_PERIOD_S = 1.0
# How long closing waits for the supervisor thread (it may be joining a router that does not answer).
CLOSE_WAIT_S = 0.2
CALL_TIMEOUT_S = 5.0
#: The objective MoveIt Pro (and Kinema's core library) moves to a waypoint with.
MOVE_TO_WAYPOINT_OBJECTIVE = "Move to Waypoint"
MOVE_TO_WAYPOINT_TREE = "Move to Waypoint (from the UI)"
_DIRECTIONS = {0: "input", 1: "output", 2: "inout"}
# The runtime publishes hot-reload outcomes on its log stream (kinema.plugins.host wording).
_RELOADED = re.compile(r"^Reloaded (?P<subject>\S+): (?P<ids>.*)$")
_RELOAD_FAILED = re.compile(
    r"^(?:(?P<location>.+?:\d+): )?(?P<subject>.+?) not reloaded, keeping the last good"
)
_OBJECTIVES_CHANGED = re.compile(r"^Objectives changed: (?P<names>.*)$")


def reload_notice_from_log(text: str, level: int, stamp: float = 0.0) -> ReloadNotice | None:
    """Recognise a hot-reload outcome among the runtime's log messages, or return None."""
    found = _RELOADED.match(text)
    if found:
        ids = tuple(i.strip() for i in found["ids"].split(",") if i.strip() and i.strip() != "no behaviors")
        return ReloadNotice(True, "behaviors_reloaded", found["subject"], text, "", ids, stamp)
    found = _OBJECTIVES_CHANGED.match(text)
    if found:
        return ReloadNotice(True, "objectives_changed", "objectives", text, "", (), stamp)
    found = _RELOAD_FAILED.match(text)
    if found and level == int(LogLevel.ERROR):
        location = found["location"] or ""
        message = text[len(location) + 2 :] if location else text
        return ReloadNotice(False, "reload_failed", found["subject"], message, location, (), stamp)
    return None


class SdkConnection:
    """A :class:`~kinema.tui.connection.RuntimeConnection` to a runtime on the zenoh network.

    Args:
        endpoint: the router to join (default ``KINEMA_ZENOH_CONNECT`` or ``tcp/127.0.0.1:7447``).
        workspace: the workspace the Configs and Behaviors screens read (default: the active one).
        config: the config package the runtime runs (default: the active one), for the behavior catalog.
        heartbeat_timeout: seconds without a heartbeat before the runtime is shown as disconnected.
    """

    def __init__(
        self,
        endpoint: str | None = None,
        *,
        workspace: Path | None = None,
        config: str | None = None,
        heartbeat_timeout: float = HEARTBEAT_TIMEOUT_S,
    ) -> None:
        self._endpoint = endpoint
        self._workspace_path = workspace
        self._config = config
        self._heartbeat_timeout = heartbeat_timeout
        self._listener: EventListener | None = None
        self._client: ObjectiveClient | None = None
        self._lock = threading.Lock()
        self._state_lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._last_heartbeat = 0.0
        # The watchdog warnings of the last /objective_server/health, shown with each heartbeat.
        self._warnings: tuple[str, ...] = ()
        self._state = ConnectionState.CONNECTING
        self._clock_window: deque[tuple[float, float]] = deque(maxlen=50)
        self._last_clock_event = 0.0
        self._selection_cache: tuple[Workspace, str | None] | None = None
        self._teleoperation_publisher: Any = None
        self._teleoperation_node: Any = None

    # -- identity -------------------------------------------------------------------------------

    @property
    def endpoint(self) -> str:
        if self._endpoint:
            return self._endpoint
        from kinema.transport.session import default_endpoints

        # A client config's endpoint (KINEMA_ZENOH_CONFIG) is where the session goes, not 7447.
        return ", ".join(default_endpoints())

    @property
    def config_name(self) -> str | None:
        if self._config:
            return self._config
        from kinema.config import active_selection

        try:
            return active_selection().config
        except KinemaError:
            return None

    # -- lifecycle ------------------------------------------------------------------------------

    def open(self, listener: EventListener) -> None:
        self._listener = listener
        self._stop.clear()
        self._thread = threading.Thread(target=self._supervise, name="kinema-tui-connection", daemon=True)
        self._thread.start()

    def close(self) -> None:
        """Stop listening. Returns at once even while a connection attempt is under way (joining a router
        that does not answer takes zenoh about 2 s): the supervisor thread closes what it opens after
        this and ends."""
        self._stop.set()
        self._listener = None
        if self._thread is not None:
            self._thread.join(timeout=CLOSE_WAIT_S)
            self._thread = None
        self._drop_client()

    def _emit(self, event: RuntimeEvent) -> None:
        listener = self._listener
        if listener is not None:
            listener(event)

    def _set_state(self, state: ConnectionState, detail: str = "") -> None:
        with self._state_lock:  # heartbeats (transport thread) and the supervisor both change it
            if state is self._state:
                return
            self._state = state
        self._emit(ConnectionChanged(state, self.endpoint, detail))

    def _supervise(self) -> None:
        """Keep a session with live subscriptions while open (runs on its own thread)."""
        while not self._stop.is_set():
            if self._client is None:
                try:
                    self._connect()
                    if self._stop.is_set():  # closed while joining: nobody will drop this client
                        self._drop_client()
                        break
                except Exception as error:
                    if self._stop.is_set():  # closed while joining: the failure is the close's
                        self._drop_client()
                        break
                    if not isinstance(error, KinemaError):  # keep retrying; the app shows why
                        log.exception("connecting to the runtime failed")
                    self._set_state(ConnectionState.DISCONNECTED, describe(error))
                    self._stop.wait(RETRY_PERIOD_S)
                    continue
            silent = time.monotonic() - self._last_heartbeat
            if self._state is ConnectionState.CONNECTED and silent > self._heartbeat_timeout:
                self._set_state(
                    ConnectionState.DISCONNECTED, f"no heartbeat from the runtime for {silent:.1f} s"
                )
            elif self._state is not ConnectionState.CONNECTED and silent > RECONNECT_AFTER_S:
                self._drop_client()  # start over with a fresh session: the router may have restarted
                continue
            self._stop.wait(0.2)

    def _connect(self) -> None:
        from kinema.drivers.mujoco import names as driver_names
        from kinema.runtime import names
        from kinema.sdk import ObjectiveClient
        from kinema.sdk.client import NodeStatusSubscription

        client = ObjectiveClient(self._endpoint, timeout=CALL_TIMEOUT_S)
        # Published before subscribing: the latched heartbeat can arrive while subscribing, and a
        # screen that sees "connected" must find a client to call.
        with self._lock:
            self._client = client
        node = client.node
        try:
            node.create_subscription(names.HEARTBEAT_TYPE, names.HEARTBEAT, self._on_heartbeat, latched=True)
            node.create_subscription(names.HEALTH_TYPE, names.HEALTH, self._on_health, latched=True)
            NodeStatusSubscription(node, self._emit_node_changes)  # closed with the client's node
            node.create_subscription(
                names.BLACKBOARD_TYPE, names.BLACKBOARD, self._on_blackboard, latched=True
            )
            node.create_subscription(names.LOG_TYPE, names.LOG, self._on_log)
            node.create_subscription(driver_names.CLOCK_TYPE, driver_names.CLOCK_TOPIC, self._on_clock)
            node.create_subscription(TASK_PLANNING_TYPE, TASK_PLANNING_TOPIC, self._on_task_planning)
            # While the TUI is attached it is the user the approval behaviors ask (see ui/approval.py
            # of the core behaviors): each request waits for the dialog's answer.
            node.create_service(
                APPROVAL_TYPE, APPROVAL_SERVICE, self._on_approval, deferred=True, max_concurrent=4
            )
            # ... and the one the user-input behaviors ask (ui/user_input.py of the core behaviors).
            node.create_service(
                USER_INPUT_TYPE, USER_INPUT_SERVICE, self._on_user_input, deferred=True, max_concurrent=4
            )
        except Exception:
            self._drop_client()
            raise
        self._last_heartbeat = time.monotonic()  # give the latched heartbeat a moment to arrive
        if self._state is ConnectionState.DISCONNECTED:
            self._set_state(ConnectionState.CONNECTING, "joined the router, waiting for a heartbeat")

    def _drop_client(self) -> None:
        with self._lock:
            client, self._client = self._client, None
        if client is not None:
            try:
                client.close()
            except Exception:  # a dead session may fail to close; it is gone either way
                log.debug("closing the SDK client failed", exc_info=True)

    # -- stream callbacks (transport threads) --------------------------------------------------

    def _on_approval(self, request: Any, responder: Any) -> None:
        def answer(approved: bool, message: str) -> None:
            if not responder.done:
                responder.reply({"approved": approved, "message": message})

        steps = tuple(
            SolutionStep(
                str(step.stage),
                float(step.duration),
                tuple(str(n) for n in step.joint_names),
                str(step.gripper),
                str(step.note),
            )
            for step in request.steps
        )
        self._emit(
            ApprovalRequested(
                str(request.prompt),
                str(request.behavior),
                str(request.node_path),
                answer,
                steps,
                float(request.duration),
            )
        )

    def _on_user_input(self, request: Any, responder: Any) -> None:
        def answer(reply: UserInputAnswer) -> None:
            if responder.done:
                return
            x, y, z = reply.position
            qx, qy, qz, qw = reply.orientation
            responder.reply(
                {
                    "accepted": reply.accepted,
                    "message": reply.message,
                    "pose": {
                        "header": {"frame_id": reply.frame_id},
                        "pose": {
                            "position": {"x": x, "y": y, "z": z},
                            "orientation": {"x": qx, "y": qy, "z": qz, "w": qw},
                        },
                    },
                    "points": [{"x": column, "y": row, "z": 0.0} for column, row in reply.points],
                    "joint_state": {
                        "name": list(joint_names) if reply.joint_positions else [],
                        "position": list(reply.joint_positions),
                    },
                }
            )

        pose = request.initial_pose
        p, q = pose.pose.position, pose.pose.orientation
        joints = request.initial_joint_state
        joint_names = tuple(str(name) for name in joints.name)
        self._emit(
            UserInputRequested(
                str(request.kind),
                str(request.prompt),
                str(request.behavior),
                str(request.node_path),
                answer,
                str(pose.header.frame_id) or "world",
                (float(p.x), float(p.y), float(p.z)),
                (float(q.x), float(q.y), float(q.z), float(q.w)),
                str(request.image_topic),
                tuple(str(text) for text in request.point_prompts),
                tuple(str(text) for text in request.point_names),
                int(request.initial_teleop_mode),
                joint_names,
                tuple(float(value) for value in joints.position),
            )
        )

    def set_teleoperation_mode(self, mode: int) -> None:
        from kinema.transport import from_dict

        # The session that asked is on this connection's node, heartbeat or not (a behavior asked it).
        client = self._client
        if client is None:
            raise TransportError(f"not connected to a runtime at {self.endpoint} (is `kinema run` running?)")
        with self._lock:
            publisher = self._teleoperation_publisher
            if publisher is None or self._teleoperation_node is not client.node:
                publisher = client.node.create_publisher(TELEOPERATION_MODE_TYPE, TELEOPERATION_MODE_TOPIC)
                self._teleoperation_publisher = publisher
                self._teleoperation_node = client.node
        publisher.publish(from_dict(TELEOPERATION_MODE_TYPE, {"data": int(mode)}))

    def _on_task_planning(self, message: Any) -> None:
        stages = tuple(
            TaskStage(str(s.name), str(s.type), str(s.kind), str(s.state), float(s.seconds), str(s.comment))
            for s in message.stages
        )
        self._emit(
            TaskPlanning(
                str(message.task_id),
                str(message.node_path),
                str(message.state),
                float(message.seconds),
                str(message.message),
                stages,
            )
        )

    def _on_heartbeat(self, message: Any) -> None:
        self._last_heartbeat = time.monotonic()
        self._set_state(ConnectionState.CONNECTED)
        stamp = message.process_timestamp
        self._emit(
            Heartbeat(
                float(stamp.sec) + float(stamp.nanosec) * 1e-9,
                str(message.objective_name),
                str(message.objective_status),
                self._warnings,
            )
        )

    def _on_health(self, message: Any) -> None:
        self._warnings = tuple(str(warning) for warning in message.warnings)

    def _emit_node_changes(self, batch: NodeStatusChanges) -> None:
        updates = tuple(
            NodeStatusUpdate(
                change.uid,
                change.node_path,
                change.node_id,
                change.node_name,
                _status(change.status),
                _status(change.previous_status),
            )
            for change in batch.changes
        )
        if updates:
            self._emit(NodeStatusBatch(batch.objective_name, updates))

    def _on_blackboard(self, message: Any) -> None:
        stamp = message.stamp
        entries = tuple(
            BlackboardEntry(str(e.scope), str(e.key), str(e.type_name), str(e.value_yaml))
            for e in message.entries
        )
        self._emit(
            BlackboardSnapshot(
                str(message.objective_name), float(stamp.sec) + float(stamp.nanosec) * 1e-9, entries
            )
        )

    def _on_log(self, message: Any) -> None:
        level = int(message.log_level)
        text = str(message.message)
        now = time.time()
        notice = reload_notice_from_log(text, level, now)
        if notice is not None:
            self._emit(notice)
            if notice.kind == "objectives_changed":
                self._emit(ObjectivesChanged())
            if notice.ok:
                return  # shown in the Behaviors screen; a good reload is not worth a toast
        known = level if level in (1, 2, 3) else int(LogLevel.INFO)
        self._emit(LogEntry(text, LogLevel(known), now, "runtime"))

    def _on_clock(self, message: Any) -> None:
        stamp = message.clock
        sim = float(stamp.sec) + float(stamp.nanosec) * 1e-9
        wall = time.monotonic()
        window = self._clock_window
        if window and sim < window[-1][0]:
            window.clear()  # the simulation was reset
        window.append((sim, wall))
        if wall - self._last_clock_event < 0.1:
            return  # /clock may tick at 1 kHz; the status bar needs a few updates a second
        self._last_clock_event = wall
        factor = None
        if len(window) >= 2 and window[-1][1] - window[0][1] > 0.05:
            factor = (window[-1][0] - window[0][0]) / (window[-1][1] - window[0][1])
        self._emit(ClockSample(sim, factor))

    # -- calls (worker threads) -----------------------------------------------------------------

    def _require_client(self) -> ObjectiveClient:
        client = self._client
        if client is None or self._state is not ConnectionState.CONNECTED:
            raise TransportError(f"not connected to a runtime at {self.endpoint} (is `kinema run` running?)")
        return client

    def workspace(self) -> Workspace:
        return self._selection()[0]

    def list_objectives(self) -> list[ObjectiveSummary]:
        return [_objective_summary(info) for info in self._require_client().objectives()]

    def objective_xml(self, name: str) -> str:
        return self._require_client().objective_xml(name)

    def start_objective(self, name: str, overrides: Mapping[str, str]) -> None:
        self._require_client().start(name, dict(overrides) or None)

    def cancel_objective(self) -> None:
        self._require_client().cancel()

    def list_waypoints(self) -> list[WaypointSummary]:
        return [_waypoint_summary(w) for w in self._require_client().waypoints()]

    def move_to_waypoint(self, name: str) -> None:
        client = self._require_client()
        known = {str(info.name) for info in client.objectives()}
        if MOVE_TO_WAYPOINT_OBJECTIVE not in known:
            raise ObjectiveError(
                f"the runtime has no {MOVE_TO_WAYPOINT_OBJECTIVE!r} objective to move with; "
                "run a config whose objective library includes Kinema's core objectives"
            )
        from xml.sax.saxutils import quoteattr  # here: it imports urllib, 30 ms the first frame need not wait

        # Wrapped as a SubTree, as MoveIt Pro's UI does: the subtree's other ports then take the defaults
        # its TreeNodesModel declares (planning group, controller, ...), which a direct run would not.
        xml = (
            f'<root BTCPP_format="4" main_tree_to_execute="{MOVE_TO_WAYPOINT_TREE}">'
            f'<BehaviorTree ID="{MOVE_TO_WAYPOINT_TREE}">'
            f'<SubTree ID="{MOVE_TO_WAYPOINT_OBJECTIVE}" waypoint_name={quoteattr(name)}/>'
            "</BehaviorTree></root>"
        )
        client.start(xml=xml)

    def save_waypoint(self, name: str, joint_group_names: tuple[str, ...] = ()) -> WaypointSummary:
        return _waypoint_summary(self._require_client().save_waypoint(name, joint_group_names))

    def rename_waypoint(self, name: str, new_name: str) -> None:
        self._require_client().rename_waypoint(name, new_name)

    def erase_waypoint(self, name: str) -> None:
        self._require_client().erase_waypoint(name)

    def list_behaviors(self) -> list[BehaviorSummary]:
        """The engine's built-in nodes plus the behaviors the runtime's config loads.

        The runtime serves no behavior list, so the plugins are loaded here, from the same workspace and
        config, exactly as the runtime loads them (a reload event makes the screen list them again).
        """
        from kinema.config import resolve_config

        workspace, config = self._selection()
        catalog = builtin_behaviors()
        if config:
            try:
                catalog += plugin_behaviors(resolve_config(config, workspace, check_files=False))
            except KinemaError as error:
                # E.g. attached to a runtime on another machine whose config is not here: the built-in
                # nodes are still worth listing; say why the rest is missing.
                self._emit(
                    LogEntry(
                        f"behaviors: the plugins of config {config!r} could not be loaded here: {error}",
                        LogLevel.WARN,
                        time.time(),
                        "ui",
                    )
                )
        return catalog

    def image_topics(self) -> list[str]:
        from kinema.tui.camera_image import IMAGE_TYPE

        client = self._require_client()
        # A fresh look at the whole network (the session's graph cache may not know every publisher yet),
        # joined with that cache (a query on a loaded machine may run out its time before every reply).
        names: set[str] = set()
        for graph in (client.node.graph(timeout=GRAPH_QUERY_S), client.node.graph()):
            names.update(name for name, types in graph.topics().items() if IMAGE_TYPE in types)
        return sorted(names)

    def watch_images(self, topic: str, listener: ImageListener) -> Callable[[], None]:
        from kinema.tui.camera_image import IMAGE_TYPE, camera_image

        client = self._require_client()
        problems: list[str] = []

        def on_image(message: Any) -> None:
            try:
                image = camera_image(topic, message)
            except KinemaError as error:
                if not problems:  # say it once, not at every frame
                    problems.append(str(error))
                    self._emit(LogEntry(f"{topic}: {error}", LogLevel.WARN, time.time(), "camera view"))
                return
            listener(image)

        subscription = client.node.create_subscription(IMAGE_TYPE, topic, on_image)
        return subscription.close

    def _selection(self) -> tuple[Workspace, str | None]:
        if self._selection_cache is None:
            from kinema.config import Workspace, active_selection

            selection = active_selection(self._workspace_path, self._config)
            workspace = (
                Workspace.discover(selection.workspace) if selection.workspace else Workspace.bundled_only()
            )
            self._selection_cache = (workspace, selection.config)
        return self._selection_cache


def builtin_behaviors() -> list[BehaviorSummary]:
    """The engine's built-in nodes (Sequence, Sleep, Script, ...)."""
    from kinema.bt import BehaviorTreeFactory

    manifests = BehaviorTreeFactory().manifests()
    return [
        BehaviorSummary(
            manifest.id,
            "kinema.bt",
            "built-in node",
            "",
            tuple(_port_summary(port) for port in manifest.ports.values()),
            {
                "subcategory": str(manifest.category),
                **dict(manifest.metadata),
                **({"description": manifest.description} if manifest.description else {}),
            },
        )
        for manifest in manifests.values()
        if manifest.builtin
    ]


def plugin_behaviors(resolved: ResolvedConfig) -> list[BehaviorSummary]:
    """The behaviors registered by the plugins ``resolved`` activates; a failed plugin is one error row."""
    from kinema.plugins import BehaviorHost

    host = BehaviorHost.for_config(resolved)
    report = host.load()
    registry = host.registry
    out: list[BehaviorSummary] = []
    for behavior_id in registry:
        record = registry[behavior_id]
        spec = registry.plugins[record.plugin].spec if record.plugin in registry.plugins else None
        source = f"{spec.source.value}: {spec.where}" if spec is not None else ""
        out.append(
            BehaviorSummary(
                behavior_id,
                record.plugin,
                source,
                str(record.location),
                tuple(_port_summary(port) for port in record.ports),
                dict(record.metadata),
            )
        )
    for error in report.errors:
        log.warning("plugins: %s", error)
    return out


def _port_summary(port: Any) -> PortSummary:
    direction = getattr(port.direction, "name", str(port.direction)).lower()
    return PortSummary(
        port.name,
        direction,
        port.default_str or "",
        port.description or "",
        port.type_name,
    )


def _status(value: Any) -> NodeStatus:
    try:
        return NodeStatus(int(value))
    except ValueError:
        return NodeStatus.IDLE


def _objective_summary(info: Any) -> ObjectiveSummary:
    return ObjectiveSummary(
        name=str(info.name),
        description=str(info.description),
        subcategory=str(info.subcategory),
        runnable=bool(info.runnable),
        favorite=bool(info.favorite),
        package=str(info.package),
        file_path=str(info.file_path),
        ports=tuple(
            PortSummary(
                str(port.name),
                _DIRECTIONS.get(int(port.direction), "input"),
                str(port.default_value),
                str(port.description),
                str(getattr(port, "type_name", "")),
            )
            for port in info.ports
        ),
    )


def _waypoint_summary(waypoint: Waypoint) -> WaypointSummary:
    return WaypointSummary(
        name=waypoint.name,
        description=waypoint.description,
        favorite=waypoint.favorite,
        joint_names=tuple(waypoint.joint_names),
        positions=tuple(waypoint.positions),
        joint_group_names=tuple(waypoint.joint_group_names),
    )


def describe(error: Exception) -> str:
    """What the app shows for a failed connection attempt: Kinema's own message, else the type too."""
    return str(error) if isinstance(error, KinemaError) else f"{type(error).__name__}: {error}"
