"""AprilTag detection and the camera behaviors it uses (GetImage, GetCameraInfo), on synthetic images."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import tick_behavior

WIDTH, HEIGHT, FOCAL = 640, 480, 400.0
CELL = 6  # pixels per tag cell: the 8-cell black square is 48 px wide


def camera_info() -> Any:
    from kinema.interfaces import load_interfaces
    from kinema.perception.intrinsics import CameraIntrinsics
    from kinema.perception.ros_messages import camera_info_message

    intrinsics = CameraIntrinsics(WIDTH, HEIGHT, FOCAL, FOCAL, (WIDTH - 1) / 2, (HEIGHT - 1) / 2)
    return camera_info_message(
        intrinsics, "wrist_camera_optical_frame", 12.5, load_interfaces().typestore.types
    )


def tags_image(placements: dict[int, tuple[int, int]]) -> Any:
    """An rgb8 image with 36h11 tags facing the camera, each with its top-left pixel (u, v)."""
    from kinema.interfaces import load_interfaces
    from kinema.perception.apriltags import tag_image
    from kinema.perception.ros_messages import image_message

    pixels = np.full((HEIGHT, WIDTH), 128, dtype=np.uint8)
    for tag_id, (u, v) in placements.items():
        big = np.kron(tag_image("36h11", tag_id), np.ones((CELL, CELL), dtype=np.uint8))
        pixels[v : v + big.shape[0], u : u + big.shape[1]] = big
    rgb = np.repeat(pixels[:, :, None], 3, axis=2)
    return image_message(rgb, "rgb8", "wrist_camera_optical_frame", 12.5, load_interfaces().typestore.types)


def expected_position(u: int, v: int, tag_size: float) -> np.ndarray:
    """Where a fronto-parallel tag drawn at (u, v) is: its black square spans 8 cells."""
    depth = FOCAL * tag_size / (8 * CELL)
    # Pixel centres are at integers: the tag's centre lies between pixels u + 5 cells - 1/2.
    centre_u, centre_v = u + 5 * CELL - 0.5, v + 5 * CELL - 0.5
    return np.array(
        [(centre_u - (WIDTH - 1) / 2) * depth / FOCAL, (centre_v - (HEIGHT - 1) / 2) * depth / FOCAL, depth]
    )


@pytest.fixture
def publishing(context: BehaviorContext) -> Iterator[Any]:
    """``publishing(type, topic, message)`` publishes the message every 20 ms until the test ends."""
    stop = threading.Event()
    threads: list[threading.Thread] = []

    def start(type_name: str, topic: str, message: Any) -> None:
        publisher = context.node.create_publisher(type_name, topic)

        def loop() -> None:
            while not stop.wait(0.02):
                publisher.publish(message)

        threads.append(threading.Thread(target=loop, daemon=True))
        threads[-1].start()

    yield start
    stop.set()
    for thread in threads:
        thread.join(5)


def test_get_image_and_camera_info_take_the_next_message(
    behavior: Any, context: BehaviorContext, publishing: Any
) -> None:
    publishing("sensor_msgs/msg/Image", "/wrist_camera/color", tags_image({}))
    publishing("sensor_msgs/msg/CameraInfo", "/wrist_camera/camera_info", camera_info())
    run = tick_behavior(behavior("GetImage"), {"topic_name": "/wrist_camera/color"}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert (run.outputs["message_out"].width, run.outputs["message_out"].height) == (WIDTH, HEIGHT)
    run = tick_behavior(behavior("GetCameraInfo"), {}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert run.outputs["message_out"].k[0] == FOCAL


def test_get_messages_fail_naming_the_topic_nobody_publishes(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(
        behavior("GetPointCloud"),
        {"topic_name": "/nobody/points", "publisher_timeout_sec": 0.3},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE
    assert "/nobody/points" in run.toasts[-1] and "0.3 s" in run.toasts[-1], run.toasts
    run = tick_behavior(behavior("GetImage"), {"topic_name": " "}, context=context)
    assert run.status == NodeStatus.FAILURE and "port [topic_name]" in run.toasts[-1], run.toasts


def test_detect_april_tags_finds_each_tag_at_its_pose(behavior: Any, context: BehaviorContext) -> None:
    placements = {3: (100, 80), 11: (400, 300)}
    run = tick_behavior(
        behavior("DetectAprilTags"),
        {"image": tags_image(placements), "camera_info": camera_info(), "tag_size": 0.0288},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    detections = run.outputs["detections"]
    assert detections.header.frame_id == "wrist_camera_optical_frame"
    assert sorted(d.id for d in detections.detections) == ["11", "3"]
    for detection in detections.detections:
        (result,) = detection.results
        assert result.hypothesis.class_id == "tag36h11" and 0 < result.hypothesis.score <= 1
        p = result.pose.pose.position
        expected = expected_position(*placements[int(detection.id)], 0.0288)
        assert np.allclose([p.x, p.y, p.z], expected, atol=0.002), (detection.id, p, expected)
        q = result.pose.pose.orientation
        # Facing the camera: the tag's z axis points back along the optical axis (a half turn about x).
        assert abs(q.x) > 0.99, q

    none = tick_behavior(
        behavior("DetectAprilTags"),
        {"image": tags_image(placements), "camera_info": camera_info(), "apriltag_family_name": "16h5"},
        context=context,
    )
    assert none.status == NodeStatus.SUCCESS and none.outputs["detections"].detections == []


def test_detect_april_tags_names_bad_ports(behavior: Any, context: BehaviorContext) -> None:
    inputs = {"image": tags_image({}), "camera_info": camera_info()}
    run = tick_behavior(
        behavior("DetectAprilTags"), {**inputs, "apriltag_family_name": "36h12"}, context=context
    )
    assert run.status == NodeStatus.FAILURE
    assert "port [apriltag_family_name]" in run.toasts[-1] and "36h11" in run.toasts[-1], run.toasts
    run = tick_behavior(behavior("DetectAprilTags"), {**inputs, "tag_size": -1.0}, context=context)
    assert run.status == NodeStatus.FAILURE and "port [tag_size] = -1.0" in run.toasts[-1]
    from kinema.transport import from_dict

    empty_info = from_dict("sensor_msgs/msg/CameraInfo", {})
    run = tick_behavior(behavior("DetectAprilTags"), {**inputs, "camera_info": empty_info}, context=context)
    assert run.status == NodeStatus.FAILURE and "port [camera_info] has no intrinsics" in run.toasts[-1]


def test_get_detection_pose_picks_by_id_and_label(behavior: Any, context: BehaviorContext) -> None:
    placements = {3: (100, 80), 11: (400, 300)}
    detections = tick_behavior(
        behavior("DetectAprilTags"),
        {"image": tags_image(placements), "camera_info": camera_info()},
        context=context,
    ).outputs["detections"]
    run = tick_behavior(
        behavior("GetDetectionPose"), {"detections": detections, "target_id": 11}, context=context
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    pose = run.outputs["detection_pose"]
    assert pose.header.frame_id == "wrist_camera_optical_frame"
    p = pose.pose.position
    assert np.allclose([p.x, p.y, p.z], expected_position(400, 300, 0.0288), atol=0.002)
    any_tag = tick_behavior(behavior("GetDetectionPose"), {"detections": detections}, context=context)
    assert any_tag.status == NodeStatus.SUCCESS
    missing = tick_behavior(
        behavior("GetDetectionPose"),
        {"detections": detections, "target_id": 5, "target_label": "tag36h11"},
        context=context,
    )
    assert missing.status == NodeStatus.FAILURE
    assert "no detection with id 5 and label 'tag36h11'" in missing.toasts[-1]
    assert "id 3 (tag36h11)" in missing.toasts[-1] and "id 11 (tag36h11)" in missing.toasts[-1]


def tray_detections(frame_id: str, tag_pose: np.ndarray, tag_id: int = 1) -> Any:
    """A Detection3DArray with one tag at ``tag_pose`` (4x4) in ``frame_id``."""
    from scipy.spatial.transform import Rotation

    from kinema.transport import from_dict

    x, y, z, w = Rotation.from_matrix(tag_pose[:3, :3]).as_quat()
    pose = {
        "position": dict(zip("xyz", (float(v) for v in tag_pose[:3, 3]), strict=True)),
        "orientation": {"x": x, "y": y, "z": z, "w": w},
    }
    header = {"frame_id": frame_id}
    return from_dict(
        "vision_msgs/msg/Detection3DArray",
        {
            "header": header,
            "detections": [
                {
                    "header": header,
                    "id": str(tag_id),
                    "results": [
                        {"hypothesis": {"class_id": "tag36h11", "score": 0.9}, "pose": {"pose": pose}}
                    ],
                }
            ],
        },
    )


TRAY_INPUTS = {
    "tray_apriltag_id": 1,
    "num_rows": 3,
    "columns_per_row": 2,
    "row_spacing": 0.10,
    "column_spacing": 0.09,
    "tag_to_tray_center": 0.125,
    "bottle_diameter": 0.04,
    "visualization_topic": "",
}


def test_tray_place_positions_lay_the_slots_out_from_the_tag(behavior: Any, context: BehaviorContext) -> None:
    from scipy.spatial.transform import Rotation

    # The tag lies flat at (0.3, 0.5, 0.48), turned 90 degrees about z: its +y axis points along world -x.
    tag = np.eye(4)
    tag[:3, :3] = Rotation.from_euler("z", 90, degrees=True).as_matrix()
    tag[:3, 3] = [0.3, 0.5, 0.48]
    run = tick_behavior(
        behavior("ComputeTrayPlacePositionsUsingAprilTags"),
        {**TRAY_INPUTS, "detections": tray_detections("world", tag)},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    poses = run.outputs["place_positions"]
    assert [p.header.frame_id for p in poses] == ["world"] * 6
    found = np.array([[p.pose.position.x, p.pose.position.y, p.pose.position.z] for p in poses])
    # Tray centre 0.125 m along the tag's +y (world -x); rows along the tag's x (world +y), the two slots
    # of a row along the tag's y (world -x), nearest the tag first.
    centre = np.array([0.3 - 0.125, 0.5, 0.48])
    expected = np.array(
        [centre + np.array([-dy, dx, 0.0]) for dx in (-0.10, 0.0, 0.10) for dy in (-0.045, 0.045)]
    )
    assert np.allclose(found, expected, atol=1e-9), found
    for pose in poses:
        q = pose.pose.orientation
        z_axis = Rotation.from_quat([q.x, q.y, q.z, q.w]).as_matrix()[:, 2]
        assert np.allclose(z_axis, [0, 0, -1], atol=1e-9), "the place frame's z points into the tray"


def test_tray_place_positions_draw_the_slots_on_the_visualization_topic(
    behavior: Any, context: BehaviorContext
) -> None:
    # The tag 0.5 m in front of the camera, facing it (a half turn about x), its +y toward image top.
    tag = np.eye(4)
    tag[:3, :3] = np.diag([1.0, -1.0, -1.0])
    tag[:3, 3] = [0.0, 0.0, 0.5]
    images: list[Any] = []
    subscription = context.node.create_subscription("sensor_msgs/msg/Image", "/tray_test_view", images.append)
    try:
        run = tick_behavior(
            behavior("ComputeTrayPlacePositionsUsingAprilTags"),
            {
                **TRAY_INPUTS,
                "detections": tray_detections("world", tag),
                "input_image": tags_image({}),
                "camera_info": camera_info(),
                "visualization_topic": "/tray_test_view",
            },
            context=context,
        )
        assert run.status == NodeStatus.SUCCESS, run.toasts
        deadline = time.monotonic() + 10
        while not images and time.monotonic() < deadline:
            time.sleep(0.02)
    finally:
        subscription.close()
    assert images, "nothing was published on the visualization topic"
    pixels = np.frombuffer(bytes(images[-1].data), dtype=np.uint8).reshape(HEIGHT, WIDTH, 3)
    green = (pixels[:, :, 1] > 150) & (pixels[:, :, 0] < 100)
    # The first slot: 0.125 - 0.045 m above the tag (image -v) and 0.10 m to its -x (image -u).
    u = (WIDTH - 1) / 2 + FOCAL * -0.10 / 0.5
    v = (HEIGHT - 1) / 2 - FOCAL * 0.08 / 0.5
    r = FOCAL * 0.02 / 0.5
    ring = green[int(v - r - 3) : int(v + r + 4), int(u - r - 3) : int(u + r + 4)]
    assert ring.sum() > 20, f"no slot circle drawn around ({u:.0f}, {v:.0f})"
    assert not green[int(v), int(u)], "a circle, not a disc"


def test_tray_place_positions_name_bad_input(behavior: Any, context: BehaviorContext) -> None:
    tag = np.eye(4)
    detections = tray_detections("world", tag, tag_id=4)
    run = tick_behavior(
        behavior("ComputeTrayPlacePositionsUsingAprilTags"),
        {**TRAY_INPUTS, "detections": detections},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE
    assert "port [tray_apriltag_id] = 1: no detection" in run.toasts[-1], run.toasts
    assert "ids detected: 4" in run.toasts[-1], run.toasts
    for port, value, words in (
        ("num_rows", 0, "1 or more"),
        ("columns_per_row", -2, "1 or more"),
        ("row_spacing", 0.03, "bottle_diameter (0.04)"),
        ("bottle_diameter", 0.0, "> 0"),
    ):
        run = tick_behavior(
            behavior("ComputeTrayPlacePositionsUsingAprilTags"),
            {**TRAY_INPUTS, "detections": tray_detections("world", tag), port: value},
            context=context,
        )
        assert run.status == NodeStatus.FAILURE, (port, value)
        assert f"port [{port}] = {value}" in run.toasts[-1] and words in run.toasts[-1], run.toasts
