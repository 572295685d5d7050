"""ICP registration, PCD files, STL surface sampling and the sensor_msgs edge."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from kinema.errors import PerceptionError
from kinema.interfaces import load_interfaces
from kinema.perception import (
    CameraIntrinsics,
    PointCloud,
    depth_to_cloud,
    load_pcd,
    register_icp,
    sample_mesh_surface,
    save_pcd,
)
from kinema.perception.ros_messages import (
    camera_info_message,
    from_point_cloud2,
    image_array,
    image_message,
    intrinsics_of,
    to_point_cloud2,
)


def _pose(roll: float, pitch: float, yaw: float, xyz: tuple[float, float, float]) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    transform = np.eye(4)
    transform[:3, :3] = Rotation.from_euler("xyz", [roll, pitch, yaw]).as_matrix()
    transform[:3, 3] = xyz
    return transform


@pytest.fixture
def part_stl(tmp_path: Path) -> Path:
    """An L-shaped part (two boxes; no symmetry ICP could settle into), in millimetres, as binary STL."""
    import trimesh

    part = trimesh.util.concatenate(
        [
            trimesh.creation.box((80.0, 40.0, 20.0)),
            trimesh.creation.box((20.0, 40.0, 60.0), transform=_pose(0, 0, 0, (30.0, 0.0, 40.0))),
        ]
    )
    path = tmp_path / "part.stl"
    part.export(path)
    return path


def _on_box_surface(points: np.ndarray, centre: tuple, size: tuple, tol: float = 1e-3) -> np.ndarray:
    offset = np.abs(points - np.asarray(centre)) - np.asarray(size) / 2
    return np.all(offset <= tol, axis=1) & np.any(np.abs(offset) <= tol, axis=1)


def test_stl_sampling_puts_points_on_the_surface_reproducibly(part_stl: Path) -> None:
    cloud = sample_mesh_surface(part_stl, 2000, scale=0.001, seed=7, frame_id="part", color=(0, 255, 0))
    again = sample_mesh_surface(part_stl, 2000, scale=0.001, seed=7)
    assert len(cloud) == 2000 and cloud.frame_id == "part"
    np.testing.assert_array_equal(cloud.points, again.points)
    np.testing.assert_array_equal(cloud.colors[0], [0, 255, 0])
    mm = cloud.points.astype(float) / 0.001
    on_surface = _on_box_surface(mm, (0.0, 0.0, 0.0), (80.0, 40.0, 20.0)) | _on_box_surface(
        mm, (30.0, 0.0, 40.0), (20.0, 40.0, 60.0)
    )
    assert on_surface.all(), f"{np.sum(~on_surface)} points off the part's faces, e.g. {mm[~on_surface][:3]}"
    assert np.ptp(cloud.points[:, 0]) == pytest.approx(0.08, abs=0.002)  # scaled to metres


def test_stl_sampling_names_a_missing_file(tmp_path: Path) -> None:
    with pytest.raises(PerceptionError, match="no such mesh file"):
        sample_mesh_surface(tmp_path / "missing.stl", 10)


@pytest.mark.parametrize(
    "motion",
    [
        (0.0, 0.0, math.radians(10), (0.03, -0.02, 0.01)),
        (math.radians(5), math.radians(-8), math.radians(-12), (-0.02, 0.0, 0.04)),
    ],
)
def test_icp_recovers_a_known_motion(part_stl: Path, motion: tuple) -> None:
    model = sample_mesh_surface(part_stl, 3000, scale=0.001, seed=1)
    truth = _pose(*motion)
    # The "scene": a different sample of the same part, moved, with 1 mm noise.
    scene = sample_mesh_surface(part_stl, 4000, scale=0.001, seed=2).transformed(truth)
    noisy = PointCloud(scene.points + np.random.default_rng(0).normal(0, 0.001, scene.points.shape))
    result = register_icp(model, noisy, max_correspondence_distance=0.05, max_iterations=100)
    error = np.linalg.inv(truth) @ result.target_T_source
    angle = math.degrees(math.acos(np.clip((np.trace(error[:3, :3]) - 1) / 2, -1, 1)))
    assert np.linalg.norm(error[:3, 3]) < 0.002 and angle < 1.0, (
        f"ICP is off by {np.linalg.norm(error[:3, 3]) * 1000:.1f} mm and {angle:.2f} degrees "
        f"after {result.iterations} iterations (fitness {result.fitness:.2f}, rmse {result.rmse:.4f})"
    )
    assert result.fitness > 0.9


def test_icp_says_when_the_clouds_do_not_overlap() -> None:
    a = PointCloud(np.random.default_rng(0).uniform(0, 0.1, (100, 3)))
    b = a.transformed(_pose(0, 0, 0, (5.0, 0.0, 0.0)))
    with pytest.raises(PerceptionError, match="do not overlap"):
        register_icp(a, b, max_correspondence_distance=0.05)


@pytest.mark.parametrize("compressed", [True, False])
def test_pcd_round_trip_keeps_points_colours_and_organisation(tmp_path: Path, compressed: bool) -> None:
    rng = np.random.default_rng(5)
    points = rng.normal(size=(12, 3)).astype(np.float32)
    points[3] = np.nan
    cloud = PointCloud(points, rng.integers(0, 255, (12, 3), dtype=np.uint8), shape=(3, 4))
    path = save_pcd(cloud, tmp_path / "cloud.pcd", compressed=compressed)
    loaded = load_pcd(path, frame_id="world")
    np.testing.assert_array_equal(loaded.points, cloud.points)
    np.testing.assert_array_equal(loaded.colors, cloud.colors)
    assert loaded.shape == (3, 4) and loaded.frame_id == "world"
    assert [p.name for p in tmp_path.iterdir()] == ["cloud.pcd"]  # no temporary file left behind


def test_pcd_reads_an_ascii_file_as_pcl_writes_it(tmp_path: Path) -> None:
    path = tmp_path / "ascii.pcd"
    path.write_text(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
        "COUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n1 2 3\n4.5 5 6\n"
    )
    cloud = load_pcd(path)
    np.testing.assert_allclose(cloud.points, [[1, 2, 3], [4.5, 5, 6]])
    assert cloud.colors is None


def test_pcd_errors_name_the_file(tmp_path: Path) -> None:
    with pytest.raises(PerceptionError, match=r"missing\.pcd: no such"):
        load_pcd(tmp_path / "missing.pcd")
    (tmp_path / "bad.pcd").write_text("not a point cloud\n")
    with pytest.raises(PerceptionError, match=r"bad\.pcd: not a readable PCD"):
        load_pcd(tmp_path / "bad.pcd")


def test_point_cloud2_through_cdr_keeps_points_nan_colours_frame_and_stamp() -> None:
    registry = load_interfaces()
    types = registry.typestore.types
    k = CameraIntrinsics.from_fovy(8, 6, 60.0)
    depth = np.full((6, 8), 1.5, dtype=np.float32)
    depth[2, 3] = np.nan
    colors = np.arange(6 * 8 * 3, dtype=np.uint8).reshape(6, 8, 3)
    cloud = depth_to_cloud(depth, k, colors, frame_id="cam_optical", stamp=12.25)
    message = to_point_cloud2(cloud, types)
    wire = registry.serialize(message, "sensor_msgs/msg/PointCloud2")
    back = from_point_cloud2(registry.deserialize(bytes(wire), "sensor_msgs/msg/PointCloud2"))
    assert (back.frame_id, back.stamp, back.shape) == ("cam_optical", 12.25, (6, 8))
    np.testing.assert_array_equal(back.points, cloud.points)
    np.testing.assert_array_equal(back.colors, cloud.colors)
    assert message.point_step == 16 and message.row_step == 16 * 8 and not message.is_dense


def test_images_and_camera_info_through_cdr() -> None:
    registry = load_interfaces()
    types = registry.typestore.types
    rgb = np.random.default_rng(0).integers(0, 255, (6, 8, 3), dtype=np.uint8)
    depth = np.linspace(0.5, 2.0, 48, dtype=np.float32).reshape(6, 8)
    for pixels, encoding in ((rgb, "rgb8"), (depth, "32FC1")):
        message = image_message(pixels, encoding, "cam", 1.0, types)
        wire = registry.serialize(message, "sensor_msgs/msg/Image")
        np.testing.assert_array_equal(
            image_array(registry.deserialize(bytes(wire), "sensor_msgs/msg/Image")), pixels
        )
    k = CameraIntrinsics.from_fovy(640, 480, 55.0)
    info = camera_info_message(k, "cam", 1.0, types)
    wire = registry.serialize(info, "sensor_msgs/msg/CameraInfo")
    back = registry.deserialize(bytes(wire), "sensor_msgs/msg/CameraInfo")
    assert intrinsics_of(back) == k
    np.testing.assert_allclose(np.asarray(back.p).reshape(3, 4)[:, :3], k.k)
