"""VisualizePath, PublishTF, PublishEmpty, AveragePoseStamped(Vector), AddPoseStampedToVector,
SavePoseForUrdf, GetSyncedImageAndPointCloud and ResetMujocoKeyframe: what each does, seen from outside."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import Blackboard, NodeStatus
from kinema.plugins import BehaviorRegistry
from kinema.testing import build_tree, publish_repeatedly, tick_behavior, tick_until_done
from kinema.transforms import pose_matrix, rotation_from_euler
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


def wait_for(predicate: Callable[[], Any], what: str, timeout: float = 10.0) -> Any:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.01)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")


def _pose(frame: str, xyz: tuple[float, ...], rpy: tuple[float, ...] = (0, 0, 0)) -> Any:
    from kinema.transforms import pose_dict

    matrix = np.eye(4)
    matrix[:3, :3] = rotation_from_euler(rpy)
    matrix[:3, 3] = xyz
    return from_dict(
        "geometry_msgs/msg/PoseStamped", {"header": {"frame_id": frame}, "pose": pose_dict(matrix)}
    )


def _xyz(pose: Any) -> list[float]:
    p = pose.pose.position
    return [p.x, p.y, p.z]


@pytest.fixture
def at_home(context: BehaviorContext) -> Iterator[None]:
    state = {"name": [*ARM, "robotiq_85_left_knuckle_joint"], "position": [*HOME, 0.0]}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        yield


def _markers(context: BehaviorContext) -> list[Any]:
    received: list[Any] = []
    context.node.create_subscription(
        "visualization_msgs/msg/MarkerArray",
        "/visualization_marker_array",
        lambda m: received.extend(m.markers),
    )
    return received


# -- VisualizePath ----------------------------------------------------------------------------------------


def test_visualize_path_draws_a_line_through_the_poses_and_their_axes(
    behavior: Any, context: BehaviorContext
) -> None:
    received = _markers(context)
    path = [_pose("world", (x, 0.5, 1.0)) for x in (0.0, 0.1, 0.2)]
    run = tick_behavior(behavior("VisualizePath"), {"path": path, "marker_name": "raster"}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    wait_for(lambda: len(received) == 10, "a line and three triads")
    line = received[0]
    assert (line.ns, line.type, line.header.frame_id) == ("raster", 4, "world")
    assert [p.x for p in line.points] == pytest.approx([0.0, 0.1, 0.2])
    assert sorted(m.id for m in received[1:]) == list(range(1, 10)) and {m.type for m in received[1:]} == {0}
    # a shorter path under the same name removes the axes it no longer has
    received.clear()
    tick_behavior(behavior("VisualizePath"), {"path": path[:1], "marker_name": "raster"}, context=context)
    wait_for(lambda: len(received) == 10, "the new path and six deletions")
    assert sorted(m.id for m in received if m.action == 2) == [4, 5, 6, 7, 8, 9]
    received.clear()
    tick_behavior(
        behavior("VisualizePath"),
        {"path": path, "marker_name": "plain", "show_poses": False},
        context=context,
    )
    wait_for(lambda: received, "the line alone")
    assert [m.type for m in received] == [4]


def test_visualize_path_places_poses_of_robot_links_in_the_world(
    behavior: Any, context: BehaviorContext, at_home: None, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    received = _markers(context)
    run = tick_behavior(
        behavior("VisualizePath"),
        {"path": [_pose("grasp_link", (0, 0, 0)), _pose("grasp_link", (0, 0, 0.1))], "show_poses": False},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    wait_for(lambda: received, "the path")
    grasp = fk(lab_sim_model, lab_sim_model.configuration(dict(zip(ARM, HOME, strict=True))), "grasp_link")
    points = np.array([[p.x, p.y, p.z] for p in received[0].points])
    np.testing.assert_allclose(points[0], grasp[:3, 3], atol=1e-6)
    np.testing.assert_allclose(points[1], (grasp @ [0, 0, 0.1, 1])[:3], atol=1e-6)
    empty = tick_behavior(behavior("VisualizePath"), {"path": []}, context=context)
    assert empty.status == NodeStatus.FAILURE and "empty vector" in empty.toasts[-1]


# -- PublishTF and PublishEmpty ---------------------------------------------------------------------------


def test_publish_tf_makes_a_frame_later_behaviors_resolve_and_sends_it_on_tf(
    registry: BehaviorRegistry, context: BehaviorContext, at_home: None, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    sent: list[Any] = []
    context.node.create_subscription("tf2_msgs/msg/TFMessage", "/tf", lambda m: sent.extend(m.transforms))
    xml = """<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main">
      <Parallel success_count="1" failure_count="1">
        <PublishTF pose="{center}" child_frame_id="local" publish_rate="50"/>
        <Sequence>
          <Delay delay_msec="300"><AlwaysSuccess/></Delay>
          <CreatePoseStamped reference_frame="local" position_xyz="0;0;0.1" pose_stamped="{in_local}"/>
          <TransformPoseFrame input_pose="{in_local}" target_frame_id="world" output_pose="{in_world}"/>
        </Sequence>
      </Parallel></BehaviorTree></root>"""
    blackboard = Blackboard.create()
    blackboard.set("center", _pose("grasp_link", (0.0, 0.2, 0.0), (0, 0, np.pi / 2)))
    tree = build_tree(xml, registry=registry, context=context, blackboard=blackboard)
    status, _ = tick_until_done(tree)
    assert status == NodeStatus.SUCCESS
    grasp = fk(lab_sim_model, lab_sim_model.configuration(dict(zip(ARM, HOME, strict=True))), "grasp_link")
    expected = grasp @ pose_matrix([0, 0.2, 0], [0, 0, np.sin(np.pi / 4), np.cos(np.pi / 4)]) @ [0, 0, 0.1, 1]
    np.testing.assert_allclose(_xyz(blackboard.get("in_world")), expected[:3], atol=1e-6)
    # 300 ms at 50 Hz: well over two messages, each naming the parent and the child
    wait_for(lambda: len(sent) >= 3, "transforms on /tf")
    assert (sent[0].header.frame_id, sent[0].child_frame_id) == ("grasp_link", "local")
    assert sent[0].transform.translation.y == pytest.approx(0.2)
    # halted by the Parallel, the frame stays known a while, as in a TF buffer
    assert "local" in context.frames.published()
    context.frames.release("local", linger=0.0)
    assert "local" not in context.frames.published()


def test_publish_tf_refuses_a_frame_without_a_name(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(behavior("PublishTF"), {"pose": _pose("world", (0, 0, 0))}, context=context)
    assert run.status == NodeStatus.FAILURE and "port [child_frame_id] is empty" in run.toasts[-1]
    same = tick_behavior(
        behavior("PublishTF"), {"pose": _pose("world", (0, 0, 0)), "child_frame_id": "world"}, context=context
    )
    assert same.status == NodeStatus.FAILURE and "the pose's own frame" in same.toasts[-1]


def test_publish_empty_sends_one_signal(behavior: Any, context: BehaviorContext) -> None:
    received: list[Any] = []
    context.node.create_subscription("std_msgs/msg/Empty", "/studio_ui/motion_ended", received.append)
    run = tick_behavior(
        behavior("PublishEmpty"),
        {"topic": "/studio_ui/motion_ended", "queue_size": 1, "use_best_effort": False},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS
    wait_for(lambda: len(received) == 1, "one std_msgs/Empty")
    assert tick_behavior(behavior("PublishEmpty"), {}, context=context).status == NodeStatus.FAILURE


# -- averages and pose vectors ----------------------------------------------------------------------------


def _averaging(registry: BehaviorRegistry, **ports: str) -> tuple[Any, Blackboard]:
    attributes = " ".join(f'{k}="{v}"' for k, v in ports.items())
    xml = (
        '<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main">'
        f'<AveragePoseStamped pose_sample="{{sample}}" avg_pose="{{avg}}" {attributes}/>'
        "</BehaviorTree></root>"
    )
    blackboard = Blackboard.create()
    return build_tree(xml, registry=registry, blackboard=blackboard), blackboard


def test_average_pose_stamped_averages_samples_refuses_outliers_and_starts_over(
    registry: BehaviorRegistry,
) -> None:
    tree, blackboard = _averaging(registry, num_samples="3", max_distance="0.05", max_rotation="0.3")

    def sample(x: float, yaw: float = 0.0) -> NodeStatus:
        blackboard.set("sample", _pose("camera", (x, 0.0, 0.5), (0, 0, yaw)))
        return tree.tick_once()

    assert sample(1.00) == NodeStatus.SUCCESS
    assert sample(1.02, 0.1) == NodeStatus.SUCCESS
    assert sample(1.20) == NodeStatus.FAILURE  # 19 cm off: an outlier, left out
    assert sample(1.01, 0.2) == NodeStatus.SUCCESS
    average = blackboard.get("avg")
    assert average.header.frame_id == "camera"
    assert _xyz(average) == pytest.approx([1.01, 0.0, 0.5])
    from kinema.transforms import euler_from_rotation, pose_from_message

    assert euler_from_rotation(pose_from_message(average.pose))[2] == pytest.approx(0.1, abs=1e-6)
    assert sample(2.0) == NodeStatus.SUCCESS  # three samples made the average: a new one starts here
    assert _xyz(blackboard.get("avg")) == pytest.approx([2.0, 0.0, 0.5])


def test_average_pose_stamped_run_continuously_keeps_a_moving_average(registry: BehaviorRegistry) -> None:
    tree, blackboard = _averaging(registry, num_samples="2", max_distance="1", run_continuously="true")
    for x in (0.0, 0.2, 0.4, 0.6):
        blackboard.set("sample", _pose("world", (x, 0.0, 0.0)))
        assert tree.tick_once() == NodeStatus.SUCCESS
    assert _xyz(blackboard.get("avg")) == pytest.approx([0.5, 0.0, 0.0])


def test_average_pose_stamped_vector_and_add_pose_stamped_to_vector(
    registry: BehaviorRegistry, behavior: Any, context: BehaviorContext
) -> None:
    xml = """<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main"><Sequence>
        <AddPoseStampedToVector input="{a}" vector="{poses}"/>
        <AddPoseStampedToVector input="{b}" vector="{poses}"/>
        <AddPoseStampedToVector input="{c}" vector="{poses}"/>
        <AveragePoseStampedVector pose_stamped_vector="{poses}" average_pose_stamped="{mean}"/>
      </Sequence></BehaviorTree></root>"""
    blackboard = Blackboard.create()
    for key, (x, yaw) in zip("abc", ((0.1, 0.0), (0.2, 0.3), (0.6, 0.6)), strict=True):
        blackboard.set(key, _pose("tag", (x, 1.0, 0.0), (0, 0, yaw)))
    tree = build_tree(xml, registry=registry, blackboard=blackboard)
    assert tree.tick_once() == NodeStatus.SUCCESS
    assert [_xyz(p)[0] for p in blackboard.get("poses")] == pytest.approx([0.1, 0.2, 0.6])
    assert _xyz(blackboard.get("mean")) == pytest.approx([0.3, 1.0, 0.0])
    mixed = tick_behavior(
        behavior("AveragePoseStampedVector"),
        {"pose_stamped_vector": [_pose("tag", (0, 0, 0)), _pose("world", (0, 0, 0))]},
        context=context,
    )
    assert mixed.status == NodeStatus.FAILURE and "frames 'tag', 'world'" in mixed.toasts[-1]


# -- SavePoseForUrdf --------------------------------------------------------------------------------------


def test_save_pose_for_urdf_writes_a_joint_origin(
    behavior: Any, node: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from lxml import etree

    monkeypatch.chdir(tmp_path)
    pose = _pose("world", (0.5, -0.25, 1.2), (0.1, -0.2, 3.0))
    run = tick_behavior(
        behavior("SavePoseForUrdf"),
        {"calibration_pose_stamped": pose, "file_name": "camera_mount.txt"},
        context=BehaviorContext(node),
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    text = (tmp_path / "camera_mount.txt").read_text()
    assert "parent link: world" in text
    origin = etree.fromstring(text.splitlines()[1])
    assert [float(v) for v in origin.get("xyz").split()] == pytest.approx([0.5, -0.25, 1.2])
    assert [float(v) for v in origin.get("rpy").split()] == pytest.approx([0.1, -0.2, 3.0])


# -- GetSyncedImageAndPointCloud --------------------------------------------------------------------------


def _stamped(kind: str, stamp: float) -> Any:
    header = {
        "frame_id": "wrist_camera_optical_frame",
        "stamp": {"sec": int(stamp), "nanosec": int(stamp % 1 * 1e9)},
    }
    if kind == "image":
        return from_dict(
            "sensor_msgs/msg/Image", {"header": header, "height": 1, "width": 1, "encoding": "rgb8"}
        )
    if kind == "cloud":
        return from_dict("sensor_msgs/msg/PointCloud2", {"header": header, "height": 1, "width": 0})
    return from_dict("sensor_msgs/msg/CameraInfo", {"header": header, "width": 640, "height": 480})


@pytest.fixture
def camera(context: BehaviorContext) -> Iterator[Callable[[float, float], None]]:
    """``camera(image_stamp, cloud_stamp)``: from then on the camera topics carry frames so stamped."""
    node = context.node
    publishers = {
        "image": node.create_publisher("sensor_msgs/msg/Image", "/cam/color"),
        "cloud": node.create_publisher("sensor_msgs/msg/PointCloud2", "/cam/points"),
        "info": node.create_publisher("sensor_msgs/msg/CameraInfo", "/cam/camera_info"),
    }
    stamps = {"image": 0.0, "cloud": 0.0, "info": 0.0}
    stop = threading.Event()

    def loop() -> None:
        while not stop.is_set():
            for kind, publisher in publishers.items():
                if stamps[kind]:
                    publisher.publish(_stamped(kind, stamps[kind]))
            stop.wait(0.02)

    thread = threading.Thread(target=loop, daemon=True)
    thread.start()

    def set_stamps(image: float, cloud: float) -> None:
        stamps.update(image=image, cloud=cloud, info=1.0)

    try:
        yield set_stamps
    finally:
        stop.set()
        thread.join(5)


SYNCED_TOPICS = {
    "rgb_image_topic_name": "/cam/color",
    "point_cloud_topic_name": "/cam/points",
    "rgb_camera_info_topic_name": "/cam/camera_info",
}


def test_get_synced_image_and_point_cloud_takes_an_image_and_a_cloud_of_one_moment(
    behavior: Any, context: BehaviorContext, camera: Callable[[float, float], None]
) -> None:
    camera(100.25, 100.25)
    run = tick_behavior(behavior("GetSyncedImageAndPointCloud"), SYNCED_TOPICS, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert run.outputs["rgb_image"].header.stamp.nanosec == run.outputs["point_cloud"].header.stamp.nanosec
    assert run.outputs["rgb_camera_info"].width == 640


def test_get_synced_image_and_point_cloud_fails_on_streams_of_different_moments(
    behavior: Any, context: BehaviorContext, camera: Callable[[float, float], None]
) -> None:
    camera(100.0, 100.5)
    run = tick_behavior(
        behavior("GetSyncedImageAndPointCloud"),
        {**SYNCED_TOPICS, "message_timeout_sec": 0.5},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE
    assert "no image and cloud within 10 ms of each other" in run.toasts[-1]


# -- ResetMujocoKeyframe ----------------------------------------------------------------------------------


def test_reset_mujoco_keyframe_asks_the_simulator_for_the_keyframe(
    behavior: Any, context: BehaviorContext
) -> None:
    requests: list[Any] = []

    def answer(request: Any) -> dict[str, Any]:
        requests.append(request)
        known = request.keyframe in ("default", "moving_target")
        return {
            "success": known,
            "message": "" if known else f"no keyframe {request.keyframe!r}; valid: default",
        }

    context.node.create_service("kinema_msgs/srv/SetMujocoState", "/mujoco/set_state", answer)
    reset = behavior("ResetMujocoKeyframe")
    assert (
        tick_behavior(reset, {"keyframe_name": "moving_target"}, context=context).status == NodeStatus.SUCCESS
    )
    assert tick_behavior(reset, {}, context=context).status == NodeStatus.SUCCESS  # lab_sim's own: default
    assert [r.keyframe for r in requests] == ["moving_target", "default"]
    assert not list(requests[0].joint_state.name)
    wrong = tick_behavior(reset, {"keyframe_name": "hom"}, context=context)
    assert wrong.status == NodeStatus.FAILURE and "no keyframe 'hom'" in wrong.toasts[-1]


def test_reset_mujoco_keyframe_without_a_simulator_says_so(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(
        behavior("ResetMujocoKeyframe"),
        {"keyframe_name": "default", "wait_for_server_available_timeout": 0.2},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE and "wait_for_server_available_timeout" in run.toasts[-1]
