"""At 80x24 every screen keeps the columns a user reads: values, types, set-by, positions, descriptions."""

from __future__ import annotations

from dataclasses import replace

from textual.widgets import TabbedContent
from tui_pilot_harness import drive, settle

from kinema.tui.connection import BlackboardEntry, BlackboardSnapshot
from kinema.tui.fake_connection import FakeConnection
from kinema.tui.widgets.blackboard_table import BlackboardTable
from kinema.tui.widgets.fitted_table import Column, FittedTable, fit_widths

NARROW = (80, 24)
JOINTS = ("linear_rail_joint", "shoulder_pan_joint", "robotiq_85_left_knuckle_joint")


def test_columns_give_way_least_important_first() -> None:
    columns = (
        Column("name", "Port", min_width=10),
        Column("direction", "Dir", min_width=6, weight=0, drop=3),
        Column("type", "Type", min_width=8, drop=2),
        Column("description", "Description", min_width=16, weight=3),
    )
    natural = [12, 6, 30, 80]
    assert fit_widths(columns, natural, 200, 2) == natural  # room for everything: natural widths
    narrow = fit_widths(columns, natural, 44, 2)
    assert narrow[1] == 0 and narrow[3] >= 16 and sum(narrow) + 2 * 3 <= 44  # Dir went first
    tight = fit_widths(columns, natural, 30, 2)
    assert tight[1] == tight[2] == 0 and tight[0] and tight[3]  # then Type; name and description stay


def test_a_port_name_is_never_broken_in_the_port_table_of_an_80_column_pane() -> None:
    # The behaviors pane at 80x24 showed "waypoint_na" over "me": the name column gave way first.
    from kinema.tui.widgets.fitted_table import PORT_COLUMNS

    natural = [len("velocity_scale_factor"), 5, 6, 12, 60]  # name, direction, type, default, description
    widths = fit_widths(PORT_COLUMNS, natural, 42, 1)
    assert widths[0] == natural[0] and widths[4] >= 16  # the name whole, the description readable


def lines(widget) -> list[str]:  # type: ignore[no-untyped-def]
    return [widget.render_line(y).text for y in range(widget.size.height)]


def test_at_80_columns_the_blackboard_shows_values_and_types(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        value = "{header: {frame_id: world}, pose: {position: {x: 0.4}}}"
        fake.emit(
            BlackboardSnapshot(
                "Pick Object",
                1.0,
                (BlackboardEntry("Pick Object/Wait and Log::3", "grasp_pose", "Pose", value),),
            )
        )
        await pilot.pause(0.3)
        await settle(pilot)
        shown = lines(app.screen.query_one(BlackboardTable))
        assert shown[0].split() == ["Key", "Type", "Value"], shown[0]
        assert "grasp_pose" in shown[1] and "Pose" in shown[1] and "{header: {frame_id: world}" in shown[1]

    drive(fake, scenario, mode="blackboard", size=NARROW)


def test_at_80_columns_the_resolved_config_shows_value_and_set_by(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        app.screen.query_one("#config-tabs", TabbedContent).active = "resolved"
        await settle(pilot)
        table = app.screen.query_one("#resolved-table", FittedTable)
        assert table.shown_columns() == ["key", "value", "package"]
        assert table.widths[1] >= 16

    drive(fake, scenario, mode="configs", size=NARROW)


def test_at_80_columns_port_descriptions_stay(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        app.screen.query_one(TabbedContent).active = "ports"
        await settle(pilot)
        table = app.screen.query_one("#port-table", FittedTable)
        assert "description" in table.shown_columns() and "name" in table.shown_columns()
        assert table.widths[-1] >= 16

    drive(fake, scenario, size=NARROW)


def test_waypoint_positions_are_never_cut(fake: FakeConnection) -> None:
    fake.waypoints = [
        replace(w, joint_names=JOINTS, positions=(0.0, -1.5708, 0.7929)) for w in fake.waypoints
    ]
    for size in (NARROW, (120, 40)):

        async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
            table = app.screen.query_one("#joint-table", FittedTable)
            assert table.widths[1] >= len("-1.5708")
            text = "\n".join(lines(table))
            assert "-1.5708" in text and "+0.7929" in text, text

        drive(fake, scenario, mode="waypoints", size=size)


def test_at_80_columns_two_long_objective_names_can_be_told_apart(fake: FakeConnection) -> None:
    # Cut with an ellipsis, both read "Execute MTC S…"; wrapped without an indent, "Solution" read as an
    # objective of its own. A long name wraps under itself, behind its mark.
    from textual.widgets import OptionList

    from kinema.tui.connection import ObjectiveSummary

    fake.objectives = [
        ObjectiveSummary("Execute MTC Solution", runnable=False),
        ObjectiveSummary("Execute MTC Solution JTC", runnable=False),
    ]

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await settle(pilot)
        shown = [line.strip("▊▎▁▔ ") for line in lines(app.screen.query_one("#objective-list", OptionList))]
        text = [line for line in shown if line]
        assert any(line.endswith("JTC") for line in text), text
        first = next(i for i, line in enumerate(text) if line.startswith("◦ Execute"))
        assert not text[first + 1].startswith("◦"), text  # its continuation, not another objective

    drive(fake, scenario, size=NARROW)


def test_at_80_columns_the_objective_header_shows_its_package_and_file(fake: FakeConnection) -> None:
    """The header showed "kinema_objectives:" and nothing more: the absolute path wrapped out of sight."""
    fake.objectives = [
        replace(o, file_path=f"/home/someone/.venvs/robots/lib/python3.11/site-packages/kinema/{o.file_path}")
        for o in fake.objectives
    ]

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await settle(pilot)
        shown = "\n".join(lines(app.screen.query_one("#objective-description")))
        assert "lab_sim: objectives/pick_object.xml" in shown, shown

    drive(fake, scenario, size=NARROW)
