"""Behaviors: the catalog with ports and metadata, where each came from, and hot-reload events."""

from __future__ import annotations

import time

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.widgets import DataTable, Input, Label, Static

from kinema.tui.connection import BehaviorSummary, ConnectionState, ReloadNotice
from kinema.tui.messages import BehaviorsLoaded
from kinema.tui.screens.base import LOAD_ATTEMPTS, KinemaScreen
from kinema.tui.widgets.fitted_table import PORT_COLUMNS, FittedTable


class BehaviorsScreen(KinemaScreen):
    """The behavior catalog and the hot-reload event list."""

    MODE = "behaviors"
    AUTO_FOCUS = "#behavior-table"
    BINDINGS = [
        Binding("slash", "search", "Search", id="behaviors.search", tooltip="Search behaviors"),
        Binding("f5", "reload", "Reload", id="behaviors.reload", tooltip="List the behaviors again"),
        Binding(
            "escape",
            "leave_search",
            "Leave search",
            id="behaviors.leave_search",
            tooltip="Leave the search box (its filter stays) for the list",
            show=False,
        ),
    ]

    def __init__(self) -> None:
        super().__init__()
        self.behaviors: list[BehaviorSummary] = []
        self.shown_behaviors: list[BehaviorSummary] = []

    def compose_body(self) -> ComposeResult:
        with Horizontal(classes="split"):
            with Vertical(classes="sidebar wide"):
                yield Input(placeholder="/ search behaviors", id="behavior-search")
                yield DataTable(id="behavior-table", cursor_type="row", zebra_stripes=True)
            with Vertical(classes="main"):
                yield Static("", id="behavior-title", classes="pane-title")
                yield Static("", id="behavior-details")
                yield FittedTable(PORT_COLUMNS, id="behavior-ports")
                # Shown from the first reload on: until then the port table has the room (at 80x24 it
                # showed one port above an empty reload table).
                yield Label("Hot reload", classes="pane-title", id="reload-title")
                yield DataTable(id="reload-table", cursor_type="row", zebra_stripes=True)

    def on_mount(self) -> None:
        super().on_mount()
        table = self.query_one("#behavior-table", DataTable)
        table.add_column("Behavior", key="id")
        table.add_column("Plugin", key="plugin")
        table.add_column("Subcategory", key="subcategory")
        reloads = self.query_one("#reload-table", DataTable)
        reloads.add_column("Time", key="time", width=8)
        reloads.add_column("", key="ok", width=2)
        reloads.add_column("What", key="subject")
        reloads.add_column("Message", key="message")
        for notice in self.kinema.reloads:
            self._add_reload(notice)
        self._show_reloads(bool(self.kinema.reloads))
        self.set_focus(table)
        if self.kinema.status.state is ConnectionState.CONNECTED:
            self.action_reload()

    def action_reload(self) -> None:
        self.call_runtime(
            "List behaviors", self.kinema.connection.list_behaviors, BehaviorsLoaded, attempts=LOAD_ATTEMPTS
        )

    def runtime_connected(self) -> None:
        self.action_reload()

    def on_behaviors_loaded(self, message: BehaviorsLoaded) -> None:
        self.behaviors = sorted(message.behaviors, key=lambda b: b.id.lower())
        self._refilter()

    def _refilter(self) -> None:
        needle = self.query_one("#behavior-search", Input).value.strip().lower()
        self.shown_behaviors = [
            b
            for b in self.behaviors
            if not needle
            or needle in b.id.lower()
            or needle in b.plugin.lower()
            or needle in b.metadata.get("description", "").lower()
        ]
        table = self.query_one("#behavior-table", DataTable)
        table.clear()
        for behavior in self.shown_behaviors:
            cells = (behavior.id, behavior.plugin, behavior.metadata.get("subcategory", ""))
            table.add_row(*(Text(cell) for cell in cells), key=behavior.id)
        if self.shown_behaviors:
            self._show(self.shown_behaviors[0])

    def on_input_changed(self, event: Input.Changed) -> None:
        self._refilter()

    def on_input_submitted(self, event: Input.Submitted) -> None:
        self.set_focus(self.query_one("#behavior-table", DataTable))

    def on_data_table_row_highlighted(self, event: DataTable.RowHighlighted) -> None:
        if event.data_table.id != "behavior-table" or event.row_key.value is None:
            return
        found = next((b for b in self.shown_behaviors if b.id == event.row_key.value), None)
        if found is not None:
            self._show(found)

    def _show(self, behavior: BehaviorSummary) -> None:
        self.query_one("#behavior-title", Static).update(Text(behavior.id, style="bold"))
        details = Text()
        description = behavior.metadata.get("description", "")
        details.append(description or "(no description)")
        details.append(f"\nplugin {behavior.plugin}", style="dim")
        if behavior.source:
            details.append(f"  ·  {behavior.source}", style="dim")
        if behavior.location:
            details.append(f"\n{behavior.location}", style="dim")
        extra = {k: v for k, v in behavior.metadata.items() if k != "description"}
        if extra:
            details.append("\n" + "  ".join(f"{k}: {v}" for k, v in extra.items()), style="dim")
        self.query_one("#behavior-details", Static).update(details)
        self.query_one("#behavior-ports", FittedTable).set_rows(
            [(p.name, p.direction, p.type_name, p.default, p.description) for p in behavior.ports]
        )

    def runtime_reload(self, notice: ReloadNotice) -> None:
        self._add_reload(notice)
        if notice.ok:
            self.action_reload()

    def _add_reload(self, notice: ReloadNotice) -> None:
        table = self.query_one("#reload-table", DataTable)
        stamp = time.strftime("%H:%M:%S", time.localtime(notice.stamp)) if notice.stamp else ""
        mark = Text("✔", style="green") if notice.ok else Text("✘", style="bold red")
        message = Text(notice.message)
        if notice.location:
            message = Text.assemble((f"{notice.location}: ", "bold"), notice.message)
        table.add_row(stamp, mark, Text(notice.subject), message)
        table.move_cursor(row=table.row_count - 1)
        self._show_reloads(True)

    def _show_reloads(self, shown: bool) -> None:
        self.query_one("#reload-title", Label).display = shown
        self.query_one("#reload-table", DataTable).display = shown

    def action_leave_search(self) -> None:
        if self.query_one("#behavior-search", Input).has_focus:
            self.set_focus(self.query_one("#behavior-table", DataTable))

    def action_search(self) -> None:
        self.set_focus(self.query_one("#behavior-search", Input))
