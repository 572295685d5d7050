"""Logs: the runtime's log messages and behavior toasts (and the app's own errors), with a level filter."""

from __future__ import annotations

import time

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.widgets import RichLog, Select, Static

from kinema.tui.connection import LogEntry, LogLevel
from kinema.tui.screens.base import KinemaScreen

LEVEL_STYLE = {
    LogLevel.ERROR: ("ERROR", "bold red"),
    LogLevel.WARN: ("WARN ", "yellow"),
    LogLevel.INFO: ("INFO ", "cyan"),
    LogLevel.DEBUG: ("DEBUG", "dim"),
}
LEVEL_CHOICES = [
    ("Errors only", int(LogLevel.ERROR)),
    ("Warnings and up", int(LogLevel.WARN)),
    ("Info and up", int(LogLevel.INFO)),
    ("Everything", int(LogLevel.DEBUG)),
]


def format_log(entry: LogEntry) -> Text:
    """One log line: time, level, source, message."""
    label, style = LEVEL_STYLE.get(entry.level, ("?    ", ""))
    text = Text()
    if entry.stamp:
        text.append(time.strftime("%H:%M:%S ", time.localtime(entry.stamp)), style="dim")
    text.append(label, style=style)
    if entry.source:
        text.append(f" [{entry.source}]", style="dim")
    text.append(f" {entry.message}")
    return text


class LogsScreen(KinemaScreen):
    """The log panel."""

    MODE = "logs"
    AUTO_FOCUS = "#log-panel"
    BINDINGS = [
        Binding("l", "cycle_level", "Level", id="logs.level", tooltip="Cycle the minimum level shown"),
        Binding("ctrl+l", "clear", "Clear", id="logs.clear", tooltip="Clear the log panel"),
        Binding("e", "level(1)", "Errors", id="logs.errors", tooltip="Show errors only", show=False),
        Binding("a", "level(4)", "All", id="logs.all", tooltip="Show every message", show=False),
    ]

    def __init__(self) -> None:
        super().__init__()
        self.level = int(LogLevel.INFO)

    def compose_body(self) -> ComposeResult:
        with Vertical(classes="main"):
            with Horizontal(classes="toolbar"):
                yield Select(LEVEL_CHOICES, value=self.level, allow_blank=False, id="log-level")
                yield Static("", id="log-count", classes="muted")
            # min_width: RichLog renders every line at least 78 cells wide by default, wider than the
            # panel in an 80-column terminal, which hid the end of each wrapped line.
            yield RichLog(id="log-panel", wrap=True, max_lines=5000, min_width=20)

    def on_mount(self) -> None:
        super().on_mount()
        self._rewrite()
        self.set_focus(self.query_one(RichLog))

    def on_select_changed(self, event: Select.Changed) -> None:
        if isinstance(event.value, int) and event.value != self.level:
            self.level = event.value
            self._rewrite()

    def action_cycle_level(self) -> None:
        values = [value for _, value in LEVEL_CHOICES]
        self.action_level(values[(values.index(self.level) + 1) % len(values)])

    def action_level(self, level: int) -> None:
        self.query_one("#log-level", Select).value = level

    def action_clear(self) -> None:
        self.kinema.logs.clear()
        self._rewrite()

    def runtime_log(self, entry: LogEntry) -> None:
        if entry.level <= self.level:
            self.query_one(RichLog).write(format_log(entry))
            self._count()

    def _rewrite(self) -> None:
        panel = self.query_one(RichLog)
        panel.clear()
        for entry in self.kinema.logs:
            if entry.level <= self.level:
                panel.write(format_log(entry))
        self._count()

    def _count(self) -> None:
        shown = sum(1 for entry in self.kinema.logs if entry.level <= self.level)
        self.query_one("#log-count", Static).update(f"{shown} of {len(self.kinema.logs)} messages")
