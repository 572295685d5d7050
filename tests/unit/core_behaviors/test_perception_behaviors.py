"""The perception family: camera messages, point clouds moved, cropped, merged, registered, loaded, and a
cloud turned into obstacles the next plan avoids (against a private in-process network)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.perception import PointCloud, save_pcd
from kinema.perception.ros_messages import from_point_cloud2, to_point_cloud2
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
GRIPPER = "robotiq_85_left_knuckle_joint"
HOME = [0.0, 0.0, -2.0, 2.0, -1.5708, -1.5708, 0.0]
MID = [-0.1333, 0.0, -1.25758, 1.37827, -1.69149, -1.5708, 0.0]


def _types() -> Any:
    from kinema.interfaces import load_interfaces

    return load_interfaces().typestore.types


def cloud_message(points: Any, frame: str = "world", colors: Any = None, shape: Any = None) -> Any:
    return to_point_cloud2(
        PointCloud(np.asarray(points, dtype=np.float32), colors, frame, 0.0, shape), _types()
    )


def points_of(message: Any) -> np.ndarray:
    return from_point_cloud2(message).finite().points.astype(float)


def pose(frame: str, xyz: Any, xyzw: Any = (0, 0, 0, 1)) -> Any:
    x, y, z = (float(v) for v in xyz)
    qx, qy, qz, qw = xyzw
    return from_dict(
        "geometry_msgs/msg/PoseStamped",
        {
            "header": {"frame_id": frame},
            "pose": {
                "position": {"x": x, "y": y, "z": z},
                "orientation": {"x": qx, "y": qy, "z": qz, "w": qw},
            },
        },
    )


def _q(model: Any, arm: list[float]) -> np.ndarray:
    q = np.zeros(len(model.joint_names))
    q[[model.joint_names.index(n) for n in ARM]] = arm
    return q


@pytest.fixture
def at_home(context: BehaviorContext) -> Any:
    state = {"name": [*ARM, GRIPPER], "position": [*HOME, 0.0]}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        yield


def test_get_point_cloud_takes_the_next_cloud_and_names_the_topics_there_are(
    behavior: Any, context: BehaviorContext
) -> None:
    organised = cloud_message(np.arange(12).reshape(4, 3), "scene_camera_optical_frame", shape=(2, 2))
    with publish_repeatedly(context.node, "sensor_msgs/msg/PointCloud2", "/scene_camera/points", organised):
        run = tick_behavior(
            behavior("GetPointCloud"), {"topic_name": "/scene_camera/points"}, context=context, timeout=30.0
        )
        assert run.status == NodeStatus.SUCCESS, run.toasts
        got = run.outputs["message_out"]
        assert (got.height, got.width) == (2, 2) and got.header.frame_id == "scene_camera_optical_frame"
        missing = tick_behavior(
            behavior("GetPointCloud"),
            {"topic_name": "/wrist_camera/points", "publisher_timeout_sec": 0.3},
            context=context,
            timeout=30.0,
        )
    assert missing.status == NodeStatus.FAILURE
    assert "no publisher on /wrist_camera/points" in missing.toasts[-1]
    assert "/scene_camera/points" in missing.toasts[-1], missing.toasts
    relative = tick_behavior(behavior("GetImage"), {"topic_name": "wrist_camera/color"}, context=context)
    assert relative.status == NodeStatus.FAILURE and "port [topic_name]" in relative.toasts[-1]


def test_a_frame_stamped_before_the_behavior_subscribed_is_skipped(
    behavior: Any, context: BehaviorContext, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A frame rendered before the last motion but still arriving must not pass for the scene now."""
    from types import SimpleNamespace

    clock = context.clock
    monkeypatch.setattr(context, "clock", SimpleNamespace(now=lambda: 100.0, call_later=clock.call_later))

    def stamped(t: float) -> Any:
        message = cloud_message(np.arange(12).reshape(4, 3), "scene_camera_optical_frame", shape=(2, 2))
        message.header.stamp.sec, message.header.stamp.nanosec = int(t), round((t % 1) * 1e9)
        return message

    ports = {"topic_name": "/scene_camera/points", "message_timeout_sec": 1.0}
    with publish_repeatedly(
        context.node, "sensor_msgs/msg/PointCloud2", "/scene_camera/points", stamped(99.5)
    ):
        stale = tick_behavior(behavior("GetPointCloud"), ports, context=context, timeout=30.0)
    assert stale.status == NodeStatus.FAILURE and "no message on /scene_camera/points" in stale.toasts[-1]
    with publish_repeatedly(
        context.node, "sensor_msgs/msg/PointCloud2", "/scene_camera/points", stamped(100.25)
    ):
        fresh = tick_behavior(behavior("GetPointCloud"), ports, context=context, timeout=30.0)
    assert fresh.status == NodeStatus.SUCCESS, fresh.toasts
    assert fresh.outputs["message_out"].header.stamp.nanosec == 250_000_000


def test_get_camera_info_and_image_write_the_messages(behavior: Any, context: BehaviorContext) -> None:
    from kinema.perception import CameraIntrinsics
    from kinema.perception.ros_messages import camera_info_message, image_message

    info = camera_info_message(
        CameraIntrinsics.from_fovy(64, 48, 58.0), "wrist_camera_optical_frame", 1.0, _types()
    )
    image = image_message(
        np.zeros((48, 64, 3), np.uint8), "rgb8", "wrist_camera_optical_frame", 1.0, _types()
    )
    with (
        publish_repeatedly(context.node, "sensor_msgs/msg/CameraInfo", "/wrist_camera/camera_info", info),
        publish_repeatedly(context.node, "sensor_msgs/msg/Image", "/wrist_camera/color", image),
    ):
        got_info = tick_behavior(behavior("GetCameraInfo"), {}, context=context, timeout=30.0)
        got_image = tick_behavior(behavior("GetImage"), {}, context=context, timeout=30.0)
    assert got_info.status == NodeStatus.SUCCESS and got_info.outputs["message_out"].width == 64
    assert got_image.status == NodeStatus.SUCCESS and got_image.outputs["message_out"].encoding == "rgb8"


def test_transform_point_cloud_frame_puts_grasp_link_points_in_the_world(
    behavior: Any, context: BehaviorContext, at_home: Any, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    local = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.1]])
    run = tick_behavior(
        behavior("TransformPointCloudFrame"),
        {"input_cloud": cloud_message(local, "grasp_link")},
        context=context,
        timeout=30.0,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    world_T_grasp = fk(lab_sim_model, _q(lab_sim_model, HOME), "grasp_link")
    expected = local @ world_T_grasp[:3, :3].T + world_T_grasp[:3, 3]
    assert run.outputs["output_cloud"].header.frame_id == "world"
    assert np.allclose(points_of(run.outputs["output_cloud"]), expected, atol=1e-4)
    unknown = tick_behavior(
        behavior("TransformPointCloudFrame"),
        {"input_cloud": cloud_message(local, "grasp_link"), "target_frame": "gras_link"},
        context=context,
        timeout=30.0,
    )
    assert unknown.status == NodeStatus.FAILURE and "gras_link" in unknown.toasts[-1], unknown.toasts


def test_a_cloud_is_placed_with_the_robot_as_it_was_when_the_cloud_was_taken(
    behavior: Any, context: BehaviorContext, lab_sim_model: Any
) -> None:
    """As TF looks up a transform at a message's stamp: a wrist camera's cloud taken while the arm was at
    HOME lands where HOME puts the camera, even when the newest joint state says the arm is at MID (the
    arm moved on, or a loaded machine delivered the newer state first). A stamp of 0 means now."""
    from kinema.motion import fk

    def joint_state(arm: list[float], stamp: float) -> dict[str, Any]:
        sec = int(stamp)
        return {
            "header": {"stamp": {"sec": sec, "nanosec": round((stamp - sec) * 1e9)}},
            "name": [*ARM, GRIPPER],
            "position": [*arm, 0.0],
        }

    local = np.array([[0.0, 0.0, 0.1]], dtype=np.float32)

    def placed(stamp: float) -> np.ndarray:
        cloud = to_point_cloud2(PointCloud(local, None, "grasp_link", stamp), _types())
        run = tick_behavior(
            behavior("TransformPointCloudFrame"), {"input_cloud": cloud}, context=context, timeout=30.0
        )
        assert run.status == NodeStatus.SUCCESS, run.toasts
        return points_of(run.outputs["output_cloud"])[0]

    def expected(arm: list[float]) -> np.ndarray:
        world_T_grasp = fk(lab_sim_model, _q(lab_sim_model, arm), "grasp_link")
        return world_T_grasp[:3, :3] @ local[0] + world_T_grasp[:3, 3]

    topic, kind = "/joint_states", "sensor_msgs/msg/JointState"
    with publish_repeatedly(context.node, kind, topic, joint_state(HOME, 5.0)):
        assert np.allclose(placed(0.0), expected(HOME), atol=1e-4)
    with publish_repeatedly(context.node, kind, topic, joint_state(MID, 6.0)):
        deadline = time.monotonic() + 30.0
        while not np.allclose(placed(0.0), expected(MID), atol=1e-4):
            assert time.monotonic() < deadline, "the MID joint state never arrived"
        assert np.allclose(placed(5.0), expected(HOME), atol=1e-4)
        assert np.allclose(placed(6.0), expected(MID), atol=1e-4)


def test_transform_point_cloud_moves_points_by_the_pose(behavior: Any, context: BehaviorContext) -> None:
    quarter_turn_z = (0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4))
    run = tick_behavior(
        behavior("TransformPointCloud"),
        {
            "input_cloud": cloud_message([[1.0, 0.0, 0.0]]),
            "transform_pose": pose("world", (0, 0, 1), quarter_turn_z),
        },
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert np.allclose(points_of(run.outputs["output_cloud"]), [[0.0, 1.0, 1.0]], atol=1e-6)


def test_crop_and_remove_points_in_a_box_split_the_cloud(behavior: Any, context: BehaviorContext) -> None:
    points = [[0.0, 0.0, 0.0], [0.05, 0.0, 0.0], [0.5, 0.0, 0.0], [np.nan, np.nan, np.nan]]
    box = {"point_cloud": cloud_message(points)}
    crop = tick_behavior(
        behavior("CropPointsInBox"),
        {**box, "crop_box_centroid_pose": pose("world", (0, 0, 0)), "crop_box_size": "0.2;0.2;0.2"},
        context=context,
    )
    cull = tick_behavior(
        behavior("RemovePointsInBox"),
        {**box, "remove_box_centroid_pose": pose("world", (0, 0, 0)), "remove_box_size": "0.2;0.2;0.2"},
        context=context,
    )
    assert crop.status == cull.status == NodeStatus.SUCCESS, (crop.toasts, cull.toasts)
    assert np.allclose(points_of(crop.outputs["point_cloud_cropped"]), [[0, 0, 0], [0.05, 0, 0]])
    assert np.allclose(points_of(cull.outputs["point_cloud_culled"]), [[0.5, 0, 0]])
    bad = tick_behavior(
        behavior("CropPointsInBox"),
        {**box, "crop_box_centroid_pose": pose("world", (0, 0, 0)), "crop_box_size": "0.2;0.2"},
        context=context,
    )
    assert bad.status == NodeStatus.FAILURE
    assert "port [crop_box_size]" in bad.toasts[-1] and "expected 3 values" in bad.toasts[-1], bad.toasts


def test_centroid_of_a_cloud_and_of_an_empty_one(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(
        behavior("GetCentroidFromPointCloud"),
        {"point_cloud": cloud_message([[0, 0, 0], [1, 2, 3], [np.nan] * 3], "base_link")},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    out = run.outputs["output_pose"]
    assert out.header.frame_id == "base_link"
    assert np.allclose([out.pose.position.x, out.pose.position.y, out.pose.position.z], [0.5, 1.0, 1.5])
    empty = tick_behavior(
        behavior("GetCentroidFromPointCloud"),
        {"point_cloud": cloud_message(np.empty((0, 3)))},
        context=context,
    )
    assert empty.status == NodeStatus.FAILURE and "port [point_cloud]" in empty.toasts[-1]


def test_merge_point_clouds_thins_the_union_and_refuses_mixed_frames(
    behavior: Any, context: BehaviorContext
) -> None:
    a = cloud_message([[0.001, 0.001, 0.001], [0.004, 0.004, 0.004], [0.5, 0.5, 0.5]])
    b = cloud_message([[0.002, 0.002, 0.002], [1.0, 1.0, 1.0]])
    run = tick_behavior(
        behavior("MergePointClouds"),
        {"point_clouds": [a, b], "grid_resolution_meters": 0.01},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    merged = points_of(run.outputs["merged_cloud"])
    assert len(merged) == 3, merged
    mixed = tick_behavior(
        behavior("MergePointClouds"),
        {"point_clouds": [a, cloud_message([[0, 0, 0]], "grasp_link")]},
        context=context,
    )
    assert mixed.status == NodeStatus.FAILURE
    assert "grasp_link" in mixed.toasts[-1] and "TransformPointCloudFrame" in mixed.toasts[-1], mixed.toasts
    empty = tick_behavior(behavior("MergePointClouds"), {"point_clouds": []}, context=context)
    assert empty.status == NodeStatus.FAILURE and "PushBackVector" in empty.toasts[-1]


def _box_stl(folder: Path) -> Path:
    import trimesh

    path = folder / "part.stl"
    # An L-shaped part: registration of a plain box would be ambiguous.
    part = trimesh.util.concatenate(
        [trimesh.creation.box((0.2, 0.05, 0.05)), trimesh.creation.box((0.05, 0.15, 0.05), np.eye(4))]
    )
    part.apply_translation((0.0, 0.05, 0.0))
    part.export(path)
    return path


def _in_data_folder(tmp_path: Path) -> Path:
    """A fresh folder inside Kinema's data folder (the session's own, see tests/conftest.py)."""
    import platformdirs

    folder = platformdirs.user_data_path("kinema") / "test-files" / tmp_path.name
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def test_load_a_mesh_and_register_it_onto_a_moved_copy(
    behavior: Any, context: BehaviorContext, tmp_path: Path
) -> None:
    tmp_path = _in_data_folder(tmp_path)  # the file rule: a lab_sim context reads only there
    stl = _box_stl(tmp_path)
    load = {"file_path": str(stl), "num_sampled_points": 3000, "random_seed": 7, "color": "255;0;0"}
    model = tick_behavior(behavior("LoadPointCloudFromFile"), load, context=context)
    assert model.status == NodeStatus.SUCCESS, model.toasts
    cloud = from_point_cloud2(model.outputs["point_cloud"])
    assert len(cloud) == 3000 and cloud.frame_id == "world" and (cloud.colors == [255, 0, 0]).all()
    again = tick_behavior(behavior("LoadPointCloudFromFile"), load, context=context)
    assert np.array_equal(points_of(again.outputs["point_cloud"]), points_of(model.outputs["point_cloud"]))
    yaw = 0.1
    moved = tick_behavior(
        behavior("TransformPointCloud"),
        {
            "input_cloud": model.outputs["point_cloud"],
            "transform_pose": pose("world", (0.03, -0.02, 0.01), (0, 0, np.sin(yaw / 2), np.cos(yaw / 2))),
        },
        context=context,
    )
    run = tick_behavior(
        behavior("RegisterPointClouds"),
        {
            "base_point_cloud": model.outputs["point_cloud"],
            "target_point_cloud": moved.outputs["output_cloud"],
            "max_correspondence_distance": 0.2,
            "max_iterations": 100,
        },
        context=context,
        timeout=60.0,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    found = run.outputs["target_pose_in_base_frame"]
    p, o = found.pose.position, found.pose.orientation
    assert np.allclose([p.x, p.y, p.z], [0.03, -0.02, 0.01], atol=2e-3), found
    assert abs(2 * np.arctan2(o.z, o.w) - yaw) < np.radians(0.5), found


def test_load_a_pcd_file_and_bad_files_name_what_would_do(
    behavior: Any, context: BehaviorContext, tmp_path: Path
) -> None:
    tmp_path = _in_data_folder(tmp_path)  # the file rule: a lab_sim context reads only there
    save_pcd(PointCloud(np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], np.float32)), tmp_path / "two.pcd")
    run = tick_behavior(
        behavior("LoadPointCloudFromFile"),
        {"file_path": str(tmp_path / "two.pcd"), "scale": 0.5, "frame_id": "base_link"},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert np.allclose(points_of(run.outputs["point_cloud"]), [[0.5, 1, 1.5], [2, 2.5, 3]])
    assert run.outputs["point_cloud"].header.frame_id == "base_link"
    (tmp_path / "notes.txt").write_text("x")
    wrong = tick_behavior(
        behavior("LoadPointCloudFromFile"), {"file_path": str(tmp_path / "notes.txt")}, context=context
    )
    assert wrong.status == NodeStatus.FAILURE and ".pcd" in wrong.toasts[-1] and ".stl" in wrong.toasts[-1]
    missing = tick_behavior(
        behavior("LoadPointCloudFromFile"),
        {"file_path": "description/assets/nothing.stl", "package_name": "lab_sim"},
        context=context,
    )
    assert missing.status == NodeStatus.FAILURE and "no such file" in missing.toasts[-1], missing.toasts
    color = tick_behavior(
        behavior("LoadPointCloudFromFile"),
        {"file_path": str(tmp_path / "two.pcd"), "color": "red"},
        context=context,
    )
    assert color.status == NodeStatus.FAILURE and "port [color]" in color.toasts[-1]


def _cube_surface(centre: np.ndarray, size: float, step: float = 0.01) -> np.ndarray:
    ticks = np.arange(-size / 2, size / 2 + 1e-9, step)
    a, b = np.meshgrid(ticks, ticks)
    faces = []
    for axis in range(3):
        for side in (-size / 2, size / 2):
            face = np.zeros((a.size, 3))
            others = [i for i in range(3) if i != axis]
            face[:, others[0]], face[:, others[1]], face[:, axis] = a.ravel(), b.ravel(), side
            faces.append(face)
    return np.concatenate(faces) + centre


def test_a_cloud_in_the_planning_scene_is_avoided_and_the_robot_is_not_its_own_obstacle(
    behavior: Any, context: BehaviorContext, at_home: Any, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    straight = tick_behavior(
        behavior("PlanToJointGoal"),
        {"joint_goal": from_dict("sensor_msgs/msg/JointState", {"name": ARM, "position": MID})},
        context=context,
        timeout=30.0,
    )
    assert straight.status == NodeStatus.SUCCESS, straight.toasts
    halfway = fk(lab_sim_model, _q(lab_sim_model, list((np.array(HOME) + np.array(MID)) / 2)), "grasp_link")[
        :3, 3
    ]
    grasp_now = fk(lab_sim_model, _q(lab_sim_model, HOME), "grasp_link")[:3, 3]
    # What a camera would see: an object where the tool passes, and the gripper itself.
    obstacle = _cube_surface(halfway, 0.06)
    seen = np.concatenate([obstacle, _cube_surface(grasp_now, 0.04)])
    update = tick_behavior(
        behavior("UpdatePlanningSceneService"),
        {"point_cloud": cloud_message(seen)},
        context=context,
        timeout=30.0,
    )
    assert update.status == NodeStatus.SUCCESS, update.toasts
    assert " 0 occupied cubes" not in update.toasts[-1], update.toasts
    itself = tick_behavior(
        behavior("UpdatePlanningSceneService"),
        {"point_cloud": cloud_message(_cube_surface(grasp_now, 0.04))},
        context=context,
        timeout=30.0,
    )
    assert itself.status == NodeStatus.SUCCESS and ": 0 occupied cubes" in itself.toasts[-1], itself.toasts
    tick_behavior(
        behavior("UpdatePlanningSceneService"),
        {"point_cloud": cloud_message(seen)},
        context=context,
        timeout=30.0,
    )
    check = tick_behavior(
        behavior("ValidateTrajectory"),
        {"joint_trajectory_msg": straight.outputs["joint_trajectory_msg"]},
        context=context,
        timeout=30.0,
    )
    assert check.status == NodeStatus.FAILURE and "octomap" in check.toasts[-1], check.toasts
    around = tick_behavior(
        behavior("PlanToJointGoal"),
        {"joint_goal": from_dict("sensor_msgs/msg/JointState", {"name": ARM, "position": MID})},
        context=context,
        timeout=60.0,
    )
    assert around.status == NodeStatus.SUCCESS, around.toasts
    valid = tick_behavior(
        behavior("ValidateTrajectory"),
        {"joint_trajectory_msg": around.outputs["joint_trajectory_msg"]},
        context=context,
        timeout=30.0,
    )
    assert valid.status == NodeStatus.SUCCESS, valid.toasts


def _mask(x: int, y: int, rows: int, cols: int) -> Any:
    """A Mask2D of ``rows`` x ``cols`` object pixels whose top-left pixel is (x, y)."""
    image = {
        "height": rows,
        "width": cols,
        "encoding": "mono8",
        "step": cols,
        "data": np.full(rows * cols, 255, np.uint8),
    }
    return from_dict("moveit_studio_vision_msgs/msg/Mask2D", {"x": x, "y": y, "mask": image})


def _camera_info(width: int, height: int) -> Any:
    from kinema.perception import CameraIntrinsics
    from kinema.perception.ros_messages import camera_info_message

    return camera_info_message(CameraIntrinsics.from_fovy(width, height, 60.0), "world", 0.0, _types())


def test_image_masks_pick_the_points_of_each_object(behavior: Any, context: BehaviorContext) -> None:
    grid = np.arange(16 * 3, dtype=np.float32).reshape(16, 3)
    grid[0] = np.nan  # a pixel the camera did not see
    cloud = cloud_message(grid, "world", shape=(4, 4))
    masks = tick_behavior(
        behavior("GetMasks3DFromMasks2D"),
        {
            "point_cloud": cloud,
            "camera_info": _camera_info(4, 4),
            "masks2d": [_mask(1, 1, 2, 2), _mask(0, 0, 1, 2)],
        },
        context=context,
    )
    assert masks.status == NodeStatus.SUCCESS, masks.toasts
    first, second = masks.outputs["masks3d"]
    assert list(first.point_indices) == [5, 6, 9, 10] and list(second.point_indices) == [1]
    fragment = tick_behavior(
        behavior("GetPointCloudFromMask3D"), {"point_cloud": cloud, "mask3d": first}, context=context
    )
    assert fragment.status == NodeStatus.SUCCESS, fragment.toasts
    assert np.allclose(points_of(fragment.outputs["point_cloud_fragment"]), grid[[5, 6, 9, 10]])
    other_size = tick_behavior(
        behavior("GetMasks3DFromMasks2D"),
        {"point_cloud": cloud, "camera_info": _camera_info(8, 6), "masks2d": [_mask(1, 1, 2, 2)]},
        context=context,
    )
    assert other_size.status == NodeStatus.FAILURE and "8x6" in other_size.toasts[-1], other_size.toasts
    small = tick_behavior(
        behavior("GetPointCloudFromMask3D"),
        {"point_cloud": cloud_message(grid[:4]), "mask3d": first},
        context=context,
    )
    assert small.status == NodeStatus.FAILURE and "lists point 10" in small.toasts[-1], small.toasts


def test_find_masked_objects_fits_a_box_to_each_masked_object(
    behavior: Any, context: BehaviorContext
) -> None:
    # A 40x40 camera looking down on a 0.10 x 0.04 x 0.03 block (its top at z = 0.03, table at z = 0).
    u, v = np.meshgrid(np.linspace(-0.2, 0.2, 40), np.linspace(-0.2, 0.2, 40))
    z = np.zeros_like(u)
    on_block = (np.abs(u) <= 0.05) & (np.abs(v) <= 0.02)
    z[on_block] = 0.03
    points = np.stack([u.ravel(), v.ravel(), z.ravel()], axis=1)
    rows, cols = np.nonzero(on_block)
    mask = _mask(int(cols.min()), int(rows.min()), int(np.ptp(rows)) + 1, int(np.ptp(cols)) + 1)
    side = np.array([[0.05, 0.0, 0.0], [-0.05, 0.0, 0.0]])  # what the camera sees of the block's sides
    points[np.flatnonzero(on_block.ravel())[:2]] = side
    run = tick_behavior(
        behavior("FindMaskedObjects"),
        {
            "point_cloud": cloud_message(points, shape=(40, 40)),
            "camera_info": _camera_info(40, 40),
            "masks2d": [mask],
        },
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    (found,) = run.outputs["detected_shapes"]
    dimensions = sorted(found.object.primitives[0].dimensions, reverse=True)
    assert dimensions[0] == pytest.approx(0.0842, abs=0.02) and dimensions[2] == pytest.approx(
        0.03, abs=0.005
    )
    assert found.object.header.frame_id == "world"


def test_collision_spheres_at_the_points_nearest_the_reference(
    behavior: Any, context: BehaviorContext
) -> None:
    line = np.stack([np.linspace(0.0, 1.0, 11), np.zeros(11), np.zeros(11)], axis=1)
    run = tick_behavior(
        behavior("CreateCollisionSpheresAtClosestPoints"),
        {
            "point_cloud": cloud_message(line),
            "reference_pose": pose("world", (0.52, 0.0, 0.0)),
            "closest_point_count": 3,
            "sphere_radius": 0.02,
            "filter_cylinder_radius": 1.0,
            "filter_cylinder_height": 1.0,
            "debug_output_markers": True,
        },
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    spheres = run.outputs["collision_object"]
    centres = sorted(p.position.x for p in spheres.primitive_poses)
    assert centres == pytest.approx([0.4, 0.5, 0.6]) and spheres.primitives[0].dimensions[0] == 0.02
    assert len(run.outputs["marker_poses"]) == 3 and run.outputs["marker_scale_xyz"] == [0.04] * 3
