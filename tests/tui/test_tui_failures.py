"""The TUI explains a failed or cancelled run: statuses stay, the failed path is shown, the message stays."""

from __future__ import annotations

from textual.pilot import Pilot
from textual.widgets import RichLog, Static
from tui_pilot_harness import drive, settle

from kinema.tui.connection import (
    Heartbeat,
    LogEntry,
    LogLevel,
    NodeStatus,
    NodeStatusBatch,
    NodeStatusUpdate,
    RuntimeEvent,
)
from kinema.tui.dialogs.failure import FailureDialog
from kinema.tui.fake_connection import FakeConnection
from kinema.tui.widgets.behavior_tree_view import BehaviorTreeView

# Pick Object's nodes as the engine numbers them (see fake_connection._PICK_XML).
SEQUENCE = (1, "TopLevelSequence", "Sequence", "TopLevelSequence")
MOVE = (2, "MoveToWaypoint::2", "MoveToWaypoint", "")
WAIT = (3, "Wait and Log::3", "SubTree", "")
SLEEP = (5, "Wait and Log::3/Sleep::5", "Sleep", "")
FALLBACK = (7, "Fallback::7", "Fallback", "")
FAILING = (8, "AlwaysFailure::8", "AlwaysFailure", "")
SCRIPT = (9, "Script::9", "Script", "")
FAILED = (
    "objective 'Pick Object' failed (FAILURE): objective 'Pick Object' failed: node 'Script::9' [Script]: "
    "the script could not assign grasp_pose: the blackboard entry has type Pose, not std::string " * 2
).strip()


def update(node: tuple[int, str, str, str], status: NodeStatus, previous: NodeStatus = NodeStatus.IDLE):
    return NodeStatusUpdate(*node, status, previous)


async def deliver(fake: FakeConnection, pilot: Pilot[None], *events: RuntimeEvent) -> None:
    """Emit ``events`` one at a time, letting the app take each before the next (their order is the test)."""
    for event in events:
        fake.emit(event)
        await settle(pilot)


# A run's first tick: the move done, the subtree's Sleep running.
RUNNING_RUN = NodeStatusBatch(
    "Pick Object",
    (
        update(SEQUENCE, NodeStatus.RUNNING),
        update(MOVE, NodeStatus.SUCCESS),
        update(WAIT, NodeStatus.RUNNING),
        update(SLEEP, NodeStatus.RUNNING),
    ),
)

# A whole run in one batch: the script fails, the sequence with it, and both are reset.
FAILED_RUN = NodeStatusBatch(
    "Pick Object",
    (
        update(SEQUENCE, NodeStatus.RUNNING),
        update(SCRIPT, NodeStatus.FAILURE),
        update(SEQUENCE, NodeStatus.FAILURE, NodeStatus.RUNNING),
        update(SCRIPT, NodeStatus.IDLE, NodeStatus.FAILURE),
        update(SEQUENCE, NodeStatus.IDLE, NodeStatus.FAILURE),
    ),
)


def failed_run(fake: FakeConnection) -> None:
    """A run of Pick Object whose Script fails; parents reset their children to IDLE as the run ends."""
    fake.emit(Heartbeat(10.0, "Pick Object", "Running"))
    fake.emit(
        NodeStatusBatch(
            "Pick Object",
            (
                update(SEQUENCE, NodeStatus.RUNNING),
                update(MOVE, NodeStatus.SUCCESS),
                update(WAIT, NodeStatus.SUCCESS),
                update(FAILING, NodeStatus.FAILURE),
                update(SCRIPT, NodeStatus.FAILURE),
                update(FALLBACK, NodeStatus.FAILURE),
                update(SEQUENCE, NodeStatus.FAILURE, NodeStatus.RUNNING),
                update(MOVE, NodeStatus.IDLE, NodeStatus.SUCCESS),
                update(SCRIPT, NodeStatus.IDLE, NodeStatus.FAILURE),
                update(FALLBACK, NodeStatus.IDLE, NodeStatus.FAILURE),
                update(SEQUENCE, NodeStatus.IDLE, NodeStatus.FAILURE),
            ),
        )
    )
    fake.emit(Heartbeat(11.0, "Pick Object", "Failure"))
    fake.emit(LogEntry(FAILED, LogLevel.ERROR, 1.0, "objective_server"))


def detail_lines(view: BehaviorTreeView) -> list[str]:
    return [str(item.label) for item in view._details]


def test_a_failed_run_keeps_statuses_highlights_the_path_and_explains_the_node(fake: FakeConnection) -> None:
    async def scenario(app, pilot: Pilot[None]) -> None:  # type: ignore[no-untyped-def]
        failed_run(fake)
        await settle(pilot)
        view = app.screen.query_one(BehaviorTreeView)
        assert view.shown_as("Script::9") == "FAILURE"
        assert view.shown_as("Fallback::7") == "FAILURE"
        assert view.shown_as("MoveToWaypoint::2") == "SUCCESS"
        assert view.failed_path == [1, 7, 9]
        assert view.cursor_node is not None and view.cursor_node.data.path == "Script::9"
        lines = detail_lines(view)
        assert "code = grasp_pose := 'on the table'" in lines
        # The node's own message first, then where: a line cut at the edge keeps what went wrong.
        assert any(line.startswith("why: the script could not assign grasp_pose") for line in lines)
        assert any(line.startswith("at: node 'Script::9' [Script]") for line in lines)
        width = view.size.width
        assert all(len(line) + 12 <= width for line in lines if not line.startswith("code")), lines
        panel = app.screen.query_one("#failure-panel", Static)
        shown = str(panel.render())
        assert panel.has_class("shown") and "node 'Script::9'" in shown
        assert shown.index("the script could not assign") < shown.index("node 'Script::9'")
        assert "ctrl+o whole message" in shown
        # ctrl+o opens the whole message, as the runtime wrote it too; Escape closes it.
        await pilot.press("ctrl+o")
        await settle(pilot)
        assert isinstance(app.screen, FailureDialog)
        whole = " ".join(str(w.render()) for w in app.screen.query(Static))
        assert FAILED in " ".join(whole.split()) or FAILED.split(": ", 1)[1][:60] in whole
        await pilot.press("escape")
        await settle(pilot)
        assert not isinstance(app.screen, FailureDialog)
        # The failure stays: a later heartbeat (Idle) changes nothing; Escape dismisses the panel only.
        fake.emit(Heartbeat(13.0, "Pick Object", "Idle"))
        await settle(pilot)
        assert panel.has_class("shown") and view.shown_as("Script::9") == "FAILURE"
        await pilot.press("escape")
        await settle(pilot)
        assert not panel.has_class("shown")
        assert view.shown_as("Script::9") == "FAILURE", "the tree keeps explaining until the next run"
        # A new run starts clean.
        fake.emit(Heartbeat(20.0, "Pick Object", "Running"))
        await settle(pilot)
        assert view.failed_path == [] and detail_lines(view) == []
        assert view.shown_as("Script::9") == "IDLE"

    drive(fake, scenario)


def test_a_run_whose_statuses_come_before_its_heartbeat_keeps_them(fake: FakeConnection) -> None:
    """Heartbeats and node statuses are two topics: a loaded machine may deliver a quick run's statuses first.

    The run's start is then seen in its statuses (the root leaves IDLE); its late heartbeat must not wipe
    them, and a run after it still starts clean.
    """

    def statuses_then_heartbeats(start: float) -> None:
        run = NodeStatusBatch(
            "Pick Object",
            (
                update(SEQUENCE, NodeStatus.RUNNING),
                update(MOVE, NodeStatus.SUCCESS),
                update(SCRIPT, NodeStatus.FAILURE),
                update(SEQUENCE, NodeStatus.FAILURE, NodeStatus.RUNNING),
            ),
        )
        fake.emit(run)
        fake.emit(Heartbeat(start, "Pick Object", "Running"))
        fake.emit(Heartbeat(start + 0.5, "Pick Object", "Failure"))

    async def scenario(app, pilot: Pilot[None]) -> None:  # type: ignore[no-untyped-def]
        fake.emit(Heartbeat(5.0, "Pick Object", "Success"))
        for start in (10.0, 20.0):
            statuses_then_heartbeats(start)
            await settle(pilot)
            view = app.screen.query_one(BehaviorTreeView)
            assert view.shown_as("Script::9") == "FAILURE", f"the run at {start} s lost its failed node"
            assert view.shown_as("MoveToWaypoint::2") == "SUCCESS"
        # In the usual order (heartbeat first) a new run still starts clean.
        fake.emit(Heartbeat(30.0, "Pick Object", "Running"))
        await settle(pilot)
        assert view.shown_as("Script::9") == "IDLE"
        fake.emit(NodeStatusBatch("Pick Object", (update(SEQUENCE, NodeStatus.RUNNING),)))
        await settle(pilot)
        assert view.shown_as("TopLevelSequence") == "RUNNING" and view.shown_as("Script::9") == "IDLE"

    drive(fake, scenario)


def test_a_failure_whose_outcome_comes_before_the_run_itself_stays_explained(fake: FakeConnection) -> None:
    """The outcome travels on the log topic: a loaded machine may deliver it before the run's heartbeat and
    statuses (seen in CI: the failed node was marked, then wiped by the run's own late start). Late start
    signals of the run whose outcome is shown must not reset the tree; a later run still starts clean."""

    async def scenario(app, pilot: Pilot[None]) -> None:  # type: ignore[no-untyped-def]
        view = app.screen.query_one(BehaviorTreeView)
        await deliver(fake, pilot, Heartbeat(5.0, "Pick Object", "Success"))  # the run before, held
        # Outcome first, then the run's heartbeat and statuses, then its end on the heartbeat.
        await deliver(
            fake,
            pilot,
            LogEntry(FAILED, LogLevel.ERROR, 1.0, "objective_server"),
            Heartbeat(10.0, "Pick Object", "Running"),
            FAILED_RUN,
            Heartbeat(10.5, "Pick Object", "Failure"),
        )
        assert view.shown_as("Script::9") == "FAILURE"
        assert view.failed_path == [1, 7, 9]
        assert any(line.startswith("why: ") for line in detail_lines(view))
        # Outcome first again, and the whole run's statuses only after the heartbeat's end.
        fake.emit(Heartbeat(20.0, "Pick Object", "Idle"))
        await pilot.press("ctrl+r")
        await settle(pilot)
        await deliver(
            fake,
            pilot,
            LogEntry(FAILED, LogLevel.ERROR, 1.0, "objective_server"),
            Heartbeat(21.0, "Pick Object", "Failure"),
            FAILED_RUN,
        )
        assert view.shown_as("Script::9") == "FAILURE"
        assert view.failed_path == [1, 7, 9]
        # A new run, in the usual order, starts clean.
        fake.emit(Heartbeat(30.0, "Pick Object", "Running"))
        await settle(pilot)
        assert view.failed_path == [] and view.shown_as("Script::9") == "IDLE"

    drive(fake, scenario)


def test_the_run_after_one_whose_start_came_last_starts_clean(
    fake: FakeConnection,
) -> None:
    """Statuses, then the outcome, then the ended run's late start on the heartbeat: the next run's
    start must still reset the tree (the late start belonged to the run its statuses had started)."""

    async def scenario(app, pilot: Pilot[None]) -> None:  # type: ignore[no-untyped-def]
        view = app.screen.query_one(BehaviorTreeView)
        await deliver(
            fake,
            pilot,
            Heartbeat(5.0, "Pick Object", "Idle"),
            FAILED_RUN,
            LogEntry(FAILED, LogLevel.ERROR, 1.0, "objective_server"),
            Heartbeat(10.0, "Pick Object", "Running"),
            Heartbeat(10.5, "Pick Object", "Failure"),
        )
        assert view.failed_path == [1, 7, 9]
        fake.emit(Heartbeat(20.0, "Pick Object", "Idle"))
        await settle(pilot)
        fake.emit(Heartbeat(30.0, "Pick Object", "Running"))  # the next run, before any of its statuses
        await settle(pilot)
        assert view.failed_path == [] and view.shown_as("Script::9") == "IDLE"

    drive(fake, scenario)


def test_a_cancelled_run_shows_halted_nodes(fake: FakeConnection) -> None:
    async def scenario(app, pilot: Pilot[None]) -> None:  # type: ignore[no-untyped-def]
        fake.emit(Heartbeat(10.0, "Pick Object", "Running"))
        fake.emit(RUNNING_RUN)
        fake.emit(NodeStatusBatch("Pick Object", (update(SLEEP, NodeStatus.IDLE, NodeStatus.RUNNING),)))
        fake.emit(Heartbeat(11.0, "Pick Object", "Cancelled"))
        fake.emit(LogEntry("objective 'Pick Object' was cancelled: cancelled", LogLevel.WARN, 1.0))
        await settle(pilot)
        view = app.screen.query_one(BehaviorTreeView)
        assert view.shown_as("Wait and Log::3/Sleep::5") == "HALTED"
        # Nodes whose halt was never reported (the run ended) show HALTED too, not RUNNING.
        assert view.shown_as("TopLevelSequence") == "HALTED"
        assert view.shown_as("MoveToWaypoint::2") == "SUCCESS"
        assert view.failed_path == []
        panel = app.screen.query_one("#failure-panel", Static)
        assert panel.has_class("shown") and panel.has_class("cancelled")
        # Another objective runs: the box is Pick Object's, shown with Pick Object only.
        fake.emit(Heartbeat(13.0, "", "Idle"))
        fake.emit(Heartbeat(14.0, "Open Gripper", "Running"))
        await settle(pilot)
        assert panel.has_class("shown")
        await pilot.press("down")
        await settle(pilot)
        assert app.screen.selected.name == "Open Gripper" and not panel.has_class("shown")
        await pilot.press("up")
        await settle(pilot)
        assert panel.has_class("shown") and "cancelled" in str(panel.render())
        # Pick Object runs again: how its last run ended no longer describes it.
        fake.emit(Heartbeat(15.0, "Pick Object", "Running"))
        await settle(pilot)
        assert not panel.has_class("shown")

    drive(fake, scenario)


def test_halts_reported_after_the_cancellation_keep_the_nodes_shown_halted(fake: FakeConnection) -> None:
    """On a loaded machine the halt's changes (RUNNING -> IDLE) can reach the UI after the run's end."""

    async def scenario(app, pilot: Pilot[None]) -> None:  # type: ignore[no-untyped-def]
        fake.emit(Heartbeat(10.0, "Pick Object", "Running"))
        fake.emit(RUNNING_RUN)
        fake.emit(Heartbeat(11.0, "Pick Object", "Cancelled"))
        fake.emit(LogEntry("objective 'Pick Object' was cancelled: cancelled", LogLevel.WARN, 1.0))
        await settle(pilot)
        fake.emit(
            NodeStatusBatch(
                "Pick Object",
                tuple(update(node, NodeStatus.IDLE, NodeStatus.RUNNING) for node in (SLEEP, WAIT, SEQUENCE)),
            )
        )
        await settle(pilot)
        view = app.screen.query_one(BehaviorTreeView)
        assert view.shown_as("Wait and Log::3/Sleep::5") == "HALTED"
        assert view.shown_as("TopLevelSequence") == "HALTED"
        assert view.shown_as("MoveToWaypoint::2") == "SUCCESS"
        assert app.screen.query_one("#failure-panel", Static).has_class("cancelled")

    drive(fake, scenario)


def test_a_failure_whose_node_never_reported_it_is_still_shown(fake: FakeConnection) -> None:
    """An exception in a behavior ends the run before the node's FAILURE reaches the UI."""

    async def scenario(app, pilot: Pilot[None]) -> None:  # type: ignore[no-untyped-def]
        fake.emit(Heartbeat(10.0, "Pick Object", "Running"))
        fake.emit(
            NodeStatusBatch(
                "Pick Object",
                (
                    update(SEQUENCE, NodeStatus.RUNNING),
                    update(WAIT, NodeStatus.RUNNING),
                    update(SLEEP, NodeStatus.RUNNING),
                ),
            )
        )
        message = (
            "objective 'Pick Object' failed (FAILURE): "
            "Exception in node 'Wait and Log::3/Sleep::5' [Sleep]: ValueError: no clock"
        )
        fake.emit(LogEntry(message, LogLevel.ERROR, 1.0))
        await settle(pilot)
        view = app.screen.query_one(BehaviorTreeView)
        assert view.shown_as("Wait and Log::3/Sleep::5") == "FAILURE"
        # The exception escaped through its ancestors: they failed with it (BT.CPP halts none of them).
        assert view.shown_as("TopLevelSequence") == "FAILURE"
        assert view.shown_as("Wait and Log::3") == "FAILURE"
        assert view.failed_path == [1, 3, 4, 5]

    drive(fake, scenario)


def test_a_failed_run_whose_start_comes_after_its_outcome_keeps_the_failure(fake: FakeConnection) -> None:
    """An exception ends the run before its failing node reports FAILURE, and a loaded machine may
    deliver the run's first statuses (the nodes going RUNNING) after its outcome, which travels on the
    log topic (seen in CI with the tutorial's MyBehavior): they must not undo the explanation."""

    async def scenario(app, pilot: Pilot[None]) -> None:  # type: ignore[no-untyped-def]
        view = app.screen.query_one(BehaviorTreeView)
        message = (
            "objective 'Pick Object' failed (FAILURE): "
            "Exception in node 'Wait and Log::3/Sleep::5' [Sleep]: ValueError: no clock"
        )
        await deliver(
            fake,
            pilot,
            Heartbeat(10.0, "Pick Object", "Running"),
            Heartbeat(10.1, "Pick Object", "Failure"),
            LogEntry(message, LogLevel.ERROR, 1.0),
            RUNNING_RUN,
        )
        assert view.shown_as("Wait and Log::3/Sleep::5") == "FAILURE"
        assert view.failed_path == [1, 3, 4, 5]
        assert view.shown_as("MoveToWaypoint::2") == "SUCCESS"  # what the late statuses add is kept
        assert view.shown_as("TopLevelSequence") != "RUNNING"
        # The next run starts clean and shows its nodes running again.
        await deliver(fake, pilot, Heartbeat(20.0, "Pick Object", "Running"), RUNNING_RUN)
        assert view.failed_path == [] and view.shown_as("Wait and Log::3/Sleep::5") == "RUNNING"

    drive(fake, scenario)


def test_long_log_lines_wrap(fake: FakeConnection) -> None:
    async def scenario(app, pilot: Pilot[None]) -> None:  # type: ignore[no-untyped-def]
        fake.emit(LogEntry(FAILED, LogLevel.ERROR, 1.0, "objective_server"))
        await pilot.press("5")
        await settle(pilot)
        panel = app.screen.query_one(RichLog)
        assert len(FAILED) > 2 * panel.size.width
        assert len(panel.lines) >= 2, "the message is wrapped onto several lines, not cut at the edge"
        shown = "".join(line.text for line in panel.lines)
        assert "not std::string" in shown.split("std::string", 1)[1], "the end of the message is shown"

    drive(fake, scenario)


def test_a_result_box_belongs_to_the_objective_it_describes(fake: FakeConnection) -> None:
    # A new user saw another objective's "cancelled" above the selected objective's tree.
    async def scenario(app, pilot: Pilot[None]) -> None:  # type: ignore[no-untyped-def]
        assert app.screen.selected.name == "Pick Object"
        fake.emit(Heartbeat(10.0, "Open Gripper", "Running"))
        fake.emit(Heartbeat(11.0, "Open Gripper", "Failure"))
        fake.emit(LogEntry("objective 'Open Gripper' failed: node 'X' [Y]: stuck", LogLevel.ERROR, 1.0))
        await settle(pilot)
        panel = app.screen.query_one("#failure-panel", Static)
        assert not panel.has_class("shown")  # Pick Object did not fail
        await pilot.press("down")
        await settle(pilot)
        assert app.screen.selected.name == "Open Gripper"
        assert panel.has_class("shown") and str(panel.render()).splitlines()[1].startswith("stuck")

    drive(fake, scenario)


def test_a_run_on_code_whose_reload_failed_says_so_in_the_box_before_the_path(fake: FakeConnection) -> None:
    # The runtime adds a note when the tree ran behaviors whose latest file failed to load.
    message = (
        "objective 'Pick Object' failed (FAILURE): /ws/o.xml:5: Exception in node 'Script::9' [Script]: "
        "behavior 'Script' raised in tick at /ws/b.py:12: ValueError: version 1\n"
        "note: /ws/b.py:11: plugin 'p': behavior package 'p' failed to import: SyntaxError: '(' was never "
        "closed; Script runs the version from 08:01 instead"
    )

    async def scenario(app, pilot: Pilot[None]) -> None:  # type: ignore[no-untyped-def]
        fake.emit(Heartbeat(10.0, "Pick Object", "Running"))
        fake.emit(Heartbeat(11.0, "Pick Object", "Failure"))
        fake.emit(LogEntry(message, LogLevel.ERROR, 1.0))
        await settle(pilot)
        shown = str(app.screen.query_one("#failure-panel", Static).render()).splitlines()
        assert shown[1] == "ValueError: version 1"
        assert shown[2].startswith("note: /ws/b.py:11:") and "SyntaxError" in " ".join(shown[2:4])
        view = app.screen.query_one(BehaviorTreeView)
        # The exception escaped before any status was sent: its ancestors failed with it all the same.
        assert view.shown_as("Script::9") == "FAILURE" and view.shown_as("TopLevelSequence") == "FAILURE"

    drive(fake, scenario)
