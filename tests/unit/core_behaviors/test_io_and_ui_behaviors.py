"""The io and ui families against fake servers and subscribers on a private in-process network."""

from __future__ import annotations

import importlib
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import tick_behavior


def wait_for(predicate: Callable[[], Any], what: str, timeout: float = 10.0) -> Any:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.01)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")


def test_call_trigger_service_succeeds_or_fails_as_the_service_answers(
    behavior: Any, context: BehaviorContext
) -> None:
    calls: list[str] = []

    def answer(ok: bool) -> Callable[[Any], dict[str, Any]]:
        def handler(_request: Any) -> dict[str, Any]:
            calls.append("called")
            return {"success": ok, "message": "zeroed" if ok else "sensor offline"}

        return handler

    context.node.create_service("std_srvs/srv/Trigger", "/zero_fts", answer(True))
    context.node.create_service("std_srvs/srv/Trigger", "/broken", answer(False))
    trigger = behavior("CallTriggerService")
    good = tick_behavior(trigger, {"service_name": "/zero_fts"}, context=context)
    assert good.status == NodeStatus.SUCCESS and calls == ["called"]
    bad = tick_behavior(trigger, {"service_name": "/broken"}, context=context)
    assert bad.status == NodeStatus.FAILURE and "sensor offline" in bad.toasts[-1]
    missing = tick_behavior(
        trigger,
        {"service_name": "/nobody", "response_timeout": 0.2, "wait_for_server_available_timeout": 0.2},
        context=context,
    )
    assert missing.status == NodeStatus.FAILURE and "/nobody" in missing.toasts[-1]


def test_publish_string_reaches_a_subscriber(behavior: Any, context: BehaviorContext) -> None:
    received: list[str] = []
    context.node.create_subscription("std_msgs/msg/String", "/status", lambda m: received.append(m.data))
    run = tick_behavior(behavior("PublishString"), {"topic": "/status", "message": "hello"}, context=context)
    assert run.status == NodeStatus.SUCCESS
    wait_for(lambda: received == ["hello"], "the string on /status")


def test_record_joint_trajectory_between_start_and_stop(behavior: Any, context: BehaviorContext) -> None:
    from kinema.transport import from_dict

    node = context.node
    publisher = node.create_publisher("sensor_msgs/msg/JointState", "/recorded_states")
    start = node.create_client("std_srvs/srv/Trigger", "/start_rec")
    stop = node.create_client("std_srvs/srv/Trigger", "/stop_rec")
    names = ["elbow_joint", "wrist_1_joint"]

    def publish(step: int) -> None:
        publisher.publish(
            from_dict(
                "sensor_msgs/msg/JointState",
                {
                    "header": {"stamp": {"sec": step // 10, "nanosec": (step % 10) * 100_000_000}},
                    "name": names,
                    "position": [0.02 * step, -0.01 * step],
                },
            )
        )

    def operator() -> None:
        start.wait_for_service(10.0)
        for step in range(3):
            publish(step)  # before start: not recorded
        # Those must reach the recorder before the start call does (its subscription dispatches on a
        # thread of its own, which lags under load), or they are rightly taken as after the start.
        time.sleep(1.0)
        assert start.call({}, 5.0).success
        time.sleep(0.2)
        for step in range(3, 30):
            publish(step)
            time.sleep(0.01)
        time.sleep(0.2)
        assert stop.call({}, 5.0).success

    thread = threading.Thread(target=operator, daemon=True)
    thread.start()
    run = tick_behavior(
        behavior("RecordJointTrajectory"),
        {
            "joint_state_topic": "/recorded_states",
            "planning_group_name": "",
            "start_recording_service": "/start_rec",
            "stop_recording_service": "/stop_rec",
            "joint_space_step": 0.05,
            "timeout_sec": 10.0,
        },
        context=context,
        timeout=30.0,
    )
    thread.join(10)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    trajectory = run.outputs["joint_trajectory_message"]
    assert list(trajectory.joint_names) == names
    first = np.array(trajectory.points[0].positions)
    steps = np.diff([p.positions[0] for p in trajectory.points])
    assert first[0] == pytest.approx(0.06), "recording starts with the first state after start"
    assert np.all(steps >= 0.05 - 1e-9), f"points closer than joint_space_step: {steps}"
    times = [p.time_from_start.sec + p.time_from_start.nanosec * 1e-9 for p in trajectory.points]
    assert times[0] == 0.0 and np.all(np.diff(times) > 0)


def test_record_joint_trajectory_fails_without_a_start_call(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(
        behavior("RecordJointTrajectory"),
        {"planning_group_name": "", "timeout_sec": 0.3, "start_recording_service": "/start_never"},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE and "start service was not called" in run.toasts[-1]


def _approval_server(context: BehaviorContext, approve: bool, prompts: list[str]) -> None:
    def answer(request: Any) -> dict[str, Any]:
        prompts.append(request.prompt)
        return {"approved": approve, "message": "" if approve else "too close to the table"}

    context.node.create_service("kinema_msgs/srv/RequestApproval", "/kinema/user_approval", answer)


def test_headless_approvals_follow_the_documented_rule(
    behavior: Any, context: BehaviorContext, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("KINEMA_AUTO_APPROVE", raising=False)
    assert tick_behavior(behavior("IsUserAvailable"), {}, context=context).status == NodeStatus.FAILURE
    refused = tick_behavior(behavior("WaitForMTCSolutionApproval"), {"solution": "plan"}, context=context)
    assert refused.status == NodeStatus.FAILURE
    assert "no user interface is attached" in refused.toasts[-1] and "--auto-approve" in refused.toasts[-1]
    monkeypatch.setenv("KINEMA_AUTO_APPROVE", "1")
    assert tick_behavior(behavior("IsUserAvailable"), {}, context=context).status == NodeStatus.SUCCESS
    granted = tick_behavior(behavior("WaitForMTCSolutionApproval"), {"solution": "plan"}, context=context)
    assert granted.status == NodeStatus.SUCCESS and "approved automatically" in granted.toasts[-1]
    resumed = tick_behavior(behavior("BreakpointSubscriber"), {}, context=context)
    assert resumed.status == NodeStatus.SUCCESS and "approved automatically" in resumed.toasts[-1]


@pytest.mark.parametrize("approve", [True, False])
def test_an_attached_ui_answers_the_approval(
    behavior: Any, context: BehaviorContext, monkeypatch: pytest.MonkeyPatch, approve: bool
) -> None:
    monkeypatch.setenv("KINEMA_AUTO_APPROVE", "1")  # a user, when there is one, still decides
    prompts: list[str] = []
    _approval_server(context, approve, prompts)
    assert tick_behavior(behavior("IsUserAvailable"), {}, context=context).status == NodeStatus.SUCCESS
    run = tick_behavior(behavior("WaitForMTCSolutionApproval"), {"solution": "plan"}, context=context)
    assert prompts == ["Approve the planned motion?"]
    assert run.status == (NodeStatus.SUCCESS if approve else NodeStatus.FAILURE)
    if not approve:
        assert "rejected by the user: too close to the table" in run.toasts[-1]


def test_a_breakpoint_resumes_on_its_topic_headless(
    behavior: Any, context: BehaviorContext, monkeypatch: pytest.MonkeyPatch
) -> None:
    from kinema.transport import from_dict

    monkeypatch.delenv("KINEMA_AUTO_APPROVE", raising=False)
    publisher = context.node.create_publisher("std_msgs/msg/Empty", "/resume_here")
    stop = threading.Event()

    def resume() -> None:
        while not stop.wait(0.05):
            publisher.publish(from_dict("std_msgs/msg/Empty", {}))

    thread = threading.Thread(target=resume, daemon=True)
    thread.start()
    try:
        run = tick_behavior(
            behavior("BreakpointSubscriber"), {"breakpoint_topic": "/resume_here"}, context=context
        )
    finally:
        stop.set()
        thread.join(5)
    assert run.status == NodeStatus.SUCCESS
    # A headless user saw it wait with no word on how to go on: the message says what to send.
    assert any("kinema topic pub --once /resume_here std_msgs/msg/Empty" in toast for toast in run.toasts)


def _markers(context: BehaviorContext) -> list[Any]:
    received: list[Any] = []
    context.node.create_subscription(
        "visualization_msgs/msg/MarkerArray",
        "/visualization_marker_array",
        lambda m: received.extend(m.markers),
    )
    return received


def test_publish_markers_draws_one_marker_per_pose(behavior: Any, context: BehaviorContext) -> None:
    received = _markers(context)
    poses = [
        tick_behavior(
            behavior("CreatePoseStamped"), {"position_xyz": [x, 0.0, 0.5]}, context=context
        ).outputs["pose_stamped"]
        for x in (0.1, 0.2)
    ]
    run = tick_behavior(
        behavior("PublishMarkers"),
        {"marker_type": "sphere", "marker_namespace": "obstacles", "marker_poses": poses},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    wait_for(lambda: len(received) == 2, "two sphere markers")
    assert [m.type for m in received] == [2, 2] and [m.pose.position.x for m in received] == [0.1, 0.2]
    assert received[0].ns == "obstacles" and received[0].scale.x == 0.05
    wrong = tick_behavior(
        behavior("PublishMarkers"), {"marker_type": "teapot", "marker_poses": poses}, context=context
    )
    assert wrong.status == NodeStatus.FAILURE and "valid: arrow, cube, sphere, cylinder" in wrong.toasts[-1]


def test_point_cloud_snapshots_are_drawn_and_cleared(behavior: Any, context: BehaviorContext) -> None:
    # The plugin is loaded by path: reach its conversions through a behavior class's package.
    package = behavior("SendPointCloudToUI").__module__.rsplit(".", 2)[0]
    conversions = importlib.import_module(f"{package}.messages.conversions")
    point_cloud_message, point_cloud_xyz = conversions.point_cloud_message, conversions.point_cloud_xyz
    received = _markers(context)
    xyz = np.array([[0.0, 0.0, 0.0], [0.1, 0.2, 0.3], [1.0, 1.0, 1.0]])
    cloud = point_cloud_message(xyz, "world")
    assert np.allclose(point_cloud_xyz(cloud), xyz)
    run = tick_behavior(behavior("SendPointCloudToUI"), {"point_cloud": cloud}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    drawn = wait_for(lambda: [m for m in received if m.action == 0], "the snapshot marker")
    assert drawn[0].type == 8 and len(drawn[0].points) == 3 and drawn[0].ns == "snapshot"
    assert tick_behavior(behavior("ClearSnapshot"), {}, context=context).status == NodeStatus.SUCCESS
    wait_for(lambda: [m for m in received if m.action == 2 and m.ns == "snapshot"], "the snapshot deleted")
    # A snapshot of several MB dropped on a busy link would never be drawn: these publishers keep all
    # (zenoh then waits instead of dropping), as a ROS graph tool shows.
    for topic in ("/pcd_pointcloud_captures", "/visualization_marker_array"):
        publishers = wait_for(
            lambda topic=topic: context.node.graph().publishers(topic), f"the publisher on {topic}"
        )
        assert [p.qos.keep_all for p in publishers] == [True] * len(publishers), (topic, publishers)


def test_switch_ui_primary_view_is_a_notice(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(
        behavior("SwitchUIPrimaryView"), {"primary_view_name": "Visualization"}, context=context
    )
    assert run.status == NodeStatus.SUCCESS and "kinema view" in run.toasts[-1]


def _image(width: int, height: int) -> Any:
    from kinema.transport import from_dict

    return from_dict(
        "sensor_msgs/msg/Image",
        {
            "header": {"frame_id": "camera"},
            "height": height,
            "width": width,
            "encoding": "rgb8",
            "step": width * 3,
            "data": np.zeros(width * height * 3, dtype=np.uint8),
        },
    )


def _images(context: BehaviorContext, topic: str) -> list[Any]:
    received: list[Any] = []
    context.node.create_subscription("sensor_msgs/msg/Image", topic, received.append)
    return received


def test_2d_detections_are_drawn_onto_the_image_and_published(
    behavior: Any, context: BehaviorContext
) -> None:
    from types import SimpleNamespace as NS

    from kinema.transport import from_dict

    boxes_seen = _images(context, "/boxes")
    box = NS(x=1, y=1, width=3, height=2)
    run = tick_behavior(
        behavior("PublishBoundingBoxes2D"),
        {"image": _image(8, 6), "bounding_boxes": [box], "visualization_topic": "/boxes"},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    drawn = wait_for(lambda: boxes_seen[-1] if boxes_seen else None, "the boxes image")
    pixels = np.asarray(drawn.data).reshape(6, 8, 3)
    assert pixels[1, 1].any() and pixels[3, 4].any() and not pixels[2, 2].any(), "outline only"
    masks_seen = _images(context, "/masks")
    mask_image = from_dict(
        "sensor_msgs/msg/Image",
        {"height": 2, "width": 2, "encoding": "mono8", "step": 2, "data": np.full(4, 255, dtype=np.uint8)},
    )
    run = tick_behavior(
        behavior("PublishMask2D"),
        {
            "image": _image(8, 6),
            "masks": [NS(x=5, y=3, mask=mask_image)],
            "masks_visualization_topic": "/masks",
            "opacity": 1.0,
        },
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    drawn = wait_for(lambda: masks_seen[-1] if masks_seen else None, "the masks image")
    pixels = np.asarray(drawn.data).reshape(6, 8, 3)
    assert pixels[3:5, 5:7].all(axis=2).any() and not pixels[0, 0].any()
    bad = tick_behavior(
        behavior("PublishMask2D"), {"image": _image(8, 6), "masks": [], "opacity": 2.0}, context=context
    )
    assert bad.status == NodeStatus.FAILURE and "port [opacity]" in bad.toasts[-1]


def test_the_trajectory_to_approve_is_shown_in_the_view(
    behavior: Any, context: BehaviorContext, monkeypatch: pytest.MonkeyPatch
) -> None:
    from kinema.transport import from_dict

    monkeypatch.setenv("KINEMA_AUTO_APPROVE", "1")
    shown: list[Any] = []
    context.node.create_subscription(
        "trajectory_msgs/msg/JointTrajectory", "/kinema/planned_trajectory", shown.append
    )
    trajectory = from_dict(
        "trajectory_msgs/msg/JointTrajectory",
        {"joint_names": ["elbow_joint"], "points": [{"positions": [0.3], "time_from_start": {"sec": 1}}]},
    )
    run = tick_behavior(behavior("WaitForMTCSolutionApproval"), {"solution": trajectory}, context=context)
    assert run.status == NodeStatus.SUCCESS
    assert wait_for(lambda: shown, "the trajectory on the view's topic")[0].points[0].positions[0] == 0.3
