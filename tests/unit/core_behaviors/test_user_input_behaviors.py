"""RetrievePoseParameter, RetrieveRobotStateParameter, GetPointsFromUser and DoTeleoperateAction: a UI
serving /kinema/user_input answers them; headless they follow the approvals' rule (fail, or answer as a
user who changes nothing when approvals are granted automatically). CreateBoundingBoxFromOffset: the
exemplar image's box."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import publish_repeatedly, tick_behavior
from kinema.transport import from_dict

ARM = [
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
]
HOME = [0.0, 0.0, -2.0, 2.0, -1.5708, -1.5708, 0.0]


@pytest.fixture
def at_home(context: BehaviorContext) -> Iterator[None]:
    state = {"name": [*ARM, "robotiq_85_left_knuckle_joint"], "position": [*HOME, 0.0]}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        yield


@pytest.fixture
def headless(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("KINEMA_AUTO_APPROVE", raising=False)


@pytest.fixture
def auto_approve(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("KINEMA_AUTO_APPROVE", "1")


class FakeUi:
    """Serves /kinema/user_input as the TUI does, answering each request with ``answer(request)``."""

    def __init__(self, context: BehaviorContext, answer: Any) -> None:
        self.requests: list[Any] = []
        self._answer = answer
        context.node.create_service("kinema_msgs/srv/RequestUserInput", "/kinema/user_input", self._serve)

    def _serve(self, request: Any) -> dict[str, Any]:
        self.requests.append(request)
        return self._answer(request)


def _pose(x: float, y: float, z: float) -> dict[str, Any]:
    return {"header": {"frame_id": "world"}, "pose": {"position": {"x": x, "y": y, "z": z}}}


# -- RetrievePoseParameter -----------------------------------------------------------------------------


def test_retrieve_pose_parameter_takes_the_users_pose(
    behavior: Any, context: BehaviorContext, at_home: None, headless: None
) -> None:
    ui = FakeUi(context, lambda request: {"accepted": True, "pose": _pose(0.1, 0.6, 0.7)})
    run = tick_behavior(behavior("RetrievePoseParameter"), {}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    position = run.outputs["pose"].pose.position
    assert [position.x, position.y, position.z] == pytest.approx([0.1, 0.6, 0.7])
    (request,) = ui.requests
    assert request.kind == "pose" and request.behavior == "RetrievePoseParameter"
    # The form starts at the tool frame (grasp_link) where it is now.
    from kinema.motion import fk

    q = np.zeros(len(context.robot_model.joint_names))
    q[[context.robot_model.joint_names.index(j) for j in ARM]] = HOME
    expected = fk(context.robot_model, q, "grasp_link")[:3, 3]
    start = request.initial_pose.pose.position
    assert [start.x, start.y, start.z] == pytest.approx(expected.tolist(), abs=1e-3)


def test_retrieve_pose_parameter_fails_when_the_user_cancels(
    behavior: Any, context: BehaviorContext, at_home: None, headless: None
) -> None:
    FakeUi(context, lambda request: {"accepted": False, "message": "changed my mind"})
    run = tick_behavior(behavior("RetrievePoseParameter"), {}, context=context)
    assert run.status == NodeStatus.FAILURE and "gave no pose: changed my mind" in run.toasts[-1]


def test_retrieve_pose_parameter_headless(
    behavior: Any, context: BehaviorContext, at_home: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("KINEMA_AUTO_APPROVE", raising=False)
    refused = tick_behavior(behavior("RetrievePoseParameter"), {}, context=context)
    assert refused.status == NodeStatus.FAILURE
    assert "no user interface is attached to give a pose" in refused.toasts[-1]
    assert "--auto-approve" in refused.toasts[-1]
    monkeypatch.setenv("KINEMA_AUTO_APPROVE", "1")
    granted = tick_behavior(behavior("RetrievePoseParameter"), {}, context=context)
    assert granted.status == NodeStatus.SUCCESS and "answered automatically" in granted.toasts[-1]
    assert granted.outputs["pose"].header.frame_id == "world"


# -- RetrieveRobotStateParameter -------------------------------------------------------------------------

TARGET = [0.2, 0.1, -1.8, 1.7, -1.4, -1.5708, 0.3]


def _joint_answer(names: list[str], positions: list[float]) -> dict[str, Any]:
    return {"accepted": True, "joint_state": {"name": names, "position": positions}}


def test_retrieve_robot_state_parameter_takes_the_users_joint_values(
    behavior: Any, context: BehaviorContext, at_home: None, headless: None
) -> None:
    ui = FakeUi(context, lambda request: _joint_answer(ARM, TARGET))
    run = tick_behavior(
        behavior("RetrieveRobotStateParameter"), {"command_type": "joint_slider"}, context=context
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    state = run.outputs["joint_state"]
    assert list(state.name) == ARM and list(state.position) == pytest.approx(TARGET)
    (request,) = ui.requests
    assert request.kind == "joint_state" and request.behavior == "RetrieveRobotStateParameter"
    assert "joint slider" in request.prompt
    # The form starts at the planning group's joints (lab_sim: manipulator, no gripper) where they are now.
    assert list(request.initial_joint_state.name) == ARM
    assert list(request.initial_joint_state.position) == pytest.approx(HOME)


@pytest.mark.parametrize(
    ("answer", "said"),
    [
        ({"accepted": False, "message": "not now"}, "the user gave no joint values: not now"),
        (_joint_answer([*ARM[:6], "wrist_3_jiont"], TARGET), "joints that were not asked: wrist_3_jiont"),
        (_joint_answer(ARM, TARGET[:3]), "7 names and 3 positions"),
    ],
)
def test_retrieve_robot_state_parameter_fails_on_a_cancel_or_a_wrong_answer(
    behavior: Any, context: BehaviorContext, at_home: None, headless: None, answer: dict[str, Any], said: str
) -> None:
    FakeUi(context, lambda request: answer)
    run = tick_behavior(behavior("RetrieveRobotStateParameter"), {}, context=context)
    assert run.status == NodeStatus.FAILURE and said in run.toasts[-1], run.toasts


def test_retrieve_robot_state_parameter_names_the_valid_command_types(
    behavior: Any, context: BehaviorContext, at_home: None, headless: None
) -> None:
    run = tick_behavior(behavior("RetrieveRobotStateParameter"), {"command_type": "slider"}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert "'slider'" in run.toasts[-1] and "waypoint, joint_slider, interactive_marker" in run.toasts[-1]


def test_retrieve_robot_state_parameter_headless(
    behavior: Any, context: BehaviorContext, at_home: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("KINEMA_AUTO_APPROVE", raising=False)
    refused = tick_behavior(behavior("RetrieveRobotStateParameter"), {}, context=context)
    assert refused.status == NodeStatus.FAILURE
    assert "no user interface is attached to give joint values" in refused.toasts[-1]
    assert "--auto-approve" in refused.toasts[-1]
    monkeypatch.setenv("KINEMA_AUTO_APPROVE", "1")
    granted = tick_behavior(behavior("RetrieveRobotStateParameter"), {}, context=context)
    assert granted.status == NodeStatus.SUCCESS and "answered automatically" in granted.toasts[-1]
    # A user who changes nothing: the joints where they are.
    state = granted.outputs["joint_state"]
    assert list(state.name) == ARM and list(state.position) == pytest.approx(HOME)


def test_the_former_name_retrieve_joint_state_parameter_runs_with_its_ports(
    registry: Any, context: BehaviorContext, at_home: None, auto_approve: None
) -> None:
    from kinema.testing import run_objective

    xml = """<root BTCPP_format="4"><BehaviorTree ID="T">
        <Action ID="RetrieveJointStateParameter" timeout_sec="-1" joint_state="{target_joint_state}"/>
        </BehaviorTree></root>"""
    run = run_objective(xml, registry=registry, context=context)
    assert run.status == NodeStatus.SUCCESS
    assert list(run.blackboard["target_joint_state"].position) == pytest.approx(HOME)


# -- GetPointsFromUser ------------------------------------------------------------------------------------

POINTS_INPUTS = {
    "view_name": "/wrist_camera/color",
    "point_prompts": "Click the tag;Click the bottle",
    "point_names": "tag;bottle",
}


def test_get_points_from_user_writes_the_clicked_pixels(
    behavior: Any, context: BehaviorContext, headless: None
) -> None:
    ui = FakeUi(
        context,
        lambda request: {"accepted": True, "points": [{"x": 10.0, "y": 20.0}, {"x": 300.0, "y": 200.0}]},
    )
    run = tick_behavior(behavior("GetPointsFromUser"), POINTS_INPUTS, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    points = run.outputs["pixel_coords"]
    assert [(p.header.frame_id, p.point.x, p.point.y) for p in points] == [
        ("tag", 10.0, 20.0),
        ("bottle", 300.0, 200.0),
    ]
    (request,) = ui.requests
    assert request.kind == "points" and request.image_topic == "/wrist_camera/color"
    assert list(request.point_prompts) == ["Click the tag", "Click the bottle"]


def test_get_points_from_user_headless(
    behavior: Any, context: BehaviorContext, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("KINEMA_AUTO_APPROVE", raising=False)
    refused = tick_behavior(behavior("GetPointsFromUser"), POINTS_INPUTS, context=context)
    assert refused.status == NodeStatus.FAILURE
    assert "no user interface is attached to click points on /wrist_camera/color" in refused.toasts[-1]
    monkeypatch.setenv("KINEMA_AUTO_APPROVE", "1")
    image = {"header": {"frame_id": "cam"}, "height": 480, "width": 640, "encoding": "rgb8", "step": 1920}
    with publish_repeatedly(context.node, "sensor_msgs/msg/Image", "/wrist_camera/color", image):
        granted = tick_behavior(behavior("GetPointsFromUser"), POINTS_INPUTS, context=context)
    assert granted.status == NodeStatus.SUCCESS and "image's centre" in granted.toasts[-1]
    assert [(p.point.x, p.point.y) for p in granted.outputs["pixel_coords"]] == [(320.0, 240.0)] * 2


# -- DoTeleoperateAction ----------------------------------------------------------------------------------


def test_do_teleoperate_action_follows_the_users_modes_until_done(
    behavior: Any, context: BehaviorContext, headless: None
) -> None:
    """The UI publishes the modes the user picks while the session is open, then answers."""
    mode_publisher = context.node.create_publisher("std_msgs/msg/UInt8", "/kinema/teleoperation_mode")
    opened = threading.Event()

    def session(request: Any) -> dict[str, Any]:
        opened.set()
        time.sleep(0.3)
        mode_publisher.publish(from_dict("std_msgs/msg/UInt8", {"data": 7}))
        time.sleep(0.3)
        return {"accepted": True}

    ui = FakeUi(context, session)
    run = tick_behavior(
        behavior("DoTeleoperateAction"),
        {"initial_teleop_mode": 4, "user_interaction_prompt": "Grasp the tag"},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert run.outputs["current_teleop_mode"] == 7
    assert run.outputs["tip_links"] == ["grasp_link"] and run.outputs["planning_groups"] == ["manipulator"]
    assert run.outputs["controllers"] == ["joint_trajectory_controller"]
    (request,) = ui.requests
    assert request.kind == "teleoperate" and request.prompt == "Grasp the tag"
    assert request.initial_teleop_mode == 4


def test_do_teleoperate_action_fails_when_the_user_cancels(
    behavior: Any, context: BehaviorContext, headless: None
) -> None:
    FakeUi(context, lambda request: {"accepted": False, "message": "out of reach"})
    run = tick_behavior(behavior("DoTeleoperateAction"), {}, context=context)
    assert run.status == NodeStatus.FAILURE and "cancelled teleoperation: out of reach" in run.toasts[-1]


def test_do_teleoperate_action_headless(
    behavior: Any, context: BehaviorContext, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("KINEMA_AUTO_APPROVE", raising=False)
    refused = tick_behavior(behavior("DoTeleoperateAction"), {}, context=context)
    assert refused.status == NodeStatus.FAILURE and "to teleoperate the robot" in refused.toasts[-1]
    monkeypatch.setenv("KINEMA_AUTO_APPROVE", "1")
    granted = tick_behavior(behavior("DoTeleoperateAction"), {"initial_teleop_mode": 4}, context=context)
    assert granted.status == NodeStatus.SUCCESS and "ended automatically" in granted.toasts[-1]
    assert granted.outputs["current_teleop_mode"] == 4


# -- CreateBoundingBoxFromOffset ------------------------------------------------------------------------


def test_create_bounding_box_from_offset_insets_the_exemplar_image(
    behavior: Any, context: BehaviorContext
) -> None:
    image = from_dict("sensor_msgs/msg/Image", {"height": 100, "width": 200, "encoding": "rgb8", "step": 600})
    run = tick_behavior(
        behavior("CreateBoundingBoxFromOffset"),
        {"exemplar_image": image, "padding_percent": 0.1},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    (box,) = run.outputs["bounding_boxes"]
    assert (box.center.position.x, box.center.position.y) == (100.0, 50.0)
    assert (box.size_x, box.size_y) == pytest.approx((160.0, 80.0))
    wrong = tick_behavior(
        behavior("CreateBoundingBoxFromOffset"),
        {"exemplar_image": image, "padding_percent": 0.6},
        context=context,
    )
    assert wrong.status == NodeStatus.FAILURE and "not in [0, 0.5)" in wrong.toasts[-1]
