"""The task panel: while PlanMTCTask plans, the Objectives screen shows the task's stages live."""

from __future__ import annotations

import asyncio
import time
from typing import Any

import pytest
import yaml
from tui_pilot_harness import SIZE, RecordingApp, drive, settle

from kinema.tui.connection import Heartbeat, TaskPlanning, TaskStage
from kinema.tui.fake_connection import FakeConnection
from kinema.tui.widgets.task_panel import TaskPanel

PLANNING = TaskPlanning(
    "pick_object",
    "Pick from Pose/PlanMTCTask",
    "planning",
    0.42,
    "",
    (
        TaskStage("current state", "CurrentState", "generator", "solved", 0.001),
        TaskStage("connect", "Connect", "connector", "planning", 0.31),
        TaskStage("move along frame axis", "MoveAlongFrameAxis", "propagator", "solved", 0.05),
        TaskStage("batch pose IK", "BatchPoseIK", "generator", "solved", 0.04, "2 solutions"),
    ),
)
FAILED = TaskPlanning(
    "pick_object",
    "Pick from Pose/PlanMTCTask",
    "failed",
    0.2,
    "task 'pick_object': stage 4 of 4 ('batch pose IK') failed: no IK solution for any of the 8 target poses",
    (
        TaskStage("current state", "CurrentState", "generator", "solved", 0.001),
        TaskStage("connect", "Connect", "connector", "waiting"),
        TaskStage("move along frame axis", "MoveAlongFrameAxis", "propagator", "waiting"),
        TaskStage(
            "batch pose IK",
            "BatchPoseIK",
            "generator",
            "failed",
            0.19,
            "no IK solution for any of the 8 target poses: pose 1 of 8: no IK solution; pose 3 of 8: no IK "
            "solution",
        ),
    ),
)


def rendered(app: Any) -> str:
    """What the panel shows, as plain text."""
    from rich.console import Console

    panel = app.screen.query_one(TaskPanel)
    if not panel.has_class("shown") or panel.planning is None:
        return ""
    from kinema.tui.widgets.task_panel import task_table

    console = Console(width=120, record=True)
    console.print(task_table(panel.planning))
    return console.export_text()


def test_the_panel_shows_each_stage_live_and_why_one_failed(fake: FakeConnection) -> None:
    async def scenario(app: Any, pilot: Any) -> None:
        assert rendered(app) == "", "the panel shows before any task is planned"
        fake.emit(Heartbeat(1.0, "Pick Object", "Running"))
        fake.emit(PLANNING)
        await settle(pilot)
        text = rendered(app)
        assert "pick_object" in text and "planning" in text, text
        rows = {line.split()[1]: line for line in text.splitlines()[2:] if line.strip()}
        assert "⟳ planning" in rows["connect"] and "0.310 s" in rows["connect"], text
        assert "✔ solved" in rows["current"] and "2 solutions" in rows["batch"], text

        fake.emit(FAILED)
        await settle(pilot)
        text = rendered(app)
        assert app.screen.query_one(TaskPanel).has_class("failed")
        assert "✘ failed" in text and "pose 3 of 8" in text, text

        # A new run starts: the last run's task is gone until this one plans.
        fake.emit(Heartbeat(2.0, "Pick Object", "Success"))
        fake.emit(Heartbeat(3.0, "Pick Object", "Running"))
        await settle(pilot)
        assert rendered(app) == "", rendered(app)

    drive(fake, scenario)


WAYPOINTS_FILE = "lab_sim_waypoints.yaml"

TASK = """
<root BTCPP_format="4" main_tree_to_execute="plan">
  <BehaviorTree ID="plan">
    <Sequence>
      <Action ID="InitializeMTCTask" task="{{mtc_task}}" task_id="{task_id}" timeout="-1" />
      <Action ID="SetupMTCCurrentState" task="{{mtc_task}}" />
      <Action ID="SetupMTCConnectWithProRRT" link_padding="0.0" task="{{mtc_task}}" />
      <Action ID="SetupMTCMoveAlongFrameAxis" axis_frame="grasp_link" axis_z="1.0" hand_frame="grasp_link"
              max_distance="0.1" min_distance="0.1" task="{{mtc_task}}" />
      <Action ID="CreatePoseStamped" reference_frame="world" position_xyz="{xyz}" orientation_xyzw="{xyzw}"
              pose_stamped="{{grasp_pose}}" />
      <Action ID="ResetPoseStampedVector" vector="{{poses}}" />
      <Action ID="PushBackVector" input_vector="{{poses}}" element="{{grasp_pose}}"
              output_vector="{{poses}}" />
      <Action ID="SetupMTCBatchPoseIK" target_poses="{{poses}}" task="{{mtc_task}}" />
      <Action ID="PlanMTCTask" solution="{{mtc_solution}}" task="{{mtc_task}}" />
    </Sequence>
  </BehaviorTree>
</root>
"""


@pytest.fixture(scope="module")
def lab_sim() -> tuple[Any, dict[str, dict[str, float]]]:
    from kinema.motion import RobotDescription
    from kinema.resources import bundled_dir

    model = RobotDescription.lab_sim().load_model()
    path = bundled_dir("configs") / "lab_sim" / "waypoints" / WAYPOINTS_FILE
    waypoints = {
        e["name"]: dict(zip(e["joint_state"]["name"], e["joint_state"]["position"], strict=True))
        for e in yaml.safe_load(path.read_text())
    }
    return model, waypoints


def test_a_real_planning_run_fills_the_panel_through_the_connection(lab_sim: Any) -> None:
    """PlanMTCTask plans a pick on lab_sim; the TUI's SdkConnection carries its progress to the panel."""
    from scipy.spatial.transform import Rotation

    from kinema.behaviors import BehaviorContext
    from kinema.bt import NodeStatus
    from kinema.config import resolve_config
    from kinema.motion import fk
    from kinema.plugins import BehaviorHost
    from kinema.testing import publish_repeatedly, run_objective
    from kinema.transport import Node, free_endpoint, host_router, open_session
    from kinema.tui.sdk_connection import SdkConnection

    model, waypoints = lab_sim
    # The grasp: where the pick waypoint puts the gripper (from FK, so it holds in any world frame).
    grasp = fk(model, model.configuration(waypoints["3 Waypoint Pick Pose"]), "grasp_link")
    xyz = ";".join(f"{v:.6f}" for v in grasp[:3, 3])
    xyzw = ";".join(f"{v:.8f}" for v in Rotation.from_matrix(grasp[:3, :3]).as_quat())
    start = waypoints["Look at Table"]
    host = BehaviorHost(["kinema::CoreBehaviorsLoader"])
    host.load().raise_for_errors()

    endpoint = free_endpoint()
    router = host_router(endpoint)
    session = open_session(endpoint)
    node = Node(session, "task_panel_test")
    context = BehaviorContext(node, robot_model=model, config=resolve_config("lab_sim"))
    connection = SdkConnection(endpoint, config="lab_sim")
    app = RecordingApp(connection, initial_mode="objectives")
    runs: list[Any] = []

    def plan(task_id: str, where: str) -> None:
        xml = TASK.format(task_id=task_id, xyz=where, xyzw=xyzw)
        runs.append(run_objective(xml, registry=host.registry, context=context, timeout=120.0))

    async def until(condition: Any, pilot: Any, seconds: float) -> bool:
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            if condition():
                return True
            await pilot.pause(0.1)
        return condition()

    async def main() -> None:
        async with app.run_test(size=SIZE) as pilot:
            await settle(pilot)
            assert await until(lambda: connection._client is not None, pilot, 60.0), "never joined the router"
            joints = {"name": list(start), "position": list(start.values())}
            with publish_repeatedly(node, "sensor_msgs/msg/JointState", "/joint_states", joints):
                # The TUI's subscription reaches the planner's publisher through the router a moment after
                # it is declared; plan again (at most 3 times) until a run's progress arrived.
                for attempt in range(3):
                    await asyncio.to_thread(plan, f"pick {attempt}", xyz)
                    assert runs[-1].status == NodeStatus.SUCCESS, runs[-1].toasts
                    if await until(
                        lambda a=attempt: (
                            (t := app.task_planning) is not None
                            and t.task_id == f"pick {a}"
                            and t.state == "solved"
                        ),
                        pilot,
                        10.0,
                    ):
                        break
                task = app.task_planning
                assert task is not None and task.state == "solved", f"the panel got {task}"
                assert [s.name for s in task.stages] == [
                    "current state",
                    "connect",
                    "move along frame axis",
                    "batch pose IK",
                ]
                assert all(s.state == "solved" for s in task.stages), task.stages
                assert task.stages[1].type == "Connect" and task.stages[1].seconds > 0, task.stages
                assert "PlanMTCTask" in task.node_path, task.node_path
                await settle(pilot)
                text = rendered(app)
                assert "✔ solved" in text and task.task_id in text, text

                # A task that cannot be planned: the panel names the stage and why.
                await asyncio.to_thread(plan, "unreachable", "4.0;3.0;0.8")
                assert runs[-1].status == NodeStatus.FAILURE
                assert await until(
                    lambda: (t := app.task_planning) is not None and t.state == "failed", pilot, 10.0
                ), app.task_planning
                await settle(pilot)
                task = app.task_planning
                assert task.stages[3].state == "failed" and "pose 1 of 1" in task.stages[3].comment, task
                assert "('batch pose IK')" in task.message, task.message
                text = " ".join(rendered(app).split())  # the note wraps
                assert "✘ failed" in text and "pose 1 of 1" in text, text

    try:
        asyncio.run(main())
    finally:
        context.close()
        session.close()
        router.close()
