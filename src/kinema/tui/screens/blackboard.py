"""Blackboard: a live table of every entry (subtree scopes included), a filter, and a key's recent history.

The app hands this screen a diff per snapshot; the screen merges diffs and applies them to the table at
most :data:`REFRESH_PERIOD_S` apart, and only while it is on screen, so a 10 Hz stream over 1,000 keys
costs the terminal a handful of cell updates per refresh instead of a rebuilt table.
"""

from __future__ import annotations

import time

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.widgets import DataTable, Input, Label, Static

from kinema.tui.blackboard_model import BlackboardDiff, RowKey
from kinema.tui.screens.base import KinemaScreen
from kinema.tui.widgets.blackboard_table import BlackboardTable

REFRESH_PERIOD_S = 0.2
# A pending diff touching more rows than this is cheaper to show by rebuilding the (filtered) table.
REBUILD_THRESHOLD = 2000


def format_stamp(stamp: float) -> str:
    """Wall-clock stamps as local ``HH:MM:SS.mmm``; small ones (sim time, tests) as seconds."""
    if stamp > 1e9:
        return time.strftime("%H:%M:%S", time.localtime(stamp)) + f".{int(stamp % 1 * 1000):03d}"
    return f"{stamp:.2f}"


class BlackboardScreen(KinemaScreen):
    """The live blackboard of the running (or last) objective."""

    MODE = "blackboard"
    AUTO_FOCUS = "#blackboard-table"
    BINDINGS = [
        Binding("slash", "filter", "Filter", id="blackboard.filter", tooltip="Filter keys, types and values"),
        Binding("escape", "clear_filter", "Clear filter", id="blackboard.clear", tooltip="Show every entry"),
        Binding("h", "focus_table", "Table", id="blackboard.table", tooltip="Back to the table"),
    ]

    def __init__(self) -> None:
        super().__init__()
        self.pending = BlackboardDiff()
        self.needs_rebuild = True
        self.history_key: RowKey | None = None

    def compose_body(self) -> ComposeResult:
        with Vertical(classes="main"):
            with Horizontal(classes="toolbar"):
                yield Input(placeholder="/ filter by key, scope, type or value", id="blackboard-filter")
                yield Static("", id="blackboard-summary", classes="muted")
            with Horizontal(classes="split", id="blackboard-split"):
                yield BlackboardTable(self.kinema.blackboard, id="blackboard-table")
                with Vertical(classes="side-panel"):
                    yield Label("History", classes="pane-title")
                    yield Static("", id="history-title")
                    yield DataTable(id="history-table", cursor_type="row", zebra_stripes=True)

    def on_mount(self) -> None:
        super().on_mount()
        history = self.query_one("#history-table", DataTable)
        history.add_column("Time", key="time", width=12)
        history.add_column("Value", key="value")
        self.set_interval(REFRESH_PERIOD_S, self.flush)
        self.set_focus(self.query_one(BlackboardTable))
        self.flush()

    def on_screen_resume(self) -> None:
        super().on_screen_resume()
        self.flush()

    def runtime_blackboard(self, diff: BlackboardDiff) -> None:
        if self.needs_rebuild:
            return  # the next flush shows the whole model anyway
        self.pending = self.pending.merge(diff)
        if (
            len(self.pending.added) + len(self.pending.changed) + len(self.pending.removed)
            > REBUILD_THRESHOLD
        ):
            self.needs_rebuild = True
            self.pending = BlackboardDiff()

    def flush(self) -> None:
        """Bring the table up to date (called by a timer; does nothing while the screen is hidden)."""
        if not self.is_current:
            return
        table = self.query_one(BlackboardTable)
        model = self.kinema.blackboard
        if self.needs_rebuild:
            self.needs_rebuild = False
            self.pending = BlackboardDiff()
            table.rebuild(self.query_one("#blackboard-filter", Input).value)
        elif self.pending:
            diff, self.pending = self.pending, BlackboardDiff()
            table.apply(diff)
        else:
            return
        summary = Text(f"{len(table.keys)} of {len(model.entries)} entries")
        if model.objective_name:
            summary.append(f"  ·  {model.objective_name}", style="bold")
        self.query_one("#blackboard-summary", Static).update(summary)
        self._show_history(table.selected_key())

    def on_input_changed(self, event: Input.Changed) -> None:
        if event.input.id == "blackboard-filter":
            self.needs_rebuild = True
            self.flush()

    def on_input_submitted(self, event: Input.Submitted) -> None:
        self.set_focus(self.query_one(BlackboardTable))

    def on_blackboard_table_key_highlighted(self, event: BlackboardTable.KeyHighlighted) -> None:
        self.history_key = event.key
        self._show_history(event.key)

    def _show_history(self, key: RowKey | None) -> None:
        table = self.query_one("#history-table", DataTable)
        title = self.query_one("#history-title", Static)
        table.clear()
        if key is None:
            title.update(Text("Select a key to see its recent values.", style="dim"))
            return
        scope, name = key
        title.update(Text.assemble((name, "bold"), (f"  {scope or '(root)'}", "dim")))
        for stamp, value in reversed(self.kinema.blackboard.history.get(key, ())):
            table.add_row(format_stamp(stamp), Text(value))

    def action_filter(self) -> None:
        self.set_focus(self.query_one("#blackboard-filter", Input))

    def action_clear_filter(self) -> None:
        self.query_one("#blackboard-filter", Input).value = ""
        self.set_focus(self.query_one(BlackboardTable))

    def action_focus_table(self) -> None:
        self.set_focus(self.query_one(BlackboardTable))
