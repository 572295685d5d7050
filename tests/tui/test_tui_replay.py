"""Replaying a recorded run in the TUI: step through transitions, the tree and blackboard at each moment."""

from __future__ import annotations

import asyncio
import json
from pathlib import Path

import pytest
from textual.widgets import DataTable, Static

from kinema.tui.screens.replay import ReplayApp, ReplayScreen
from kinema.tui.widgets.behavior_tree_view import BehaviorTreeView

OBJECTIVES = """<root BTCPP_format="4">
  <BehaviorTree ID="Fails">
    <Sequence name="seq">
      <Script code="a:=1; s:='text'" />
      <SubTree ID="Inner" x="{a}" />
      <Inverter name="flip"><AlwaysSuccess name="ok"/></Inverter>
      <AlwaysSuccess name="never"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Inner"><Sequence><Script code="y:=x+1"/><AlwaysSuccess/></Sequence></BehaviorTree>
</root>"""


def record_failed_run(folder: Path) -> Path:
    """Run "Fails" on an objective server with the runtime's recorder; return the .btlog it wrote."""
    from kinema.bt import BehaviorTreeFactory
    from kinema.runtime.objective_server import FactoryTreeSource, ObjectiveRequest, ObjectiveServer
    from kinema.runtime.recordings import RunRecorder, list_recordings

    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(OBJECTIVES)
    recorder = RunRecorder(folder)
    with ObjectiveServer(FactoryTreeSource(factory), listeners=[recorder], tick_rate_hz=500) as server:
        result = server.submit(ObjectiveRequest(objective_name="Fails")).wait(30)
        assert result is not None and result.failed, result
    (recording,) = list_recordings(folder)
    return recording.path


def drive_replay(path: Path, scenario) -> None:  # type: ignore[no-untyped-def]
    app = ReplayApp(path)

    async def main() -> None:
        async with app.run_test(size=(130, 36)) as pilot:
            await pilot.pause()
            await scenario(app.screen, pilot)

    asyncio.run(main())


def position_text(screen: ReplayScreen) -> str:
    return str(screen.query_one("#replay-position", Static).render())


def blackboard_rows(screen: ReplayScreen) -> set[tuple[str, ...]]:
    table = screen.query_one("#replay-entries", DataTable)
    return {tuple(str(cell) for cell in table.get_row_at(i)) for i in range(table.row_count)}


def test_stepping_through_a_recorded_failure(tmp_path: Path) -> None:
    path = record_failed_run(tmp_path)

    async def scenario(screen: ReplayScreen, pilot) -> None:  # type: ignore[no-untyped-def]
        view = screen.query_one(BehaviorTreeView)
        assert isinstance(screen, ReplayScreen) and screen.transitions > 10
        assert screen.position == 0 and "before the first transition" in position_text(screen)
        assert view.shown_as("seq") == "IDLE" and blackboard_rows(screen) == set()

        await pilot.press("right")
        await pilot.pause()
        assert screen.position == 1 and "seq → ◉ RUNNING" in position_text(screen)
        assert view.shown_as("seq") == "RUNNING"

        await pilot.press("f")  # the first FAILURE: the Inverter flips its child's SUCCESS
        await pilot.pause()
        assert "flip → ✘ FAILURE" in position_text(screen), position_text(screen)
        assert view.shown_as("flip") == "FAILURE" and view.shown_as("ok") == "SUCCESS"
        assert view.shown_as("never") == "IDLE", "the node after the failure never ran"
        # The blackboard at that moment: the Script and the subtree have written.
        rows = blackboard_rows(screen)
        assert ("Fails", "a", "int", "1") in rows and ("Fails", "s", "std::string", "text") in rows, rows
        assert any(row[0].startswith("Inner") and row[1] == "y" for row in rows), rows

        await pilot.press("end")
        await pilot.pause()
        assert screen.position == screen.transitions
        assert view.shown_as("seq") == "FAILURE", "how the run ended stays readable after the resets"
        await pilot.press("home")
        await pilot.pause()
        assert screen.position == 0 and view.shown_as("flip") == "IDLE"

    drive_replay(path, scenario)


def test_a_recording_without_blackboard_or_cut_short_still_replays(tmp_path: Path) -> None:
    from kinema.runtime.recordings import blackboard_path

    path = record_failed_run(tmp_path)
    blackboard_path(path).unlink()
    path.write_bytes(path.read_bytes()[:-4])

    async def scenario(screen: ReplayScreen, pilot) -> None:  # type: ignore[no-untyped-def]
        title = str(screen.query_one("#replay-title", Static).render())
        assert "no blackboard was recorded" in title and "cut short" in title
        await pilot.press("end")
        await pilot.pause()
        assert screen.position == screen.transitions > 0

    drive_replay(path, scenario)


def test_kinema_ui_replay_of_a_missing_file_is_one_line(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    from kinema.cli.main import main

    missing = tmp_path / "nope.btlog"
    code = main(["ui", "--replay", str(missing)])
    err = capsys.readouterr().err
    assert code == 1
    assert err.startswith("error: ") and "nope.btlog" in err and len(err.strip().splitlines()) == 1, err


def write_fixed_recording(folder: Path) -> Path:
    """A recording with fixed times and blackboard (a snapshot must not depend on the clock)."""
    from kinema.bt import BehaviorTreeFactory
    from kinema.bt.btlog import BtlogWriter
    from kinema.bt.model_xml import write_tree_to_xml
    from kinema.runtime.recordings import blackboard_path

    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(OBJECTIVES)
    tree = factory.create_tree("Fails")
    path = folder / "20261124-050000-000001-Fails.btlog"
    transitions = [(1000, 1, 1), (2000, 2, 2), (3000, 3, 1), (3500, 4, 1), (4000, 5, 2), (4500, 6, 2)]
    transitions += [(5000, 4, 2), (5500, 3, 2), (6000, 8, 2), (6500, 7, 3), (7000, 1, 3)]
    with BtlogWriter(path, write_tree_to_xml(tree), start_epoch_us=1_795_000_000_000_000) as writer:
        writer.write(transitions)
    frames = [
        {"t_us": 2000, "entries": [["Fails", "a", "int", "1"], ["Fails", "s", "std::string", "text"]]},
        {"t_us": 4000, "entries": [["Fails", "a", "int", "1"], ["Inner::3", "y", "double", "2.0"]]},
    ]
    blackboard_path(path).write_text("".join(json.dumps(f) + "\n" for f in frames))
    return path


@pytest.mark.parametrize("size", [(80, 24), (120, 40)], ids=["80x24", "120x40"])
def test_replay_snapshot(snap_compare, tmp_path: Path, size: tuple[int, int]) -> None:  # type: ignore[no-untyped-def]
    path = write_fixed_recording(tmp_path)

    async def run_before(pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.pause()
        for _ in range(10):
            await pilot.press("right")
        await pilot.pause()

    app = ReplayApp(path)
    app.title = "Kinema replay"
    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_the_app_opens_the_latest_recording_from_the_command_palette(tmp_path: Path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    from tui_pilot_harness import drive, settle

    from kinema.runtime.recordings import FOLDER_NAME
    from kinema.runtime.run_folder import RunFolder
    from kinema.tui.fake_connection import FakeConnection

    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))

    async def nothing_yet(app, pilot) -> None:  # type: ignore[no-untyped-def]
        app.action_replay_latest()
        await settle(pilot)
        assert any(text.startswith("Nothing to replay: no recordings") for text in app.shown), app.shown

    drive(FakeConnection.demo(), nothing_yet)
    folder = RunFolder.create("lab_sim").path / FOLDER_NAME
    folder.mkdir()
    write_fixed_recording(folder)

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        app.action_replay_latest()
        await settle(pilot)
        assert isinstance(app.screen, ReplayScreen) and app.screen.transitions == 11
        await pilot.press("escape")
        await settle(pilot)
        assert not isinstance(app.screen, ReplayScreen)

    drive(FakeConnection.demo(), scenario)
