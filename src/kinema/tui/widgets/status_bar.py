"""The bottom status line: connection, the heartbeat (objective, status, elapsed) and sim time."""

from __future__ import annotations

import re

from rich.text import Text
from textual.widgets import Static

from kinema.tui.connection import ConnectionState
from kinema.tui.runtime_status import RuntimeStatus

_STATE_STYLE = {
    ConnectionState.CONNECTED: ("●", "green"),
    ConnectionState.CONNECTING: ("◌", "yellow"),
    ConnectionState.DISCONNECTED: ("○", "red"),
}
STATUS_STYLE = {
    "Running": "bold yellow",
    "Loading": "yellow",
    "Success": "bold green",
    "Failure": "bold red",
    "Cancelled": "magenta",
    "Idle": "dim",
    "Unknown": "dim",
}


class StatusBar(Static):
    """Shows a :class:`RuntimeStatus`; the app sets it with :meth:`show` (attributes down)."""

    DEFAULT_CSS = """
    StatusBar { height: 1; background: $panel; color: $text; padding: 0 1; }
    """

    _shown: tuple[object, ...] = ()

    def show(self, status: RuntimeStatus) -> None:
        """Render ``status`` (heartbeats come 10 times a second; only a visible change repaints)."""
        key = (
            status.state,
            status.endpoint,
            status.detail,
            status.objective,
            status.status,
            None if status.elapsed is None else round(status.elapsed, 1),
            None if status.sim_time is None else round(status.sim_time, 2),
            None if status.real_time_factor is None else round(status.real_time_factor, 2),
            # The watchdog's seconds grow every beat; whole seconds are enough on screen.
            tuple(_whole_seconds(warning) for warning in status.warnings),
            status.last_outcome,
            self.size.width,
        )
        if key != self._shown:
            self._shown = key
            # The bar's padding takes a column each side.
            self.update(render_status(status, self.size.width - 2 if self.size.width > 2 else None))

    def on_resize(self) -> None:
        self._shown = ()  # the endpoint fits again, or no longer


def render_status(status: RuntimeStatus, width: int | None = None) -> Text:
    """The status line as rich text (also used by tests to check wording). With ``width``, what does not
    fit is left out whole, least needed first (a connected runtime's endpoint, the real-time factor, the
    sim time), rather than cut at the edge: the run's objective, status and time come first."""
    line = _render(status, with_endpoint=True)
    if width is None or status.state is not ConnectionState.CONNECTED:
        return line
    # What goes first when the line is too long: the endpoint, then the real-time factor, then sim time.
    for endpoint, factor, clock in ((False, True, True), (False, False, True), (False, False, False)):
        if line.cell_len <= width:
            break
        line = _render(status, with_endpoint=endpoint, with_factor=factor, with_clock=clock)
    return line


def _render(
    status: RuntimeStatus, *, with_endpoint: bool, with_factor: bool = True, with_clock: bool = True
) -> Text:
    symbol, colour = _STATE_STYLE[status.state]
    text = Text()
    text.append(f"{symbol} {status.state.value}", style=f"bold {colour}")
    if status.endpoint and with_endpoint:
        text.append(f" {status.endpoint}", style="dim")
    if status.state is ConnectionState.DISCONNECTED:
        if status.detail:
            text.append(f" — {_short_detail(status.detail)}", style="red")
        return text
    text.append("  │  ")
    if status.objective:
        text.append(status.objective, style="bold")
        text.append(" ")
    if status.status == "Idle" and status.last_outcome and status.objective:
        # The server says Idle a couple of seconds after a run ends: how it ended stays on the line.
        text.append(status.last_outcome, style=STATUS_STYLE.get(status.last_outcome, ""))
    else:
        text.append(status.status, style=STATUS_STYLE.get(status.status, ""))
    if status.elapsed is not None and status.objective:
        text.append(f" {status.elapsed:.1f} s")
    if status.status == "Idle" and status.last_outcome and status.objective:
        text.append(" · idle", style="dim")
    if status.sim_time is not None and with_clock:
        text.append("  │  sim ")
        text.append(f"{status.sim_time:.2f} s")
        if status.real_time_factor is not None and with_factor:
            text.append(f"  RTF {status.real_time_factor:.2f}x")
    if status.warnings:
        # The watchdog: a behavior stuck in tick is the first thing a user must see.
        text.append("  │  ")
        text.append(f"⚠ {_whole_seconds(status.warnings[0])}", style="bold red")
        if len(status.warnings) > 1:
            text.append(f" (+{len(status.warnings) - 1} more)", style="red")
    return text


def _whole_seconds(warning: str) -> str:
    """``... for 3.4 s`` as ``... for 3 s``."""
    return re.sub(r"(\d+)\.\d s\b", r"\1 s", warning)


def _short_detail(detail: str) -> str:
    """Why the connection is down, short enough for one line at 80 columns: the endpoint is shown before
    it already, and "no Kinema router answers at <endpoint> (start one with ...)" lost its advice."""
    if detail.startswith("no Kinema router answers"):
        return "none answers: `kinema run` starts one"
    return detail
