"""What every screen of the app shares: the navigation tabs, the status bar, the footer, runtime calls."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from textual import events, on
from textual.app import App, ComposeResult
from textual.message import Message
from textual.screen import Screen

from kinema.errors import KinemaError
from kinema.tui.messages import RuntimeCallFailed, RuntimeCallSucceeded
from kinema.tui.widgets.key_footer import KeyFooter
from kinema.tui.widgets.nav_bar import NavBar
from kinema.tui.widgets.status_bar import StatusBar

if TYPE_CHECKING:
    from kinema.tui.app import KinemaApp
    from kinema.tui.blackboard_model import BlackboardDiff
    from kinema.tui.connection import LogEntry, NodeStatusBatch, ReloadNotice, TaskPlanning
    from kinema.tui.run_outcome import RunOutcome
    from kinema.tui.runtime_status import RuntimeStatus

log = logging.getLogger("kinema.tui")

RETRY_PAUSE_S = 1.0
#: How often the screens try to list what they show before saying it failed.
LOAD_ATTEMPTS = 3


class RuntimeView:
    """What the app hands runtime updates to (``KinemaApp.register_view``): each hook does nothing here, and
    a screen overrides those it cares about."""

    def show_status(self, status: RuntimeStatus) -> None:
        """The runtime status changed."""

    def runtime_connected(self) -> None:
        """The runtime (re)appeared: reload what this screen shows."""

    def runtime_run_started(self, objective_name: str) -> None:
        """A new objective run started."""

    def runtime_node_statuses(self, batch: NodeStatusBatch) -> None:
        """Nodes of the running tree changed status."""

    def runtime_blackboard(self, diff: BlackboardDiff) -> None:
        """The blackboard changed (``diff`` against what the app had)."""

    def runtime_log(self, entry: LogEntry) -> None:
        """A log message or toast arrived."""

    def runtime_run_ended(self, outcome: RunOutcome) -> None:
        """An objective run failed or was cancelled (its message stays shown until dismissed)."""

    def runtime_task_planning(self, task: TaskPlanning) -> None:
        """A task is being planned (PlanMTCTask): its stages' states changed."""

    def runtime_reload(self, notice: ReloadNotice) -> None:
        """A hot reload happened."""

    def runtime_objectives_changed(self) -> None:
        """The objective library changed."""


class KinemaScreen(RuntimeView, Screen[None]):
    """A screen of the app. Subclasses set :attr:`MODE` and implement :meth:`compose_body`.

    The app calls the ``runtime_*`` hooks (attributes down); a screen overrides those it cares about.
    """

    MODE = ""

    def __init__(self) -> None:
        super().__init__()
        # Textual sets the size classes (-narrow, -tall, ...) on the first resize, after the widgets were
        # composed and styled, and then styles them all again; set up front, that resize changes nothing.
        self.add_class(*breakpoint_classes(self.app), update=False)
        self._resumed = False
        self._drawn = False

    @property
    def kinema(self) -> KinemaApp:
        """The app, typed."""
        return self.app  # type: ignore[return-value]

    def compose(self) -> ComposeResult:
        yield NavBar(self.MODE)
        yield from self.compose_body()
        yield StatusBar(id="status-bar")
        yield KeyFooter()

    def compose_body(self) -> ComposeResult:
        """The screen's own widgets."""
        yield from ()

    def on_mount(self) -> None:
        self.kinema.register_view(self)
        self.show_status(self.kinema.status)

    def on_unmount(self) -> None:
        self.kinema.unregister_view(self)

    @on(events.ScreenResume)
    def _first_resume(self, event: events.ScreenResume) -> None:
        # The first resume comes just after the screen was composed, every widget styled: Textual's
        # restyle of them all on resume would only repeat that work before the first frame.
        if not self._resumed:
            self._resumed = True
            event.refresh_styles = False

    def on_screen_resume(self) -> None:
        self.show_status(self.kinema.status)

    @on(events.Idle)
    def _draw_first_frame(self) -> None:
        # Textual draws a screen on the ticks of its 60 Hz update timer, which the screen resumes when it
        # goes idle with something to draw; resumed, the timer waits for its next tick. For the first frame
        # that was 17-19 ms of doing nothing once the app's start was over: it is drawn right away instead.
        if self._drawn or self.app._batch_count or not self.is_current:
            return
        self._drawn = True
        self._on_timer_update()

    @on(events.Resize)
    def _same_size(self, event: events.Resize) -> None:
        # Textual hands a new screen the terminal's size up to three times on the way to the first frame
        # (laid out on resume, then the app's first resize, then that resize again when the app is idle),
        # and lays every widget out and renders again each time. A resize to the size the screen was
        # laid out at changes nothing: Textual's own handler is skipped.
        if self.is_attached and self._compositor.size == event.size:
            event.stop()
            event.prevent_default()

    def show_status(self, status: RuntimeStatus) -> None:
        """Show the runtime status in this screen's status bar."""
        for bar in self.query(StatusBar):
            bar.show(status)

    # -- calling the runtime off the UI thread ---------------------------------------------------

    def call_runtime(
        self,
        what: str,
        call: Callable[[], Any],
        done: Callable[[Any], Message | None] | None = None,
        *,
        announce: bool = False,
        attempts: int = 1,
    ) -> None:
        """Run ``call`` on a worker thread; post ``done(result)`` back to this screen.

        A failure is posted to the app as :class:`RuntimeCallFailed` (shown, never raised), so a runtime
        that went away or refused the request never takes the app down.

        Args:
            what: what the user asked for, for messages ("Run 'Pick Object'").
            call: the blocking call.
            done: builds the message to post with the result, or None.
            announce: notify the user on success.
            attempts: how often to try a read-only call before reporting its failure (never retry a call
                that changes something).
        """

        def work() -> None:
            for attempt in range(1, attempts + 1):
                try:
                    result = call()
                    break
                except KinemaError as error:
                    if attempt < attempts:
                        time.sleep(RETRY_PAUSE_S)  # a runtime that just appeared may not serve yet
                        continue
                    self.app.post_message(RuntimeCallFailed(what, str(error)))
                    return
                except Exception as error:  # shown to the user; the app must survive
                    log.exception("%s failed", what)
                    self.app.post_message(RuntimeCallFailed(what, f"{type(error).__name__}: {error}"))
                    return
            if done is not None:
                message = done(result)
                if message is not None:
                    self.post_message(message)
            if announce:
                self.app.post_message(RuntimeCallSucceeded(what))

        self.run_worker(work, thread=True, group=what, name=what)


def breakpoint_classes(app: App[Any]) -> list[str]:
    """The size classes Textual gives a screen of ``app`` at the terminal's size (``HORIZONTAL_BREAKPOINTS``
    and ``VERTICAL_BREAKPOINTS``: for each, the class of the largest breakpoint the size reaches)."""
    width, height = app.size
    chosen = []
    for size, breakpoints in ((width, app.HORIZONTAL_BREAKPOINTS), (height, app.VERTICAL_BREAKPOINTS)):
        reached = [(at, name) for at, name in breakpoints or () if size >= at]
        if reached:
            chosen.append(max(reached)[1])
    return chosen
