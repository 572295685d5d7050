"""The Objectives screen against the scripted runtime: browse, filter, inspect, run, cancel, live status."""

from __future__ import annotations

from textual.widgets import Checkbox, Input, OptionList, Select, TabbedContent, TextArea
from tui_pilot_harness import drive, settle

from kinema.errors import TransportError
from kinema.tui.connection import Heartbeat, NodeStatus, NodeStatusBatch, NodeStatusUpdate
from kinema.tui.fake_connection import FakeConnection
from kinema.tui.screens.objectives import ObjectivesScreen
from kinema.tui.widgets.behavior_tree_view import BehaviorTreeView
from kinema.tui.widgets.override_form import OverrideForm


def listed(app) -> list[str]:  # type: ignore[no-untyped-def]
    options = app.screen.query_one("#objective-list", OptionList)
    return [str(options.get_option_at_index(i).id) for i in range(options.option_count)]


def test_library_is_listed_favorites_first_and_the_first_is_shown(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        assert isinstance(app.screen, ObjectivesScreen)
        assert listed(app) == ["Pick Object", "Open Gripper", "Wait and Log"]
        tree = app.screen.query_one(BehaviorTreeView)
        assert tree.outline is not None and tree.outline.tree_id == "Pick Object"
        # The subtree was expanded from its own document.
        assert any(node.path == "Wait and Log::3/Sleep::5" for node in tree.outline.nodes())
        await pilot.press("f3")  # the XML tab
        await settle(pilot)
        assert '<BehaviorTree ID="Pick Object"' in app.screen.query_one("#objective-xml", TextArea).text

    drive(fake, scenario)


def test_search_and_filters_narrow_the_list(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.press("slash")
        await pilot.press(*"grip")
        await settle(pilot)
        assert listed(app) == ["Open Gripper"]
        app.screen.query_one("#objective-search", Input).value = ""
        await pilot.press("escape")  # leave the search box; the list has the focus for the keys below
        app.screen.query_one("#objective-list", OptionList).focus()
        await pilot.press("ctrl+f")
        await settle(pilot)
        assert listed(app) == ["Pick Object"]
        await pilot.press("ctrl+f", "ctrl+u")
        await settle(pilot)
        assert listed(app) == ["Pick Object", "Open Gripper"]
        assert app.screen.query_one("#runnable", Checkbox).value
        app.screen.query_one("#runnable", Checkbox).value = False
        app.screen.query_one("#subcategory", Select).value = "Utilities"
        await settle(pilot)
        assert listed(app) == ["Wait and Log"]

    drive(fake, scenario)


def test_run_sends_the_filled_in_parameters_and_cancel_cancels(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.press("f4")
        await settle(pilot)
        assert app.screen.query_one(TabbedContent).active == "parameters"
        form = app.screen.query_one(OverrideForm)
        inputs = {field.name: field for field in form.query(Input)}
        assert set(inputs) == {"waypoint_name", "speed"}  # output ports get no input
        inputs["speed"].value = "0.25"
        app.screen.query_one("#objective-list", OptionList).focus()
        await pilot.press("enter")
        await settle(pilot)
        assert fake.called("start_objective") == [("Pick Object", {"speed": "0.25"})]
        assert app.screen.query_one(TabbedContent).active == "tree"
        await pilot.press("ctrl+x")
        await settle(pilot)
        assert fake.called("cancel_objective") == [()]
        assert any("Cancel the objective" in text for text in app.shown)

    drive(fake, scenario)


def test_the_parameters_key_puts_the_cursor_in_the_form_and_enter_runs(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.press("f4")
        await settle(pilot)
        form = app.screen.query_one(OverrideForm)
        first = form.query(Input).first()
        assert app.focused is first and first.name == "waypoint_name"
        await pilot.press(*"box")
        await settle(pilot)
        assert first.value == "box" and fake.called("cancel_objective") == []
        await pilot.press("enter")
        await settle(pilot)
        assert fake.called("start_objective") == [("Pick Object", {"waypoint_name": "box"})]
        # The run shows its tree, and the keys are the list's again, not the hidden field's.
        assert app.screen.query_one(TabbedContent).active == "tree"
        assert app.focused is app.screen.query_one("#objective-list", OptionList)
        await pilot.press("ctrl+x")
        await settle(pilot)
        assert fake.called("cancel_objective") == [()] and first.value == "box"

    drive(fake, scenario)


def test_letters_typed_on_the_list_search_and_never_run_or_switch_screens(fake: FakeConnection) -> None:
    # A new user typed a name into what looked like the search box: `u` toggled a filter and `r` started
    # an objective on the arm. Every letter on the list searches; once there, digits are typed too.
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        assert app.focused is app.screen.query_one("#objective-list", OptionList)
        await pilot.press(*"run quickly 3")
        await settle(pilot)
        assert isinstance(app.screen, ObjectivesScreen)  # neither 3 (a screen) nor q (quit) acted
        assert app.screen.query_one("#objective-search", Input).value == "run quickly 3"
        assert fake.called("start_objective") == [] and fake.called("cancel_objective") == []
        assert not app.screen.query_one("#runnable", Checkbox).value
        search = app.screen.query_one("#objective-search", Input)
        search.value = ""
        await pilot.press(*"grip")
        await settle(pilot)
        assert listed(app) == ["Open Gripper"]
        # Enter leaves the search box for the list; the hint names what Enter on the list runs.
        await pilot.press("enter")
        await settle(pilot)
        assert fake.called("start_objective") == []
        hint = str(app.screen.query_one("#run-hint").render())
        assert "Enter or ctrl+r runs Open Gripper" in hint
        await pilot.press("enter")
        await settle(pilot)
        assert fake.called("start_objective") == [("Open Gripper", {})]

    drive(fake, scenario)


def test_a_click_on_an_objective_selects_it_without_running_it(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        options = app.screen.query_one("#objective-list", OptionList)
        await pilot.click(options, offset=(4, 2))
        await settle(pilot)
        assert app.screen.selected.name == "Open Gripper"
        assert fake.called("start_objective") == []

    drive(fake, scenario)


def test_a_subtree_only_objective_is_not_run(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.press("down", "down")
        await settle(pilot)
        assert app.screen.selected.name == "Wait and Log"
        await pilot.press("ctrl+r")
        await settle(pilot)
        assert fake.called("start_objective") == []
        assert any("subtree only" in text for text in app.shown)

    drive(fake, scenario)


def test_node_statuses_show_live_on_the_tree_and_reset_on_a_new_run(fake: FakeConnection) -> None:
    def update(uid: int, path: str, status: NodeStatus) -> NodeStatusUpdate:
        return NodeStatusUpdate(uid, path, "", "", status)

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        view = app.screen.query_one(BehaviorTreeView)
        fake.emit(Heartbeat(1.0, "Pick Object", "Running"))
        fake.emit(
            NodeStatusBatch(
                "Pick Object",
                (
                    update(1, "TopLevelSequence", NodeStatus.RUNNING),
                    update(2, "MoveToWaypoint::2", NodeStatus.SUCCESS),
                    update(5, "Wait and Log::3/Sleep::5", NodeStatus.RUNNING),
                ),
            )
        )
        await settle(pilot)
        assert view.status_of("TopLevelSequence") is NodeStatus.RUNNING
        assert view.status_of("MoveToWaypoint::2") is NodeStatus.SUCCESS
        assert view.status_of("Wait and Log::3/Sleep::5") is NodeStatus.RUNNING
        labels = [str(node.label) for node in view._by_uid.values()]
        assert any(label.startswith("✔ MoveToWaypoint") and "SUCCESS" in label for label in labels)
        # Another objective's statuses do not paint this tree.
        fake.emit(NodeStatusBatch("Open Gripper", (update(1, "OpenGripper", NodeStatus.FAILURE),)))
        await settle(pilot)
        assert view.status_of("TopLevelSequence") is NodeStatus.RUNNING
        # The run ends, then a new one starts: everything is idle again.
        fake.emit(Heartbeat(2.0, "Pick Object", "Success"))
        fake.emit(Heartbeat(3.0, "Pick Object", "Running"))
        await settle(pilot)
        assert view.status_of("MoveToWaypoint::2") is NodeStatus.IDLE

    drive(fake, scenario)


def test_a_failing_runtime_call_is_shown_and_the_app_keeps_running(fake: FakeConnection) -> None:
    fake.failures["start_objective"] = TransportError("no runtime answered on tcp/127.0.0.1:7447 within 2 s")

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.press("ctrl+r")
        await settle(pilot)
        assert any("Run 'Pick Object' failed: no runtime answered" in text for text in app.shown)
        assert any("no runtime answered" in entry.message for entry in app.logs)
        await pilot.press("down")
        await settle(pilot)
        assert app.screen.selected.name == "Open Gripper"  # still responsive

    drive(fake, scenario)


def test_the_command_palette_runs_an_objective(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.press("ctrl+p")
        await settle(pilot)
        await pilot.press(*"run open gr")
        await pilot.pause(0.5)
        await settle(pilot)
        await pilot.press("enter")
        await settle(pilot)
        assert fake.called("start_objective") == [("Open Gripper", {})]

    drive(fake, scenario)


def test_the_ports_tab_shows_each_parameters_type(fake: FakeConnection) -> None:
    from textual.widgets import DataTable

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        app.screen.query_one(TabbedContent).active = "ports"  # as a click on its tab does
        await settle(pilot)
        table = app.screen.query_one("#port-table", DataTable)
        rows = [[str(cell) for cell in table.get_row_at(i)] for i in range(table.row_count)]
        assert rows[:2] == [
            ["waypoint_name", "input", "std::string", "Look at Table", "Where to look before picking"],
            ["speed", "input", "double", "0.5", "Velocity scale factor"],
        ]

    drive(fake, scenario)


def test_tabs_first_shown_after_another_objective_was_selected_show_that_one(fake: FakeConnection) -> None:
    """The XML, Parameters and Ports tabs are filled when first shown: with the objective selected then."""

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.press("down")  # Open Gripper, no ports
        await settle(pilot)
        assert app.screen.selected.name == "Open Gripper"
        await pilot.press("f3")
        await settle(pilot)
        assert '<BehaviorTree ID="Open Gripper"' in app.screen.query_one("#objective-xml", TextArea).text
        app.screen.query_one(TabbedContent).active = "ports"
        await settle(pilot)
        assert app.screen.query_one("#port-table").row_count == 0
        await pilot.press("up")  # Pick Object: the tabs shown before follow the selection
        await settle(pilot)
        assert app.screen.query_one("#port-table").row_count == 3
        await pilot.press("f3")
        await settle(pilot)
        assert '<BehaviorTree ID="Pick Object"' in app.screen.query_one("#objective-xml", TextArea).text
        await pilot.press("f4")
        await settle(pilot)
        fields = [field.name for field in app.screen.query_one(OverrideForm).query(Input)]
        assert fields == ["waypoint_name", "speed"]

    drive(fake, scenario)


def test_cancel_works_from_the_search_box_and_escape_leaves_it(fake: FakeConnection) -> None:
    # A new user typing in the search box pressed ctrl+x to stop a moving arm: the box took it as "cut".
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.press("slash", *"grip")
        await settle(pilot)
        search = app.screen.query_one("#objective-search", Input)
        assert app.focused is search
        await pilot.press("ctrl+x")
        await settle(pilot)
        assert fake.called("cancel_objective") == [()]
        assert search.value == "grip"
        await pilot.press("escape")
        await settle(pilot)
        assert app.focused is app.screen.query_one("#objective-list", OptionList)
        assert search.value == "grip" and listed(app) == ["Open Gripper"]

    drive(fake, scenario)


def test_asking_to_quit_twice_asks_once(fake: FakeConnection) -> None:
    from kinema.tui.dialogs.confirm import ConfirmDialog

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.press("ctrl+q")
        await settle(pilot)
        await pilot.press("ctrl+q")
        await settle(pilot)
        assert sum(isinstance(screen, ConfirmDialog) for screen in app.screen_stack) == 1
        await pilot.press("n")
        await settle(pilot)
        assert not any(isinstance(screen, ConfirmDialog) for screen in app.screen_stack)
        await pilot.press("ctrl+q")  # and it asks again once the first answer is in
        await settle(pilot)
        assert isinstance(app.screen, ConfirmDialog)

    drive(fake, scenario, owns_runtime=True)
