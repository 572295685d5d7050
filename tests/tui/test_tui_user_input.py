"""What only the user can give a running objective, asked in the TUI: a pose, joint values, points on a
camera image, a teleoperation session; the answer goes back to the behavior that asked."""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import pytest
from tui_pilot_harness import drive, settle

from kinema.tui.connection import UserInputAnswer, UserInputRequested
from kinema.tui.dialogs.user_input import JointStateDialog, PointsDialog, PoseDialog, TeleoperateDialog
from kinema.tui.fake_connection import FakeConnection


def _request(kind: str, answers: list[UserInputAnswer], **fields: Any) -> UserInputRequested:
    return UserInputRequested(
        kind, f"a {kind} question", "SomeBehavior", "Main/Ask", answers.append, **fields
    )


def test_a_pose_is_given_in_a_form_that_starts_at_the_tool(fake: FakeConnection) -> None:
    answers: list[UserInputAnswer] = []

    async def scenario(app: Any, pilot: Any) -> None:
        fake.emit(_request("pose", answers, position=(0.1, 0.5, 0.9), orientation=(0.0, 1.0, 0.0, 0.0)))
        await settle(pilot)
        assert isinstance(app.screen, PoseDialog)
        position = app.screen.query_one("#pose-position")
        assert position.value == "0.1 0.5 0.9"
        assert app.screen.query_one("#pose-orientation").value == "0 1 0 0"
        position.value = "0.2 nonsense"
        await pilot.click("#ok")
        await settle(pilot)
        assert answers == [] and isinstance(app.screen, PoseDialog), "a bad position is refused, not sent"
        position.value = "0.2, 0.6, 0.8"
        ok = app.screen.query_one("#ok")
        while ok.has_class("-active"):  # a Button ignores clicks while it still shows the last one (0.2 s)
            await pilot.pause(0.05)
        await pilot.click("#ok")
        await settle(pilot)
        (answer,) = answers
        assert answer.accepted and answer.frame_id == "world"
        assert answer.position == (0.2, 0.6, 0.8) and answer.orientation == (0.0, 1.0, 0.0, 0.0)
        fake.emit(_request("pose", answers))
        await settle(pilot)
        await pilot.press("escape")
        await settle(pilot)
        assert not answers[-1].accepted and not isinstance(app.screen, PoseDialog)

    drive(fake, scenario)


def test_joint_values_are_given_in_a_form_that_starts_where_the_joints_are(fake: FakeConnection) -> None:
    answers: list[UserInputAnswer] = []
    joints = {"joint_names": ("elbow_joint", "wrist_1_joint"), "joint_positions": (1.9, -1.57)}

    async def scenario(app: Any, pilot: Any) -> None:
        fake.emit(_request("joint_state", answers, **joints))
        await settle(pilot)
        assert isinstance(app.screen, JointStateDialog)
        elbow, wrist = app.screen.query_one("#joint-0"), app.screen.query_one("#joint-1")
        assert (elbow.value, wrist.value) == ("1.9", "-1.57")
        wrist.value = "a lot"
        await pilot.click("#ok")
        await settle(pilot)
        assert answers == [] and isinstance(app.screen, JointStateDialog), "a bad value is refused, not sent"
        wrist.value = "-1.2"
        app.screen.set_focus(wrist)
        await pilot.press("enter")
        await settle(pilot)
        (answer,) = answers
        assert answer.accepted and answer.joint_positions == (1.9, -1.2)
        fake.emit(_request("joint_state", answers, **joints))
        await settle(pilot)
        await pilot.press("escape")
        await settle(pilot)
        assert not answers[-1].accepted and not isinstance(app.screen, JointStateDialog)

    drive(fake, scenario)


def test_points_are_clicked_on_the_image_or_typed(fake: FakeConnection) -> None:
    answers: list[UserInputAnswer] = []
    fake.cameras["/wrist_camera/color"] = np.zeros((480, 640, 3), dtype=np.uint8)

    async def scenario(app: Any, pilot: Any) -> None:
        fake.emit(
            _request(
                "points",
                answers,
                image_topic="/wrist_camera/color",
                point_prompts=("Click the tag", "Click the bottle"),
                point_names=("tag", "bottle"),
            )
        )
        await settle(pilot)
        assert isinstance(app.screen, PointsDialog)
        await pilot.pause(0.5)
        caption = str(app.screen.query_one("#points-caption").render())
        assert "640 x 480 pixels" in caption, caption
        pictures = list(app.screen.query("#points-picture"))
        if pictures:  # a terminal that draws images: a click on its middle is the image's middle
            picture = pictures[0]
            await pilot.click("#points-picture", offset=(picture.size.width // 2, picture.size.height // 2))
            await settle(pilot)
            column, row = (float(v) for v in app.screen.query_one("#point-0").value.split())
            assert abs(column - 320) <= 640 / picture.size.width + 1
            assert abs(row - 240) <= 480 / picture.size.height + 1
        else:
            app.screen.query_one("#point-0").value = "320 240"
        app.screen.query_one("#point-1").value = "10 20"
        await pilot.click("#ok")
        await settle(pilot)
        (answer,) = answers
        assert answer.accepted and len(answer.points) == 2 and answer.points[1] == (10.0, 20.0)
        assert ("stop_watching_images", "/wrist_camera/color") in fake.calls, "one still image is enough"

    drive(fake, scenario)


def test_a_teleoperation_session_sends_the_modes_the_user_picks_until_done(fake: FakeConnection) -> None:
    answers: list[UserInputAnswer] = []

    async def scenario(app: Any, pilot: Any) -> None:
        fake.emit(_request("teleoperate", answers, initial_teleop_mode=4))
        await settle(pilot)
        assert isinstance(app.screen, TeleoperateDialog) and app.teleoperating
        await pilot.click("#teleop-close")
        await settle(pilot)
        await pilot.pause(0.2)
        assert fake.called("set_teleoperation_mode") == [(7,)]
        # Moving to a pose: the objective asks for the pose; declining it ends that mode.
        await pilot.click("#teleop-pose")
        await settle(pilot)
        fake.emit(_request("pose", answers))
        await settle(pilot)
        assert isinstance(app.screen, PoseDialog)
        await pilot.press("escape")
        await settle(pilot)
        await pilot.pause(0.2)
        assert fake.called("set_teleoperation_mode") == [(7,), (4,), (0,)]
        assert isinstance(app.screen, TeleoperateDialog)
        # Moving to joint values: the same, with the joint values form.
        await pilot.click("#teleop-joints")
        await settle(pilot)
        fake.emit(_request("joint_state", answers, joint_names=("elbow_joint",), joint_positions=(1.9,)))
        await settle(pilot)
        assert isinstance(app.screen, JointStateDialog)
        await pilot.press("escape")
        await settle(pilot)
        await pilot.pause(0.2)
        assert fake.called("set_teleoperation_mode") == [(7,), (4,), (0,), (5,), (0,)]
        assert isinstance(app.screen, TeleoperateDialog)
        await pilot.press("ctrl+d")
        await settle(pilot)
        assert answers[-1].accepted and not app.teleoperating
        assert not isinstance(app.screen, TeleoperateDialog)

    drive(fake, scenario)


@pytest.mark.parametrize("kind", ["points", "teleoperate", "joint_state"])
def test_an_attached_tui_is_the_user_the_input_behaviors_ask(monkeypatch: Any, kind: str) -> None:
    """End to end over a router: the TUI's connection serves /kinema/user_input; a behavior asks it."""
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
    asked: list[UserInputRequested] = []

    def listener(event: Any) -> None:
        if isinstance(event, UserInputRequested):
            asked.append(event)
            if event.kind == "teleoperate":
                connection.set_teleoperation_mode(6)
                time.sleep(0.5)  # the mode reaches the behavior before the session ends
            if event.kind == "joint_state":
                assert event.joint_names == ("elbow_joint", "wrist_1_joint")
                assert event.joint_positions == (1.9, -1.57)
                event.answer(UserInputAnswer(True, joint_positions=(1.5, -1.2)))
                return
            event.answer(UserInputAnswer(True, points=((12.0, 34.0),)))

    session = open_session(endpoint)
    try:
        connection.open(listener)
        node = Node(session, "user_input_test")
        client = node.create_client("kinema_msgs/srv/RequestUserInput", "/kinema/user_input")
        assert client.wait_for_service(20.0), "the TUI connection did not serve /kinema/user_input"
        host = BehaviorHost(["kinema::CoreBehaviorsLoader"])
        host.load().raise_for_errors()
        from kinema.config import resolve_config

        context = BehaviorContext(node, config=resolve_config("lab_sim"))  # names the camera to click on
        if kind == "teleoperate":
            run = tick_behavior(
                host.registry["DoTeleoperateAction"].cls, {"initial_teleop_mode": 4}, context=context
            )
            assert run.status == NodeStatus.SUCCESS, run.toasts
            assert run.outputs["current_teleop_mode"] == 6
        elif kind == "joint_state":
            from kinema.testing import publish_repeatedly

            # Without a robot model the question covers every joint /joint_states names.
            state = {"name": ["elbow_joint", "wrist_1_joint"], "position": [1.9, -1.57]}
            with publish_repeatedly(node, "sensor_msgs/msg/JointState", "/joint_states", state):
                run = tick_behavior(host.registry["RetrieveRobotStateParameter"].cls, {}, context=context)
            assert run.status == NodeStatus.SUCCESS, run.toasts
            answer = run.outputs["joint_state"]
            assert list(answer.name) == ["elbow_joint", "wrist_1_joint"] and list(answer.position) == [
                1.5,
                -1.2,
            ]
        else:
            run = tick_behavior(
                host.registry["GetPointsFromUser"].cls, {"point_prompts": "here"}, context=context
            )
            assert run.status == NodeStatus.SUCCESS, run.toasts
            assert [(p.point.x, p.point.y) for p in run.outputs["pixel_coords"]] == [(12.0, 34.0)]
        assert [event.kind for event in asked] == [kind]
        context.close()
    finally:
        connection.close()
        session.close()
        router.close()
