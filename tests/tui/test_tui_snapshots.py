"""Snapshot tests: each screen on the demo runtime at a fixed size, with no clocks and no toasts.

Update after an intended change with ``pytest tests/tui/test_tui_snapshots.py --snapshot-update`` and look at
the SVGs (``__snapshots__/``) before committing them.
"""

from __future__ import annotations

from dataclasses import replace

import pytest
from textual.pilot import Pilot
from tui_pilot_harness import settle

from kinema.tui.app import KinemaApp
from kinema.tui.connection import (
    BlackboardEntry,
    BlackboardSnapshot,
    Heartbeat,
    LogEntry,
    LogLevel,
    NodeStatus,
    NodeStatusBatch,
    NodeStatusUpdate,
    ReloadNotice,
)
from kinema.tui.fake_connection import FakeConnection


@pytest.fixture(params=[(80, 24), (120, 40)], ids=["80x24", "120x40"])
def size(request: pytest.FixtureRequest) -> tuple[int, int]:
    """Every screen at the terminal people use (80x24) and a roomy one (120x40)."""
    return request.param  # type: ignore[no-any-return]


class QuietApp(KinemaApp):
    """The app without toasts (they time out on the wall clock, which snapshots must not depend on)."""

    def notify(self, *args: object, **kwargs: object) -> None:  # type: ignore[override]
        return None


def app_on(mode: str, fake: FakeConnection | None = None) -> tuple[QuietApp, FakeConnection]:
    fake = fake or FakeConnection.demo()
    return QuietApp(fake, initial_mode=mode), fake


def test_objectives_screen_with_a_running_tree(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    app, fake = app_on("objectives")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        fake.emit(Heartbeat(10.0, "Pick Object", "Running"))
        fake.emit(Heartbeat(12.5, "Pick Object", "Running"))
        fake.emit(
            NodeStatusBatch(
                "Pick Object",
                (
                    NodeStatusUpdate(
                        1, "TopLevelSequence", "Sequence", "TopLevelSequence", NodeStatus.RUNNING
                    ),
                    NodeStatusUpdate(2, "MoveToWaypoint::2", "MoveToWaypoint", "", NodeStatus.SUCCESS),
                    NodeStatusUpdate(3, "Wait and Log::3", "SubTree", "", NodeStatus.RUNNING),
                    NodeStatusUpdate(5, "Wait and Log::3/Sleep::5", "Sleep", "", NodeStatus.RUNNING),
                ),
            )
        )
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_objectives_parameters_tab(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    app, _ = app_on("objectives")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        await pilot.press("f4")
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_configs_screen_resolved_values(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    app, _ = app_on("configs")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        await pilot.press("up")
        await settle(pilot)
        await pilot.press("v")
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_blackboard_screen(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    app, fake = app_on("blackboard")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        for stamp, count in ((1.0, "1"), (2.0, "2"), (3.0, "3")):
            fake.emit(
                BlackboardSnapshot(
                    "Pick Object",
                    stamp,
                    (
                        BlackboardEntry("Pick Object", "count", "int", count),
                        BlackboardEntry(
                            "Pick Object",
                            "grasp_pose",
                            "PoseStamped",
                            "{header: {frame_id: world}, pose: {position: {x: 0.4, y: 0, z: 0.1}}}",
                        ),
                        BlackboardEntry("Pick Object/Wait and Log::3", "seconds", "double", "0.5"),
                    ),
                )
            )
            await pilot.pause(0.25)
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_behaviors_screen_with_a_failed_reload(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    app, fake = app_on("behaviors")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        fake.emit(
            ReloadNotice(
                False,
                "reload_failed",
                "my_behaviors",
                "my_behaviors not reloaded, keeping the last good version: invalid syntax",
                "src/my_behaviors/my_behavior.py:7",
            )
        )
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_logs_screen(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    app, fake = app_on("logs")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        fake.emit(LogEntry("[MyServiceClient] Sum: 5", LogLevel.INFO, 0.0, "runtime"))
        fake.emit(LogEntry("gripper is slow to open", LogLevel.WARN, 0.0, "runtime"))
        fake.emit(
            LogEntry(
                "Objective 'Pick Object' failed: MoveToWaypoint: no path", LogLevel.ERROR, 0.0, "runtime"
            )
        )
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_waypoints_screen(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    app, _ = app_on("waypoints")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_objectives_screen_after_a_failed_run(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    from test_tui_failures import failed_run

    app, fake = app_on("objectives")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        failed_run(fake)
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_objectives_screen_while_a_task_plans(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    from test_tui_task_planning import PLANNING

    app, fake = app_on("objectives")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        fake.emit(Heartbeat(10.0, "Pick Object", "Running"))
        fake.emit(PLANNING)
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_objectives_screen_after_a_task_failed_to_plan(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    from test_tui_task_planning import FAILED

    app, fake = app_on("objectives")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        fake.emit(Heartbeat(10.0, "Pick Object", "Running"))
        fake.emit(FAILED)
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_approval_of_a_planned_motion(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    from test_tui_approvals import PICK_STEPS

    from kinema.tui.connection import ApprovalRequested

    app, fake = app_on("objectives")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        fake.emit(
            ApprovalRequested(
                "Approve the planned motion?",
                "WaitForMTCSolutionApproval",
                "Pick from Pose With Approval/ask for approval",
                lambda *_: None,
                PICK_STEPS,
                3.88,
            )
        )
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_objectives_ports_tab(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    from textual.widgets import TabbedContent

    app, _ = app_on("objectives")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        app.screen.query_one(TabbedContent).active = "ports"
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_the_whole_failure_message(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    from test_tui_failures import failed_run

    app, fake = app_on("objectives")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        failed_run(fake)
        await settle(pilot)
        await pilot.press("ctrl+o")
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_the_quit_question(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    fake = FakeConnection.demo()
    app = QuietApp(fake, initial_mode="waypoints", owns_runtime=True)

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        await pilot.press("ctrl+q")
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_configs_screen_files(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    app, _ = app_on("configs")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        await pilot.press("i")
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


def test_waypoints_of_a_real_arm(snap_compare, size) -> None:  # type: ignore[no-untyped-def]
    # lab_sim's joint names: the positions were cut to "+" and "-" at 120 columns.
    fake = FakeConnection.demo()
    fake.waypoints = [replace(w, joint_names=LAB_SIM_JOINTS, positions=LAB_SIM_HOME) for w in fake.waypoints]
    app = QuietApp(fake, initial_mode="waypoints")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)

    assert snap_compare(app, terminal_size=size, run_before=run_before)


LAB_SIM_JOINTS = (
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
    "robotiq_85_left_knuckle_joint",
)
LAB_SIM_HOME = (0.0, -1.5708, -1.5708, 1.5708, -1.5708, -1.5708, 0.0, 0.7929)


def test_camera_screen(snap_compare, size, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    from test_tui_camera import picture

    monkeypatch.setenv("KINEMA_TUI_IMAGE", "halfcell")
    fake = FakeConnection.demo()
    fake.cameras = {"/wrist_camera/color": picture((200, 30, 30))}
    app = QuietApp(fake, initial_mode="objectives", camera="/wrist_camera/color")

    async def run_before(pilot: Pilot[None]) -> None:
        await settle(pilot)
        await pilot.pause(0.5)  # the screen redraws every 0.2 s

    assert snap_compare(app, terminal_size=size, run_before=run_before)
