"""A behavior's approval question appears as a dialog in the TUI, and the user's answer goes back."""

from __future__ import annotations

from typing import Any

import pytest
from tui_pilot_harness import drive, settle

from kinema.tui.connection import ApprovalRequested, SolutionStep
from kinema.tui.dialogs.approval import ApprovalDialog
from kinema.tui.dialogs.confirm import ConfirmDialog
from kinema.tui.fake_connection import FakeConnection


def test_the_user_approves_or_declines_in_a_dialog(fake: FakeConnection) -> None:
    answers: list[tuple[bool, str]] = []

    def ask(prompt: str) -> ApprovalRequested:
        return ApprovalRequested(
            prompt, "WaitForMTCSolutionApproval", "Main/Approve", lambda *a: answers.append(a)
        )

    async def scenario(app: Any, pilot: Any) -> None:
        fake.emit(ask("Approve the planned motion?"))
        await settle(pilot)
        assert isinstance(app.screen, ConfirmDialog)
        assert "Approve the planned motion?" in app.screen.question
        assert "WaitForMTCSolutionApproval at Main/Approve" in app.screen.question
        await pilot.press("y")  # a printable key never lets the robot move
        await settle(pilot)
        assert answers == [] and isinstance(app.screen, ConfirmDialog)
        keys = " ".join(str(label.render()) for label in app.screen.query(".dialog-keys"))
        assert "ctrl+y: Approve" in keys and "n or Esc: Reject" in keys
        await pilot.press("ctrl+y")
        await settle(pilot)
        assert answers == [(True, "")]
        fake.emit(ask("Breakpoint at Main/Stop: resume?"))
        await settle(pilot)
        await pilot.press("n")
        await settle(pilot)
        assert answers[-1] == (False, "declined in the TUI")
        assert not isinstance(app.screen, ConfirmDialog)

    drive(fake, scenario)


def test_an_attached_tui_is_the_user_the_approval_behaviors_ask(monkeypatch: Any) -> None:
    """End to end over a router: the TUI's connection serves the approval service; a behavior asks it."""
    from kinema.behaviors import BehaviorContext
    from kinema.bt import NodeStatus
    from kinema.plugins import BehaviorHost
    from kinema.testing import tick_behavior
    from kinema.transport import Node, free_endpoint, host_router, open_session
    from kinema.tui.sdk_connection import SdkConnection

    monkeypatch.delenv("KINEMA_AUTO_APPROVE", raising=False)
    endpoint = free_endpoint()
    router = host_router(endpoint)
    connection = SdkConnection(endpoint, config="lab_sim")
    asked: list[str] = []

    def listener(event: Any) -> None:
        if isinstance(event, ApprovalRequested):
            asked.append(event.prompt)
            event.answer(False, "not now")

    session = open_session(endpoint)
    try:
        connection.open(listener)
        node = Node(session, "approval_test")
        client = node.create_client("kinema_msgs/srv/RequestApproval", "/kinema/user_approval")
        assert client.wait_for_service(20.0), "the TUI connection did not serve /kinema/user_approval"
        host = BehaviorHost(["kinema::CoreBehaviorsLoader"])
        host.load().raise_for_errors()
        context = BehaviorContext(node)
        available = tick_behavior(host.registry["IsUserAvailable"].cls, {}, context=context)
        assert available.status == NodeStatus.SUCCESS
        run = tick_behavior(
            host.registry["WaitForMTCSolutionApproval"].cls, {"solution": "plan"}, context=context
        )
        assert asked == ["Approve the planned motion?"]
        assert run.status == NodeStatus.FAILURE and "rejected by the user: not now" in run.toasts[-1]
        context.close()
    finally:
        connection.close()
        session.close()
        router.close()


PICK_STEPS = (
    SolutionStep("connect", 2.41, ("linear_rail_joint", "shoulder_pan_joint", "shoulder_lift_joint")),
    SolutionStep("touch the cube", 0.0, (), "", "collisions allowed: gripper - cube"),
    SolutionStep(
        "close gripper",
        0.62,
        ("robotiq_85_left_knuckle_joint",),
        "robotiq_85_left_knuckle_joint 0.000 -> 0.793 (closes)",
    ),
    SolutionStep("lift", 0.85, ("linear_rail_joint", "shoulder_pan_joint", "shoulder_lift_joint")),
)


def test_a_motion_to_approve_is_listed_step_by_step(fake: FakeConnection) -> None:
    answers: list[tuple[bool, str]] = []

    async def scenario(app: Any, pilot: Any) -> None:
        fake.emit(
            ApprovalRequested(
                "Approve the planned motion?",
                "WaitForMTCSolutionApproval",
                "Pick/Approve",
                lambda *a: answers.append(a),
                PICK_STEPS,
                3.88,
            )
        )
        await settle(pilot)
        assert isinstance(app.screen, ApprovalDialog)
        text = " ".join(rendered_steps(app.screen).split())
        for expected in (
            "connect",
            "2.41 s",
            "collisions allowed: gripper - cube",
            "close gripper",
            "0.000 -> 0.793 (closes)",
            "lift",
            "3 motions, 3.88 s in all",
        ):
            assert expected in text, text
        assert "the gripper moves in 1 of them" in text, text
        await pilot.press("ctrl+y")
        await settle(pilot)
        assert answers == [(True, "")]

    drive(fake, scenario)


def rendered_steps(dialog: ApprovalDialog) -> str:
    from rich.console import Console

    from kinema.tui.dialogs.approval import steps_table

    console = Console(width=100, record=True)
    console.print(steps_table(dialog.steps, dialog.duration))
    return console.export_text()


def test_approving_a_planned_task_shows_its_motions_and_draws_it_in_the_view(monkeypatch: Any) -> None:
    """Over a router: WaitForMTCSolutionApproval with an MTC solution sends its motions to the TUI's
    connection and publishes the motion and the stages' tool paths for kinema view before the answer."""
    import threading

    import numpy as np
    import yaml

    from kinema.behaviors import BehaviorContext
    from kinema.bt import NodeStatus
    from kinema.motion import CollisionChecker, RobotDescription
    from kinema.motion.task import Task, plan_task
    from kinema.motion.task_stages import (
        AllowCollisions,
        CurrentState,
        MotionSettings,
        MoveAlongFrameAxis,
        PlanToJointState,
    )
    from kinema.plugins import BehaviorHost
    from kinema.resources import bundled_dir
    from kinema.testing import tick_behavior
    from kinema.transport import Node, free_endpoint, host_router, open_session
    from kinema.tui.sdk_connection import SdkConnection
    from kinema.ui_topics import MARKER_ARRAY_TOPIC, MARKER_ARRAY_TYPE, PLANNED_TRAJECTORY_TOPIC

    monkeypatch.delenv("KINEMA_AUTO_APPROVE", raising=False)
    model = RobotDescription.lab_sim().load_model()
    path = bundled_dir("configs") / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml"
    entry = next(e for e in yaml.safe_load(path.read_text()) if e["name"] == "Look at Table")
    joints = entry["joint_state"]
    start = model.configuration(dict(zip(joints["name"], joints["position"], strict=True)))
    closed = model.semantic.group_states[("gripper", "close")]
    solution = plan_task(
        Task(
            "grab",
            [
                CurrentState(start),
                AllowCollisions(["gripper"], ["wrist_3_link"], name="allow"),
                PlanToJointState(closed, MotionSettings(group="gripper"), name="close gripper"),
                MoveAlongFrameAxis(
                    (0, 0, 1),
                    "world",
                    "grasp_link",
                    0.05,
                    0.05,
                    MotionSettings(group="manipulator", link_padding=0.0),
                    name="lift",
                ),
            ],
        ),
        CollisionChecker(model),
    )

    endpoint = free_endpoint()
    router = host_router(endpoint)
    connection = SdkConnection(endpoint, config="lab_sim")
    asked: list[ApprovalRequested] = []
    drawn: list[Any] = []
    markers: list[Any] = []
    drawn_before_answer: list[bool] = []
    got_markers = threading.Event()

    def listener(event: Any) -> None:
        if isinstance(event, ApprovalRequested):
            asked.append(event)
            # The view has the motion while the question is open (published before asking).
            drawn_before_answer.append(bool(drawn) and got_markers.wait(10.0))
            event.answer(True, "")

    session = open_session(endpoint)
    try:
        node = Node(session, "approval_view_test")
        node.create_subscription(
            "trajectory_msgs/msg/JointTrajectory", PLANNED_TRAJECTORY_TOPIC, drawn.append
        )

        def keep_markers(message: Any) -> None:
            markers.append(message)
            got_markers.set()

        node.create_subscription(MARKER_ARRAY_TYPE, MARKER_ARRAY_TOPIC, keep_markers)
        connection.open(listener)
        client = node.create_client("kinema_msgs/srv/RequestApproval", "/kinema/user_approval")
        assert client.wait_for_service(20.0), "the TUI connection did not serve /kinema/user_approval"
        host = BehaviorHost(["kinema::CoreBehaviorsLoader"])
        host.load().raise_for_errors()
        context = BehaviorContext(node, robot_model=model)
        run = tick_behavior(
            host.registry["WaitForMTCSolutionApproval"].cls, {"solution": solution}, context=context
        )
        assert run.status == NodeStatus.SUCCESS, run.toasts
        assert len(asked) == 1
        request = asked[0]
        assert [s.stage for s in request.steps] == ["allow", "close gripper", "lift"]
        assert request.steps[0].note == "collisions allowed: gripper - wrist_3_link", request.steps
        assert request.steps[1].gripper.endswith("(closes)"), request.steps
        assert request.steps[1].joint_names == ("robotiq_85_left_knuckle_joint",)
        assert request.steps[2].gripper == "" and request.steps[2].note == "", request.steps
        assert request.duration == pytest.approx(solution.joined().duration, rel=1e-6)
        assert drawn_before_answer == [True], (len(drawn), len(markers))
        last = drawn[-1]
        names = [str(n) for n in last.joint_names]
        end = [solution.end[model.index(n)] for n in names]
        np.testing.assert_allclose(list(last.points[-1].positions), end, atol=1e-6)
        lines = [m.text for a in markers for m in a.markers if m.ns == "mtc_solution" and m.action == 0]
        assert "lift" in lines, lines
        context.close()
    finally:
        connection.close()
        session.close()
        router.close()
