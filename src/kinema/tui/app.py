"""The Kinema terminal UI: browse configs and objectives, run them, watch the live blackboard.

The app is a subscriber like any SDK client: it holds a :class:`RuntimeConnection`, receives its events on
background threads into an inbox, and drains the inbox on the UI thread, keeping only the newest
heartbeat, clock sample and blackboard snapshot, so a fast stream can never queue up behind the screen.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

from textual import events
from textual.app import App, SuspendNotSupported, SystemCommand
from textual.binding import Binding
from textual.notifications import SeverityLevel
from textual.screen import Screen
from textual.timer import Timer

from kinema.tui import startup_gc
from kinema.tui.blackboard_model import BlackboardModel
from kinema.tui.connection import (
    ApprovalRequested,
    BlackboardSnapshot,
    ClockSample,
    ConnectionChanged,
    ConnectionState,
    Heartbeat,
    LogEntry,
    LogLevel,
    NodeStatus,
    NodeStatusBatch,
    NodeStatusUpdate,
    ObjectivesChanged,
    ReloadNotice,
    RuntimeConnection,
    RuntimeEvent,
    TaskPlanning,
    UserInputRequested,
)
from kinema.tui.messages import (
    KeyDelivered,
    ModeSelected,
    RuntimeCallFailed,
    RuntimeCallSucceeded,
    RuntimeEventsArrived,
)
from kinema.tui.repeat_limiter import RepeatLimiter, held_back, watchdog_kind
from kinema.tui.run_outcome import RunOutcome, parse_outcome
from kinema.tui.runtime_status import ACTIVE_STATUSES, RuntimeStatus
from kinema.tui.screens.base import KinemaScreen, RuntimeView
from kinema.tui.stylesheet import OnceParsedStylesheet
from kinema.tui.widgets.nav_bar import SCREENS

log = logging.getLogger("kinema.tui")

# The app's screens (modes): module in kinema.tui.screens and class, imported when first shown.
SCREEN_CLASSES = {
    "configs": ("configs", "ConfigsScreen"),
    "objectives": ("objectives", "ObjectivesScreen"),
    "blackboard": ("blackboard", "BlackboardScreen"),
    "behaviors": ("behaviors", "BehaviorsScreen"),
    "logs": ("logs", "LogsScreen"),
    "waypoints": ("waypoints", "WaypointsScreen"),
}


def screen_class(mode: str) -> type[Screen[None]]:
    """The class of the screen for ``mode`` (a key of :data:`SCREEN_CLASSES`), its module imported now."""
    import importlib

    module, name = SCREEN_CLASSES[mode]
    cls: type[Screen[None]] = getattr(importlib.import_module(f"kinema.tui.screens.{module}"), name)
    return cls


def _new_screen(mode: str) -> Screen[None]:
    return screen_class(mode)()


MAX_LOGS = 2000
# Seconds the app waits for a key to go all the way up before it gives out the next one anyway.
KEY_WAIT_S = 1.0
MAX_RELOADS = 200
TOAST_SEVERITY = {LogLevel.ERROR: "error", LogLevel.WARN: "warning"}
# The uid of a tree's root node (BT.CPP numbers the nodes from 1, the root first).
ROOT_UID = 1


@dataclass
class EventInbox:
    """Events from the connection's threads, waiting for the UI thread. Thread-safe."""

    lock: threading.Lock = field(default_factory=threading.Lock)
    ordered: list[RuntimeEvent] = field(default_factory=list)
    heartbeat: Heartbeat | None = None
    heartbeat_key: tuple[str, str] = ("", "")
    clock: ClockSample | None = None
    blackboard: BlackboardSnapshot | None = None
    task_planning: TaskPlanning | None = None
    signalled: bool = False

    def put(self, event: RuntimeEvent) -> bool:
        """Queue ``event``; returns True when the UI thread must be woken (the inbox was idle)."""
        with self.lock:
            if isinstance(event, Heartbeat):
                # A heartbeat that changes the status or objective is ordered with the node statuses
                # around it (a new run resets the tree before its first statuses); the rest coalesce.
                key = (event.objective_name, event.status)
                if key != self.heartbeat_key:
                    self.heartbeat_key = key
                    self.ordered.append(event)
                    self.heartbeat = None
                else:
                    self.heartbeat = event
            elif isinstance(event, ClockSample):
                self.clock = event
            elif isinstance(event, BlackboardSnapshot):
                self.blackboard = event
            elif isinstance(event, TaskPlanning):
                self.task_planning = event
            else:
                self.ordered.append(event)
            wake = not self.signalled
            self.signalled = True
            return wake

    def drain(self) -> list[RuntimeEvent]:
        """Take everything queued, in order, with the newest heartbeat/clock/blackboard/task last."""
        with self.lock:
            events: list[RuntimeEvent] = self.ordered
            self.ordered = []
            for latest in (self.heartbeat, self.clock, self.blackboard, self.task_planning):
                if latest is not None:
                    events.append(latest)
            self.heartbeat = self.clock = self.blackboard = self.task_planning = None
            self.signalled = False
            return events


class KinemaApp(App[None]):
    """The Kinema TUI.

    Args:
        connection: the runtime to show (an :class:`~kinema.tui.sdk_connection.SdkConnection`, or a
            :class:`~kinema.tui.fake_connection.FakeConnection` in tests).
        owns_runtime: True when this app was opened by ``kinema run`` (closing it stops the runtime).
        initial_mode: the screen to open first.
    """

    TITLE = "Kinema"
    # Screens lay out differently in a narrow (80 columns) or short (24 lines) terminal: app.tcss.
    HORIZONTAL_BREAKPOINTS = [(0, "-narrow"), (100, "-normal")]
    VERTICAL_BREAKPOINTS = [(0, "-short"), (32, "-tall")]
    # Absolute, so subclasses defined elsewhere (tests, embedding apps) find the stylesheet too.
    CSS_PATH = Path(__file__).with_name("app.tcss")
    # Each screen's module is imported when the screen is first shown: the first frame needs only one.
    MODES = {mode: partial(_new_screen, mode) for mode in SCREEN_CLASSES}
    BINDINGS = [
        *(
            Binding(
                key,
                f"switch_mode('{mode}')",
                label,
                show=False,
                id=f"app.{mode}",
                tooltip=f"Show the {label} screen",
            )
            for mode, label, key in SCREENS
        ),
        Binding(
            "7",
            "show_camera",
            "Camera",
            show=False,
            id="app.camera",
            tooltip="Show the latest image of a camera topic",
        ),
        Binding("ctrl+q", "quit", "Quit", id="app.quit", tooltip="Close the app", priority=True),
        # q too, where no text is typed (on the objective list, letters search).
        Binding("q", "quit", "Quit", id="app.quit_q", show=False, tooltip="Close the app"),
        Binding(
            "ctrl+x",
            "cancel_objective",
            "Cancel",
            id="app.cancel",
            tooltip="Cancel the running objective from any screen",
            # Before any focused widget's own ctrl+x (a text field's "cut"): stopping the robot must work
            # wherever the cursor is.
            priority=True,
        ),
    ]

    def __init__(
        self,
        connection: RuntimeConnection,
        *,
        owns_runtime: bool = False,
        initial_mode: str = "objectives",
        camera: str | None = None,
    ) -> None:
        if initial_mode not in SCREEN_CLASSES:
            raise ValueError(f"no screen {initial_mode!r}; the screens are {', '.join(SCREEN_CLASSES)}")
        # The first screen is the app's default mode, composed when the app is: switching to it from
        # Textual's blank default screen restyled every widget of it twice more before the first frame.
        # Textual's App.__init__ reads the mode through the instance, so each app can start on its own.
        self.DEFAULT_MODE = initial_mode  # type: ignore[misc]
        super().__init__()
        self.camera_topic = camera
        # True while a teleoperation session (DoTeleoperateAction) is open in a dialog.
        self.teleoperating = False
        # True while the "Close Kinema?" question is open.
        self._asking_to_quit = False
        self.connection = connection
        self.owns_runtime = owns_runtime
        self.initial_mode = initial_mode
        self.status = RuntimeStatus(endpoint=connection.endpoint)
        self.blackboard = BlackboardModel()
        self.logs: deque[LogEntry] = deque(maxlen=MAX_LOGS)
        self.reloads: deque[ReloadNotice] = deque(maxlen=MAX_RELOADS)
        self.node_statuses: dict[str, dict[tuple[int, str], NodeStatusUpdate]] = {}
        # The last run of each objective that failed or was cancelled, until it runs again.
        self.outcomes: dict[str, RunOutcome] = {}
        # The task PlanMTCTask plans (or planned last) in the current run; None before one.
        self.task_planning: TaskPlanning | None = None
        # A run's start comes twice, on two topics in either order: its heartbeat, and its root leaving
        # IDLE in the node statuses. The first resets the per-run views; these say which one came first.
        self._started_by_heartbeat: set[str] = set()
        self._started_by_statuses: set[str] = set()
        # Objectives whose outcome (a log message, a third topic) came before the heartbeat reported the
        # run's end, with the heartbeat's (objective, status) then: a start signal that arrives before the
        # heartbeat moves on to another resting status is that ended run's, late, and must not wipe the
        # explanation the outcome put on the tree.
        self._ended_ahead: dict[str, tuple[str, str]] = {}
        self.inbox = EventInbox()
        self.repeats = RepeatLimiter()
        # Keys taken from the terminal and not yet given out (see on_event).
        self._pending_keys: deque[events.Key] = deque()
        self._key_in_flight = False
        self._switching = False
        self._key_timer: Timer | None = None
        self.views: list[RuntimeView] = []
        self._connection_open = False
        self._closing = False
        self.sub_title = connection.endpoint + ("  (closing stops the runtime)" if owns_runtime else "")
        # Nothing is read into the stylesheet yet: the sources are read when the app runs.
        self.stylesheet = OnceParsedStylesheet(variables=self.get_css_variables())

    def _run_started(self, name: str) -> None:
        """A new run of objective ``name``: forget the last one's statuses and outcome, reset the views."""
        self.node_statuses.pop(name, None)
        self.outcomes.pop(name, None)
        self.task_planning = None
        self._views_call(lambda view: view.runtime_run_started(name))

    # -- lifecycle ----------------------------------------------------------------------------------

    def on_mount(self) -> None:
        # Joining the runtime imports the transport (zenoh, numpy) on the connection's thread; begun
        # after the first frame, it does not hold the interpreter while the screen is being drawn.
        self.call_after_refresh(self._open_connection)
        if self.camera_topic:
            self.action_show_camera(self.camera_topic)
        self.call_after_refresh(startup_gc.settle)

    def _open_connection(self) -> None:
        if not self._closing:
            self.connection.open(self._receive)
            self._connection_open = True

    def on_unmount(self) -> None:
        self._closing = True
        if not self._connection_open:
            return
        try:
            self.connection.close()
        except Exception:
            log.exception("closing the runtime connection failed")

    def register_view(self, screen: RuntimeView) -> None:
        """A screen was mounted; it receives runtime updates from now on."""
        if screen not in self.views:
            self.views.append(screen)

    def unregister_view(self, screen: RuntimeView) -> None:
        """A screen was unmounted."""
        if screen in self.views:
            self.views.remove(screen)

    # -- runtime events -----------------------------------------------------------------------------

    def _receive(self, event: RuntimeEvent) -> None:
        """The connection's listener (any thread): queue, and wake the UI thread once."""
        if self.inbox.put(event):
            self.post_message(RuntimeEventsArrived())

    def on_runtime_events_arrived(self, _: RuntimeEventsArrived) -> None:
        self.process_events(self.inbox.drain())

    def process_events(self, events: Iterable[RuntimeEvent]) -> None:
        """Apply events to the app's state and hand them down to the screens (UI thread)."""
        status_changed = False
        for event in events:
            if isinstance(event, ConnectionChanged):
                was = self.status.state
                self.status.apply_connection(event)
                status_changed = True
                if event.state is ConnectionState.CONNECTED and was is not ConnectionState.CONNECTED:
                    self._views_call(lambda view: view.runtime_connected())
                if event.state is ConnectionState.DISCONNECTED and was is ConnectionState.CONNECTED:
                    self._connection_message(
                        f"Lost the runtime at {event.endpoint}: {plain_detail(event.detail)}. The app "
                        "reconnects by itself; if it does not, check that `kinema run` still runs.",
                        "Disconnected",
                        LogLevel.WARN,
                    )
                elif event.state is ConnectionState.CONNECTED and was is ConnectionState.DISCONNECTED:
                    self._connection_message(
                        f"Connected again to the runtime at {event.endpoint}.", "Reconnected", LogLevel.INFO
                    )
            elif isinstance(event, Heartbeat):
                was_connected = self.status.state is ConnectionState.CONNECTED
                started = self.status.apply_heartbeat(event)
                ahead = self._ended_ahead.get(event.objective_name)
                if (
                    ahead is not None
                    and event.status not in ACTIVE_STATUSES
                    and ahead != (event.objective_name, event.status)
                ):
                    del self._ended_ahead[event.objective_name]  # the heartbeat caught up with the end
                if started and event.objective_name in self._ended_ahead:
                    # The ended run's own start, late (see _ended_ahead). If its statuses started it,
                    # that note is used up: the next start on the heartbeat is a new run's.
                    self._started_by_statuses.discard(event.objective_name)
                elif started:
                    if event.objective_name in self._started_by_statuses:
                        # Its statuses came first (a busy machine reorders topics): already reset.
                        self._started_by_statuses.discard(event.objective_name)
                    else:
                        self._started_by_heartbeat.add(event.objective_name)
                        self._run_started(event.objective_name)
                if not was_connected:
                    self._views_call(lambda view: view.runtime_connected())
                status_changed = True
            elif isinstance(event, ClockSample):
                self.status.apply_clock(event)
                status_changed = True
            elif isinstance(event, NodeStatusBatch):
                name = event.objective_name
                if any(u.uid == ROOT_UID and u.previous is NodeStatus.IDLE for u in event.updates):
                    if name in self._ended_ahead or (
                        name in self.outcomes
                        and self.outcomes[name].outcome == "Failure"
                        and any(u.uid == ROOT_UID and u.status is NodeStatus.FAILURE for u in event.updates)
                    ):
                        # The failed run whose outcome is shown, arriving late (before the heartbeat said
                        # it ended, or whole in one batch): apply it, keep the explanation. A new run that
                        # fails within one batch sends its own outcome next, which explains it again.
                        pass
                    elif name in self._started_by_heartbeat:
                        self._started_by_heartbeat.discard(name)
                    else:
                        self._started_by_statuses.add(name)
                        self._run_started(name)
                latest = self.node_statuses.setdefault(event.objective_name, {})
                for update in event.updates:
                    latest[(update.uid, update.node_path)] = update
                self._views_call(lambda view: view.runtime_node_statuses(event))  # noqa: B023 - called now
            elif isinstance(event, BlackboardSnapshot):
                diff = self.blackboard.apply(event.objective_name, event.stamp, event.entries)
                if diff:
                    self._views_call(lambda view: view.runtime_blackboard(diff))  # noqa: B023 - called now
            elif isinstance(event, LogEntry):
                self.add_log(event, toast=True)
            elif isinstance(event, ReloadNotice):
                self.reloads.append(event)
                self._views_call(lambda view: view.runtime_reload(event))  # noqa: B023 - called now
                if not event.ok:
                    where = f"{event.location}: " if event.location else ""
                    self.notify(f"{where}{event.message}", title="Reload failed", severity="error", timeout=8)
            elif isinstance(event, ObjectivesChanged):
                self._views_call(lambda view: view.runtime_objectives_changed())
            elif isinstance(event, ApprovalRequested):
                self.ask_approval(event)
            elif isinstance(event, UserInputRequested):
                self.ask_user_input(event)
            elif isinstance(event, TaskPlanning):
                self.task_planning = event
                self._views_call(lambda view: view.runtime_task_planning(event))  # noqa: B023 - called now
        if status_changed:
            for view in self.views:
                view.show_status(self.status)

    def ask_approval(self, request: ApprovalRequested) -> None:
        """Show a behavior's question (approve a motion, resume a breakpoint); the answer goes back to it.

        A question about a planned motion lists its steps (stage, duration, joints, gripper changes).
        """

        def answered(approved: bool | None) -> None:
            request.answer(bool(approved), "" if approved else "declined in the TUI")

        question = f"{request.prompt}\n({request.behavior} at {request.node_path})"
        if request.steps:
            from kinema.tui.dialogs.approval import ApprovalDialog

            self.push_screen(ApprovalDialog(question, request.steps, request.duration), answered)
            return
        from kinema.tui.dialogs.confirm import MotionQuestionDialog  # dialogs load when first shown

        self.push_screen(MotionQuestionDialog(question), answered)

    def ask_user_input(self, request: UserInputRequested) -> None:
        """Ask the user for what a behavior needs (a pose, joint values, points on an image, a teleoperation
        session); the answer goes back to it. A pose or joint values the user declines during teleoperation
        also end the "move to" mode, so the objective does not ask again at once."""
        from kinema.tui.connection import TELEOP_NONE, UserInputAnswer
        from kinema.tui.dialogs.user_input import (
            JointStateDialog,
            PointsDialog,
            PoseDialog,
            TeleoperateDialog,
        )

        def answered(answer: UserInputAnswer | None) -> None:
            answer = answer or UserInputAnswer(False, "cancelled in the TUI")
            request.answer(answer)
            if request.kind == "teleoperate":
                self.teleoperating = False
            elif request.kind in ("pose", "joint_state") and not answer.accepted and self.teleoperating:
                self.pick_teleoperation_mode(TELEOP_NONE)

        if request.kind == "pose":
            self.push_screen(PoseDialog(request), answered)
        elif request.kind == "joint_state":
            self.push_screen(JointStateDialog(request), answered)
        elif request.kind == "points":
            from kinema.tui.screens.camera import image_widget_class

            try:
                widget_class = image_widget_class()
            except ValueError as error:  # a bad KINEMA_TUI_IMAGE: typed points still work
                self.notify(str(error), severity="warning")
                widget_class = None
            self.push_screen(PointsDialog(request, self.connection.watch_images, widget_class), answered)
        elif request.kind == "teleoperate":
            self.teleoperating = True
            self.push_screen(TeleoperateDialog(request, self.pick_teleoperation_mode), answered)
        else:
            request.answer(UserInputAnswer(False, f"this TUI cannot answer a {request.kind!r} question"))

    def pick_teleoperation_mode(self, mode: int) -> None:
        """Tell the running teleoperation session the mode the user picked (off the UI thread)."""

        def send() -> None:
            try:
                self.connection.set_teleoperation_mode(mode)
            except Exception as error:  # shown, never raised: the runtime may be gone
                self.call_from_thread(self.notify, str(error), title="Teleoperation", severity="error")

        self.run_worker(send, thread=True, group="teleoperation-mode")

    def _connection_message(self, text: str, title: str, level: LogLevel) -> None:
        """A lost or found connection: a toast and a log line, at most one of each kind per period."""
        held = self.repeats.admit(f"connection {title}", time.monotonic())
        if held is None:
            return
        text += held_back(held)
        self.add_log(LogEntry(f"{title}: {text}", level, time.time(), "ui"))
        self.notify(text, title=title, severity="error" if level <= LogLevel.WARN else "information")

    def add_log(self, entry: LogEntry, *, toast: bool = False) -> None:
        """Keep ``entry`` for the Logs screen and, for runtime toasts, show it as a notification.

        A watchdog warning is kept and shown once per kind and period (it repeats under load)."""
        kind = watchdog_kind(entry.message)
        if kind is not None:
            held = self.repeats.admit(kind, time.monotonic())
            if held is None:
                return
            message = entry.message.removeprefix("watchdog: ")
            entry = LogEntry(
                message[:1].upper() + message[1:] + held_back(held), entry.level, entry.stamp, "watchdog"
            )
        self.logs.append(entry)
        outcome = parse_outcome(entry.message) if entry.level <= LogLevel.WARN else None
        if outcome is not None:
            self.outcomes[outcome.objective_name] = outcome
            beat = (self.status.objective, self.status.status)
            if beat != (outcome.objective_name, outcome.outcome):
                self._ended_ahead[outcome.objective_name] = beat
        self._views_call(lambda view: view.runtime_log(entry))
        if outcome is not None:
            self._views_call(lambda view: view.runtime_run_ended(outcome))
        if toast and entry.level <= LogLevel.INFO:
            self.notify(entry.message, severity=TOAST_SEVERITY.get(entry.level, "information"))  # type: ignore[arg-type]

    def _views_call(self, hook: object) -> None:
        for view in list(self.views):
            try:
                hook(view)  # type: ignore[operator]
            except Exception as error:
                log.exception("a screen failed to take a runtime update")
                self.logs.append(
                    LogEntry(f"{type(view).__name__}: {error}", LogLevel.ERROR, time.time(), "ui")
                )

    def notify(
        self,
        message: str,
        *,
        title: str = "",
        severity: SeverityLevel = "information",
        timeout: float | None = None,
        markup: bool = False,
    ) -> None:
        """Show a toast. Markup is off by default: runtime messages contain ``[node/path]`` and file names."""
        super().notify(message, title=title, severity=severity, timeout=timeout, markup=markup)

    # -- messages from screens ----------------------------------------------------------------------

    def on_runtime_call_failed(self, message: RuntimeCallFailed) -> None:
        self.add_log(LogEntry(f"{message.what} failed: {message.error}", LogLevel.ERROR, time.time(), "ui"))
        self.notify(message.error, title=f"{message.what} failed", severity="error", timeout=8)

    def on_runtime_call_succeeded(self, message: RuntimeCallSucceeded) -> None:
        self.add_log(LogEntry(message.what, LogLevel.INFO, time.time(), "ui"))
        self.notify(message.what, timeout=3)

    def on_mode_selected(self, message: ModeSelected) -> None:
        self.run_worker(self.action_switch_mode(message.mode), group="switch-mode")

    # -- one key at a time ------------------------------------------------------------------------------

    # Textual hands a key to whatever has the focus when it takes the key from the terminal, and the key's
    # bindings run later, when it has bubbled up. Keys typed in a burst (a busy machine, a fast typist)
    # were all handed to the widget focused before the first of them ran: the letters typed after "/"
    # went to the table instead of the filter it focuses, those after "3" to the screen being left. So
    # the app gives out the next key only once the last one has gone all the way up (a KeyDelivered
    # message sent behind it, along the same path), or its screen switch is done.

    async def on_event(self, event: events.Event) -> None:
        if isinstance(event, events.Key) and not event.is_forwarded:
            self._pending_keys.append(event)
            await self._next_key()
            return
        await super().on_event(event)

    async def _next_key(self) -> None:
        if self._key_in_flight or self._switching or not self._pending_keys:
            return
        key = self._pending_keys.popleft()
        target = self.focused or self.screen
        self._key_in_flight = True
        await super().on_event(key)
        if self._switching:  # a priority binding switched screens: the switch releases the keys
            self._key_in_flight = False
            return
        target.post_message(KeyDelivered())
        # A key whose widget went away (a dialog it closed) never sends its KeyDelivered up.
        self._key_timer = self.set_timer(KEY_WAIT_S, self._key_came_back)

    async def on_key_delivered(self, message: KeyDelivered) -> None:
        message.stop()
        await self._key_came_back()

    async def _key_came_back(self) -> None:
        if self._key_timer is not None:
            self._key_timer.stop()
            self._key_timer = None
        self._key_in_flight = False
        await self._next_key()

    async def action_switch_mode(self, mode: str) -> None:
        """Show screen ``mode``; the keys typed meanwhile go to it once it is up."""
        self._switching = True
        try:
            await self.switch_mode(mode)
        finally:
            self.call_after_refresh(self._switched)

    async def _switched(self) -> None:
        self._switching = False
        self._key_in_flight = False
        await self._next_key()

    # -- actions and commands -----------------------------------------------------------------------

    async def action_quit(self) -> None:
        """Close the app; when it owns the runtime (``kinema run``), ask first, since that stops it."""
        if not self.owns_runtime:
            self.exit()
            return

        from kinema.tui.dialogs.confirm import ConfirmDialog

        if self._asking_to_quit:
            return  # already asking: a second ctrl+q must not stack another question
        self._asking_to_quit = True

        def answered(stop: bool | None) -> None:
            self._asking_to_quit = False
            if stop:
                self.exit()

        self.push_screen(
            ConfirmDialog(
                "Close Kinema? This stops the runtime that `kinema run` started.", "Quit and stop", "Stay"
            ),
            answered,
        )

    def action_cancel_objective(self) -> None:
        screen = self.screen
        if isinstance(screen, KinemaScreen):
            screen.call_runtime("Cancel the objective", self.connection.cancel_objective, announce=True)

    def action_replay_latest(self) -> None:
        """Open the newest recording (of a runtime on this machine) in the replay screen."""
        from kinema.errors import KinemaError
        from kinema.runtime.recordings import latest_recording
        from kinema.tui.screens.replay import ReplayScreen, load_recording

        def load() -> None:  # reading a recording takes a while: not on the UI thread
            try:
                path = latest_recording()
                loaded = load_recording(path)
            except KinemaError as error:
                self.call_from_thread(
                    self.notify, str(error), title="Nothing to replay", severity="warning", timeout=8
                )
                return

            def show() -> None:
                self.push_screen(ReplayScreen(path, loaded))

            self.call_from_thread(show)

        self.run_worker(load, thread=True, group="replay")

    def action_show_camera(self, topic: str | None = None) -> None:
        """Open the camera view (on ``topic``, else the last one shown)."""
        from kinema.tui.screens.camera import CameraScreen, image_support_loaded, load_image_support

        if isinstance(self.screen, CameraScreen):
            return
        if not image_support_loaded():
            # textual-image asks the terminal what it can draw, and the answers come on the input the app
            # reads: ask with the terminal handed back for a moment (once, on the first camera view).
            try:
                with self.suspend():
                    load_image_support()
            except SuspendNotSupported:  # headless (tests) or a web driver: nothing to ask
                load_image_support()
        try:
            self.push_screen(CameraScreen(topic or self.camera_topic))
        except ValueError as error:  # KINEMA_TUI_IMAGE names no drawing method
            self.notify(str(error), title="Cannot show images", severity="error", timeout=8)

    def get_system_commands(self, screen: Screen[object]) -> Iterable[SystemCommand]:
        yield from super().get_system_commands(screen)
        for mode, label, key in SCREENS:
            yield SystemCommand(
                f"Go to {label}",
                f"Show the {label} screen (key {key})",
                lambda mode=mode: self.switch_mode(mode),
            )  # type: ignore[misc]
        yield SystemCommand(
            "Cancel objective", "Cancel the running objective (ctrl+x)", self.action_cancel_objective
        )
        yield SystemCommand(
            "Show a camera image",
            "The latest picture of an image topic, e.g. /wrist_camera/color (key 7)",
            self.action_show_camera,
        )
        yield SystemCommand(
            "Replay the latest recording",
            "Step through the newest recorded run of this machine (`kinema ui --replay FILE` for another)",
            self.action_replay_latest,
        )
        from kinema.tui.screens.objectives import ObjectivesScreen
        from kinema.tui.screens.waypoints import WaypointsScreen

        for view in self.views:
            if isinstance(view, ObjectivesScreen):
                for objective in view.objectives:
                    if objective.runnable:
                        yield SystemCommand(
                            f"Run {objective.name}",
                            objective.description or "Run this objective with its default parameters",
                            partial(view.run_by_name, objective.name),
                        )
            elif isinstance(view, WaypointsScreen):
                for waypoint in view.waypoints:
                    yield SystemCommand(
                        f"Move to waypoint {waypoint.name}",
                        waypoint.description or "Move the robot to this saved waypoint",
                        partial(view.move_to, waypoint.name),
                    )


def plain_detail(detail: str) -> str:
    """Why the connection was lost, in words: the heartbeat timeout says what it means."""
    if detail.startswith("no heartbeat from the runtime for "):
        seconds = detail.removeprefix("no heartbeat from the runtime for ").split(" ", 1)[0]
        return f"no sign of life from it for {seconds} s (it stopped, or the machine is very busy)"
    return detail or "it stopped answering"


def run_app(
    connection: RuntimeConnection,
    owns_runtime: bool = False,
    initial_mode: str = "objectives",
    camera: str | None = None,
) -> None:
    """Open the TUI on ``connection`` and return when the user closes it.

    Args:
        connection: the runtime to attach to.
        owns_runtime: True for ``kinema run``: the caller stops the runtime after this returns; the app
            says so in its title. An attached app (``kinema ui``) leaves the runtime running.
        initial_mode: the first screen (``configs``, ``objectives``, ``blackboard``, ``behaviors``,
            ``logs``, ``waypoints``).
        camera: an image topic to show in the camera view on top of it.
    """
    if camera:
        # The camera view's image library asks the terminal what it can draw; with a camera on the first
        # screen that must happen before the app takes the terminal over (else on the first camera view).
        from kinema.tui.screens.camera import load_image_support

        load_image_support()
    try:
        KinemaApp(connection, owns_runtime=owns_runtime, initial_mode=initial_mode, camera=camera).run()
    finally:
        startup_gc.release()  # in case the app closed before its first frame
