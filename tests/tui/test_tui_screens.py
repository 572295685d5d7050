"""Configs, Blackboard, Behaviors, Logs and Waypoints screens, the status bar and reconnection (Pilot)."""

from __future__ import annotations

from rich.text import Text
from textual.widgets import DataTable, Input, OptionList, RichLog, Select, Tree
from tui_pilot_harness import drive, settle

from kinema.errors import TransportError
from kinema.tui.connection import (
    BlackboardEntry,
    BlackboardSnapshot,
    ClockSample,
    ConnectionChanged,
    ConnectionState,
    Heartbeat,
    LogEntry,
    LogLevel,
    ReloadNotice,
)
from kinema.tui.fake_connection import FakeConnection
from kinema.tui.screens.blackboard import BlackboardScreen
from kinema.tui.widgets.blackboard_table import BlackboardTable
from kinema.tui.widgets.status_bar import StatusBar


def table_rows(table: DataTable) -> list[list[str]]:  # type: ignore[type-arg]
    """The table's cells as the user reads them (text cells are markup: render them)."""
    return [
        [Text.from_markup(cell).plain if isinstance(cell, str) else str(cell) for cell in table.get_row_at(i)]
        for i in range(table.row_count)
    ]


def tree_labels(tree: Tree) -> list[str]:  # type: ignore[type-arg]
    out: list[str] = []
    stack = [tree.root]
    while stack:
        node = stack.pop()
        out.append(str(node.label))
        stack.extend(reversed(node.children))
    return out


def _nodes(tree: Tree) -> list:  # type: ignore[type-arg]
    found, stack = [], [tree.root]
    while stack:
        node = stack.pop()
        found.append(node)
        stack.extend(node.children)
    return found


# -- Configs -------------------------------------------------------------------------------------


def test_configs_show_packages_chain_provenance_and_files(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        options = app.screen.query_one("#config-list", OptionList)
        names = [options.get_option_at_index(i).id for i in range(options.option_count)]
        assert names == ["example_config", "lab_sim"]
        assert app.screen.details.name == "lab_sim"  # the runtime's config is preselected
        options.focus()
        await pilot.press("up")
        await settle(pilot)
        details = app.screen.details
        assert details.name == "example_config" and not details.error
        chain = tree_labels(app.screen.query_one("#chain-tree", Tree))
        assert [label.split()[0] for label in chain[1:]] == ["lab_sim", "example_config"]
        rows = table_rows(app.screen.query_one("#resolved-table", DataTable))
        by_key = {row[0]: row for row in rows}
        # Key, value, and the package that set it.
        assert by_key["based_on_package"][1:] == ["lab_sim", "example_config"]
        assert by_key["hardware.robot_description.urdf"][2] == "lab_sim"  # inherited
        # Lists show as written (not swallowed as markup).
        started = by_key["ros2_control.controllers_active_at_startup"][1]
        assert started.startswith("[") and started.endswith("]") and len(started) > 2
        await pilot.press("i")
        await settle(pilot)
        files = tree_labels(app.screen.query_one("#file-tree", Tree))
        assert "config/" in files and "config.yaml" in files and "package.xml" in files
        # Enter on a file opens it, read-only; Escape goes back (a new user found the tab opened nothing).
        tree = app.screen.query_one("#file-tree", Tree)
        package_xml = next(n for n in _nodes(tree) if str(n.label) == "package.xml")
        tree.move_cursor(package_xml)
        app.screen.set_focus(tree)
        await pilot.press("enter")
        await settle(pilot)
        from kinema.tui.dialogs.file_view import FileViewDialog

        assert isinstance(app.screen, FileViewDialog)
        assert "<name>example_config</name>" in app.screen.query_one("#file-text").text
        await pilot.press("escape")
        await settle(pilot)
        assert not isinstance(app.screen, FileViewDialog)

    drive(fake, scenario, mode="configs")


# -- Blackboard ----------------------------------------------------------------------------------


def snapshot(stamp: float, values: dict[str, str], scope: str = "") -> BlackboardSnapshot:
    entries = tuple(BlackboardEntry(scope, key, "int", value) for key, value in values.items())
    return BlackboardSnapshot("Pick Object", stamp, entries)


def test_blackboard_rows_update_in_place_filter_and_show_history(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        table = app.screen.query_one(BlackboardTable)
        rows = lambda: [list(row) for row in table.row_texts()]  # noqa: E731 - read at each use
        rebuilds = 0
        original = table.rebuild

        def counting_rebuild(*args, **kwargs):  # type: ignore[no-untyped-def]
            nonlocal rebuilds
            rebuilds += 1
            original(*args, **kwargs)

        table.rebuild = counting_rebuild  # type: ignore[method-assign]
        fake.emit(snapshot(1.0, {"count": "1", "goal": "[1, 2]", "name": "'a'"}))
        fake.emit(
            BlackboardSnapshot(
                "Pick Object",
                1.0,
                (
                    BlackboardEntry("", "count", "int", "1"),
                    BlackboardEntry("", "goal", "int", "[1, 2]"),
                    BlackboardEntry("", "name", "int", "'a'"),
                    BlackboardEntry("Wait and Log::3", "seconds", "double", "0.5"),
                ),
            )
        )
        await pilot.pause(0.3)
        await settle(pilot)
        assert sorted(r[1] for r in rows()) == ["count", "goal", "name", "seconds"]
        assert ["Wait and Log::3", "seconds", "double", "0.5"] in rows()
        assert ["(root)", "goal", "int", "[1, 2]"] in rows()  # shown as written, not as markup
        for i in range(2, 6):
            fake.emit(
                BlackboardSnapshot(
                    "Pick Object",
                    float(i),
                    (
                        BlackboardEntry("", "count", "int", str(i)),
                        BlackboardEntry("", "goal", "int", "[1, 2]"),
                        BlackboardEntry("Wait and Log::3", "seconds", "double", "0.5"),
                    ),
                )
            )
            await pilot.pause(0.25)
        await settle(pilot)
        shown = rows()
        assert ["(root)", "count", "int", "5"] in shown
        assert "name" not in [r[1] for r in shown]  # removed from the blackboard, removed from the table
        assert rebuilds == 0  # live updates never rebuilt the table
        table.set_cursor([r[1] for r in shown].index("count"))
        await settle(pilot)
        history = table_rows(app.screen.query_one("#history-table", DataTable))
        assert [row[1] for row in history][:3] == ["5", "4", "3"]
        await pilot.press("slash", *"seco")
        await pilot.pause(0.3)
        await settle(pilot)
        assert [r[1] for r in rows()] == ["seconds"]
        assert "1 of 3 entries" in str(app.screen.query_one("#blackboard-summary").render())

    drive(fake, scenario, mode="blackboard")


def test_blackboard_updates_wait_while_the_screen_is_hidden(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        screen = app.screen
        assert isinstance(screen, BlackboardScreen)
        await pilot.press("2")
        await settle(pilot)
        fake.emit(snapshot(1.0, {f"k{i}": str(i) for i in range(50)}))
        await pilot.pause(0.3)
        assert screen.query_one(BlackboardTable).keys == []
        await pilot.press("3")
        await settle(pilot)
        assert len(screen.query_one(BlackboardTable).keys) == 50

    drive(fake, scenario, mode="blackboard")


# -- Behaviors -----------------------------------------------------------------------------------


def test_behaviors_catalog_and_reload_events(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        table = app.screen.query_one("#behavior-table", DataTable)
        assert [row[0] for row in table_rows(table)] == ["MoveToWaypoint", "MyBehavior"]
        await pilot.press("down")
        await settle(pilot)
        ports = table_rows(app.screen.query_one("#behavior-ports", DataTable))
        assert [p[0] for p in ports] == ["int_1", "int_2", "int_out"]
        details = str(app.screen.query_one("#behavior-details").render())
        assert "Adds two integers." in details and "workspace: src/my_behaviors" in details
        assert "src/my_behaviors/my_behavior.py:12" in details
        # No reload yet: the port table has the room of the empty reload list (at 80x24 one port showed).
        assert not app.screen.query_one("#reload-table", DataTable).display
        fake.emit(
            ReloadNotice(
                False,
                "reload_failed",
                "my_behaviors",
                "SyntaxError: invalid syntax",
                "src/my_behaviors/my_behavior.py:7",
            )
        )
        fake.emit(ReloadNotice(True, "behaviors_reloaded", "my_behaviors", "reloaded 1 behavior"))
        await settle(pilot)
        reloads = table_rows(app.screen.query_one("#reload-table", DataTable))
        assert reloads[0][1] == "✘" and "src/my_behaviors/my_behavior.py:7: SyntaxError" in reloads[0][3]
        assert reloads[1][1] == "✔"
        assert app.screen.query_one("#reload-table", DataTable).display
        assert any("my_behavior.py:7: SyntaxError" in text for text in app.shown)
        # Esc leaves the search box for the list, so that the screen keys (1-6) switch screens again.
        await pilot.press("slash", "M")
        assert app.focused is not None and app.focused.id == "behavior-search"
        await pilot.press("escape")
        assert app.focused is not None and app.focused.id == "behavior-table"
        assert len(fake.called("list_behaviors")) == 2  # a good reload lists the behaviors again

    drive(fake, scenario, mode="behaviors")


# -- Logs ----------------------------------------------------------------------------------------


def test_toasts_notify_and_the_log_panel_filters_by_level(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        fake.emit(LogEntry("Sum: 5", LogLevel.INFO, 0.0, "MyServiceClient"))
        fake.emit(LogEntry("gripper slow", LogLevel.WARN))
        fake.emit(LogEntry("planning failed", LogLevel.ERROR))
        await settle(pilot)
        assert {"Sum: 5", "gripper slow", "planning failed"} <= set(app.shown)
        panel = app.screen.query_one(RichLog)
        assert len(panel.lines) == 3
        await pilot.press("e")
        await settle(pilot)
        assert app.screen.query_one("#log-level", Select).value == int(LogLevel.ERROR)
        assert [line.text for line in panel.lines] == ["ERROR planning failed"]
        await pilot.press("l")
        await settle(pilot)
        assert len(panel.lines) == 2
        assert "2 of 3 messages" in str(app.screen.query_one("#log-count").render())

    drive(fake, scenario, mode="logs")


def test_long_log_lines_wrap_whole_at_80_columns_after_the_scrollbar_appears(fake: FakeConnection) -> None:
    # A new user read "(targe 0.7929)" for "(target 0.7929)": lines were wrapped wider than the panel, and
    # the end of each was out of sight.
    words = " ".join(f"word{index:02d}" for index in range(30))

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        for number in range(40):
            fake.emit(LogEntry(f"{number}: {words}", LogLevel.INFO))
        await settle(pilot)
        panel = app.screen.query_one(RichLog)
        assert panel.show_vertical_scrollbar and len(panel.lines) > panel.scrollable_content_region.height
        width = panel.scrollable_content_region.width
        assert max(line.cell_length for line in panel.lines) <= width
        text = " ".join(line.text.strip() for line in panel.lines)
        assert text.count(words) == 40

    drive(fake, scenario, mode="logs", size=(80, 24))


# -- Waypoints -----------------------------------------------------------------------------------


def test_waypoints_move_save_rename_delete(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        table = app.screen.query_one("#waypoint-table", DataTable)
        assert [row[1] for row in table_rows(table)] == ["Home", "Look at Table"]
        joints = table_rows(app.screen.query_one("#joint-table", DataTable))
        assert joints == [["joint_1", "+0.0000"], ["joint_2", "+0.0000"]]
        await pilot.press("down", "enter")
        await settle(pilot)
        assert fake.called("move_to_waypoint") == [("Look at Table",)]
        await pilot.press("s")
        await settle(pilot)
        await pilot.press(*"Above Tray", "enter")
        await settle(pilot)
        assert fake.called("save_waypoint") == [("Above Tray",)]
        assert "Above Tray" in [row[1] for row in table_rows(table)]
        await pilot.press("n")
        await settle(pilot)
        app.screen.query_one(Input).value = "Tray"
        await pilot.press("enter")
        await settle(pilot)
        assert fake.called("rename_waypoint")[0][1] == "Tray"
        renamed = fake.called("rename_waypoint")[0][0]
        await pilot.press("d")
        await settle(pilot)
        await pilot.press("n")  # declined: nothing deleted
        await settle(pilot)
        assert fake.called("erase_waypoint") == []
        await pilot.press("d")
        await settle(pilot)
        await pilot.press("y")
        await settle(pilot)
        erased = fake.called("erase_waypoint")[0][0]
        assert erased not in [row[1] for row in table_rows(table)]
        assert renamed not in [row[1] for row in table_rows(table)]

    drive(fake, scenario, mode="waypoints")


# -- status bar, connection ----------------------------------------------------------------------


def test_status_bar_shows_heartbeat_sim_time_and_a_lost_runtime_then_reloads_on_return(
    fake: FakeConnection,
) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        bar = app.screen.query_one(StatusBar)
        fake.emit(Heartbeat(5.0, "Pick Object", "Running"))
        fake.emit(Heartbeat(7.5, "Pick Object", "Running"))
        fake.emit(ClockSample(12.25, 0.97))
        await settle(pilot)
        text = str(bar.render())
        assert "connected" in text and "Pick Object Running 2.5 s" in text and "sim 12.25 s" in text
        assert "RTF 0.97x" in text
        listed_before = len(fake.called("list_objectives"))
        fake.failures["list_objectives"] = TransportError("no runtime")
        fake.emit(ConnectionChanged(ConnectionState.DISCONNECTED, "fake://runtime", "no heartbeat for 3 s"))
        await settle(pilot)
        assert "disconnected" in str(bar.render()) and "no heartbeat for 3 s" in str(bar.render())
        assert any("no heartbeat for 3 s" in text for text in app.shown)
        del fake.failures["list_objectives"]
        fake.emit(ConnectionChanged(ConnectionState.CONNECTED, "fake://runtime"))
        await settle(pilot)
        assert "● connected" in str(bar.render())
        assert len(fake.called("list_objectives")) == listed_before + 1

    drive(fake, scenario)


def test_every_binding_has_an_id_and_a_tooltip() -> None:
    from kinema.tui.app import SCREEN_CLASSES, KinemaApp, screen_class

    for mode in SCREEN_CLASSES:
        for binding in [*KinemaApp.BINDINGS, *screen_class(mode).BINDINGS]:
            assert binding.id and binding.tooltip, binding


def test_a_broken_config_is_shown_with_its_error_and_files(fake: FakeConnection, tmp_path) -> None:  # type: ignore[no-untyped-def]
    package = tmp_path / "src" / "my_config"
    (package / "config").mkdir(parents=True)
    (package / "config" / "config.yaml").write_text("# mine\nbased_on_package: lab_simm\n")
    fake.workspace_root = str(tmp_path)
    fake.fake_config = "my_config"

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        details = app.screen.details
        assert details.name == "my_config"
        assert "lab_simm" in details.error and "lab_sim" in details.error.replace("lab_simm", "")
        assert "config.yaml:2" in details.error  # where the bad value is
        title = str(app.screen.query_one("#config-title").render())
        assert "lab_simm" in title
        assert details.files == ["config/config.yaml"]
        labels = {option.id: str(option.prompt) for option in _options(app)}
        assert "bundled" in labels["lab_sim"] and "bundled" not in labels["my_config"]

    drive(fake, scenario, mode="configs")


def _options(app):  # type: ignore[no-untyped-def]
    options = app.screen.query_one("#config-list", OptionList)
    return [options.get_option_at_index(i) for i in range(options.option_count)]


def test_the_mouse_switches_screens_and_picks_rows(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.click("#nav-waypoints")
        await settle(pilot)
        assert app.current_mode == "waypoints"
        table = app.screen.query_one("#waypoint-table", DataTable)
        await pilot.click("#waypoint-table", offset=(10, 2))  # the second row (below the header)
        await settle(pilot)
        assert app.screen.selected().name == "Look at Table"
        await pilot.click("#nav-objectives")
        await settle(pilot)
        assert app.current_mode == "objectives" and table.cursor_row == 1

    drive(fake, scenario, mode="configs")
