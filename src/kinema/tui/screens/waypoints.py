"""Waypoints: list, move to, save the current state as a waypoint, rename, delete."""

from __future__ import annotations

from collections.abc import Callable

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.widgets import DataTable, Static

from kinema.tui.connection import ConnectionState, RuntimeConnection, WaypointSummary
from kinema.tui.dialogs.confirm import ConfirmDialog
from kinema.tui.dialogs.text_prompt import TextPromptDialog
from kinema.tui.messages import WaypointsLoaded
from kinema.tui.screens.base import LOAD_ATTEMPTS, KinemaScreen
from kinema.tui.widgets.fitted_table import Column, FittedTable


class WaypointsScreen(KinemaScreen):
    """The saved waypoints of the runtime's config."""

    MODE = "waypoints"
    AUTO_FOCUS = "#waypoint-table"
    BINDINGS = [
        Binding("enter", "move", "Move to", id="waypoints.move", tooltip="Move the robot to the waypoint"),
        Binding(
            "s", "save", "Save current", id="waypoints.save", tooltip="Save the current state as a waypoint"
        ),
        Binding("n", "rename", "Rename", id="waypoints.rename", tooltip="Rename the selected waypoint"),
        Binding("d", "delete", "Delete", id="waypoints.delete", tooltip="Delete the selected waypoint"),
        Binding("f5", "reload", "Reload", id="waypoints.reload", tooltip="List the waypoints again"),
    ]

    def __init__(self) -> None:
        super().__init__()
        self.waypoints: list[WaypointSummary] = []

    def compose_body(self) -> ComposeResult:
        with Horizontal(classes="split", id="waypoint-split"):
            with Vertical(classes="main"):
                yield FittedTable(
                    (
                        Column("favorite", "", min_width=1, weight=0),
                        Column("name", "Waypoint", min_width=14, weight=1),
                        Column("groups", "Groups", min_width=8, weight=1, drop=2, wrap=False),
                        Column("description", "Description", min_width=14, weight=2, drop=1),
                    ),
                    id="waypoint-table",
                )
            with Vertical(classes="side-panel"):
                yield Static("", id="waypoint-title", classes="pane-title")
                # A position is never cut: "-1.5708" shown as "-" says nothing (a long joint name is).
                yield FittedTable(
                    (
                        Column("joint", "Joint", min_width=8, weight=1, wrap=False),
                        Column("position", "Position", min_width=9, weight=0),
                    ),
                    id="joint-table",
                )

    def on_mount(self) -> None:
        super().on_mount()
        table = self.query_one("#waypoint-table", DataTable)
        self.set_focus(table)
        if self.kinema.status.state is ConnectionState.CONNECTED:
            self.action_reload()

    def action_reload(self) -> None:
        self.call_runtime(
            "List waypoints", self.kinema.connection.list_waypoints, WaypointsLoaded, attempts=LOAD_ATTEMPTS
        )

    def runtime_connected(self) -> None:
        self.action_reload()

    def on_waypoints_loaded(self, message: WaypointsLoaded) -> None:
        table = self.query_one("#waypoint-table", FittedTable)
        previous = self.selected()
        self.waypoints = sorted(message.waypoints, key=lambda w: (not w.favorite, w.name.lower()))
        table.set_rows(
            [
                (
                    Text("★", style="yellow") if waypoint.favorite else Text(""),
                    Text(waypoint.name),
                    Text(", ".join(waypoint.joint_group_names)),
                    Text(waypoint.description),
                )
                for waypoint in self.waypoints
            ],
            [waypoint.name for waypoint in self.waypoints],
        )
        names = [w.name for w in self.waypoints]
        if previous is not None and previous.name in names:
            table.move_cursor(row=names.index(previous.name))
        self._show(self.selected())

    def selected(self) -> WaypointSummary | None:
        """The waypoint under the cursor."""
        table = self.query_one("#waypoint-table", DataTable)
        if not self.waypoints or table.row_count == 0:
            return None
        row = min(table.cursor_row, len(self.waypoints) - 1)
        return self.waypoints[row]

    def on_data_table_row_highlighted(self, event: DataTable.RowHighlighted) -> None:
        if event.data_table.id == "waypoint-table":
            self._show(self.selected())

    def on_data_table_row_selected(self, event: DataTable.RowSelected) -> None:
        if event.data_table.id == "waypoint-table":
            self.action_move()

    def _show(self, waypoint: WaypointSummary | None) -> None:
        joints = self.query_one("#joint-table", FittedTable)
        title = self.query_one("#waypoint-title", Static)
        if waypoint is None:
            joints.set_rows([])
            title.update(Text("No waypoint selected", style="dim"))
            return
        # Enter moves the robot: the panel says where to, before the key is pressed.
        title.update(Text.assemble((waypoint.name, "bold"), ("\nEnter moves the robot here", "dim")))
        joints.set_rows(
            [
                (Text(name), Text(f"{position:+.4f}"))
                for name, position in zip(waypoint.joint_names, waypoint.positions, strict=False)
            ]
        )

    def action_move(self) -> None:
        waypoint = self.selected()
        if waypoint is None:
            self.notify("No waypoint selected.", severity="warning")
            return
        self.move_to(waypoint.name)

    def move_to(self, name: str) -> None:
        """Move the robot to waypoint ``name``."""
        connection = self.kinema.connection
        self.call_runtime(
            f"Move to waypoint {name!r}",
            lambda: connection.move_to_waypoint(name),
            announce=True,
        )

    def action_save(self) -> None:
        connection = self.kinema.connection

        def save(name: str | None) -> None:
            if name:
                self.call_runtime(
                    f"Save waypoint {name!r}",
                    lambda: _then_list(connection, lambda: connection.save_waypoint(name)),
                    WaypointsLoaded,
                    announce=True,
                )

        self.app.push_screen(
            TextPromptDialog("Save the robot's current state as waypoint:", placeholder="waypoint name"), save
        )

    def action_rename(self) -> None:
        waypoint = self.selected()
        if waypoint is None:
            self.notify("No waypoint selected.", severity="warning")
            return
        connection = self.kinema.connection

        def rename(new_name: str | None) -> None:
            if new_name and new_name != waypoint.name:
                self.call_runtime(
                    f"Rename waypoint {waypoint.name!r} to {new_name!r}",
                    lambda: _then_list(
                        connection, lambda: connection.rename_waypoint(waypoint.name, new_name)
                    ),
                    WaypointsLoaded,
                    announce=True,
                )

        self.app.push_screen(
            TextPromptDialog(f"Rename waypoint {waypoint.name!r} to:", waypoint.name), rename
        )

    def action_delete(self) -> None:
        waypoint = self.selected()
        if waypoint is None:
            self.notify("No waypoint selected.", severity="warning")
            return
        connection = self.kinema.connection

        def delete(confirmed: bool | None) -> None:
            if confirmed:
                self.call_runtime(
                    f"Delete waypoint {waypoint.name!r}",
                    lambda: _then_list(connection, lambda: connection.erase_waypoint(waypoint.name)),
                    WaypointsLoaded,
                    announce=True,
                )

        self.app.push_screen(ConfirmDialog(f"Delete waypoint {waypoint.name!r}?", "Delete"), delete)


def _then_list(connection: RuntimeConnection, change: Callable[[], object]) -> list[WaypointSummary]:
    """Make a change, then read the list back (what the table shows is what the runtime has)."""
    change()
    return connection.list_waypoints()
