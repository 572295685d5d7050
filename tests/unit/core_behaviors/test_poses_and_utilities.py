"""CreatePoseStamped, TransformPose, VisualizePose, LogMessage and WaitForDuration."""

from __future__ import annotations

import threading
import time
from typing import Any

import numpy as np

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import build_tree, tick_behavior


def _pose(behavior: Any, context: BehaviorContext, xyz: list[float], xyzw: list[float]) -> Any:
    run = tick_behavior(
        behavior("CreatePoseStamped"),
        {"reference_frame": "world", "position_xyz": xyz, "orientation_xyzw": xyzw},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    return run.outputs["pose_stamped"]


def test_create_pose_stamped_normalises_the_quaternion(behavior: Any, context: BehaviorContext) -> None:
    pose = _pose(behavior, context, [0.1, 0.2, 0.3], [0.0, 0.0, 2.0, 0.0])
    assert pose.header.frame_id == "world"
    assert (pose.pose.position.x, pose.pose.position.y, pose.pose.position.z) == (0.1, 0.2, 0.3)
    assert abs(pose.pose.orientation.z) == 1.0


def test_create_pose_stamped_rejects_bad_vectors(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(behavior("CreatePoseStamped"), {"position_xyz": [1.0, 2.0]}, context=context)
    assert run.status == NodeStatus.FAILURE and "3 values" in run.toasts[-1]
    zero = tick_behavior(behavior("CreatePoseStamped"), {"orientation_xyzw": [0.0] * 4}, context=context)
    assert zero.status == NodeStatus.FAILURE and "zero quaternion" in zero.toasts[-1]


def test_transform_pose_offsets_in_the_poses_own_axes(behavior: Any, context: BehaviorContext) -> None:
    # A pose turned 90 degrees about z: its own x axis is the world's y axis.
    s = float(np.sqrt(0.5))
    pose = _pose(behavior, context, [1.0, 0.0, 0.0], [0.0, 0.0, s, s])
    run = tick_behavior(
        behavior("TransformPose"),
        {"input_pose": pose, "translation_xyz": [0.5, 0.0, 0.0], "quaternion_xyzw": [0.0, 0.0, s, s]},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    out = run.outputs["output_pose"].pose
    np.testing.assert_allclose([out.position.x, out.position.y, out.position.z], [1.0, 0.5, 0.0], atol=1e-9)
    np.testing.assert_allclose(abs(out.orientation.z), 1.0, atol=1e-9)  # 180 degrees about z in all


def test_visualize_pose_publishes_a_triad(behavior: Any, context: BehaviorContext) -> None:
    received: list[Any] = []
    arrived = threading.Event()

    def on_markers(message: Any) -> None:
        received.append(message)
        arrived.set()

    context.node.create_subscription(
        "visualization_msgs/msg/MarkerArray", "/visualization_marker_array", on_markers
    )
    pose = _pose(behavior, context, [0.5, 0.0, 1.0], [0.0, 0.0, 0.0, 1.0])
    deadline = time.monotonic() + 5.0
    while not arrived.is_set() and time.monotonic() < deadline:  # the first publication may beat discovery
        run = tick_behavior(
            behavior("VisualizePose"),
            {"pose": pose, "marker_name": "grasp", "marker_size": 0.2, "marker_lifetime": 2.0},
            context=context,
        )
        assert run.status == NodeStatus.SUCCESS, run.toasts
        arrived.wait(0.1)
    markers = received[-1].markers
    assert [m.ns for m in markers] == ["grasp"] * 3
    x_axis = markers[0].points
    assert (x_axis[0].x, x_axis[1].x) == (0.5, 0.7)
    assert markers[0].lifetime.sec == 2


def test_visualize_pose_needs_a_pose(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(behavior("VisualizePose"), {"pose": "not a pose"}, context=context)
    assert run.status == NodeStatus.FAILURE and "PoseStamped" in run.toasts[-1]


def test_log_message_levels(behavior: Any, context: BehaviorContext) -> None:
    info = tick_behavior(behavior("LogMessage"), {"message": "hi"}, context=context)
    assert info.status == NodeStatus.SUCCESS and info.messages[-1].level == "info" and info.toasts == ["hi"]
    error = tick_behavior(behavior("LogMessage"), {"message": "bad", "log_level": "error"}, context=context)
    assert error.status == NodeStatus.SUCCESS and error.messages[-1].level == "failure"
    wrong = tick_behavior(behavior("LogMessage"), {"message": "x", "log_level": "loud"}, context=context)
    assert wrong.status == NodeStatus.FAILURE


def test_wait_for_duration_follows_the_runtime_clock(registry: Any) -> None:
    from kinema.bt import ManualClock

    clock = ManualClock()
    context = BehaviorContext(clock=clock)
    tree = build_tree(
        '<root BTCPP_format="4"><BehaviorTree ID="T">'
        '<Action ID="WaitForDuration" delay_duration="2.5" /></BehaviorTree></root>',
        registry=registry,
        context=context,
    )
    assert tree.tick_once() == NodeStatus.RUNNING
    clock.advance(2.0)
    assert tree.tick_once() == NodeStatus.RUNNING
    clock.advance(0.6)
    assert tree.tick_once() == NodeStatus.SUCCESS


def test_log_message_shows_blackboard_values_of_any_type(registry: Any, context: BehaviorContext) -> None:
    # MoveIt Pro's ports as they are: a whole "{key}" is a string pointer; {key} inside a text is a value.
    from kinema.testing import run_objective

    xml = """<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence>
      <Script code="count := 3; ratio := 0.5; word := 'hi'"/>
      <CreatePoseStamped position_xyz="1;2;3" pose_stamped="{pose}"/>
      <LogMessage message="{word}"/>
      <LogMessage message="count={count} ratio={ratio} word={word} missing={nope}"/>
      <LogMessage message="picked at {pose}" log_level="warn"/>
    </Sequence></BehaviorTree></root>"""
    run = run_objective(xml, registry=registry, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert run.toasts[0] == "hi"
    assert run.toasts[1] == "count=3 ratio=0.5 word=hi missing={nope}: (not set)"
    picked = run.toasts[2]
    assert picked.startswith("picked at {header: {") and "position: {x: 1.0, y: 2.0, z: 3.0}" in picked
    assert "frame_id: world" in picked and "object at 0x" not in picked
