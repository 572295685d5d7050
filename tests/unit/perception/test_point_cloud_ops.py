"""Point clouds as arrays: depth back-projection, transforms, boxes, centroid, voxel grids."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kinema.errors import PerceptionError
from kinema.perception import (
    CameraIntrinsics,
    PointCloud,
    crop_box,
    depth_to_cloud,
    merge_clouds,
    remove_box,
    voxel_downsample,
)


def _pose(yaw: float = 0.0, xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    transform = np.eye(4)
    transform[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    transform[:3, 3] = xyz
    return transform


@pytest.mark.parametrize(
    ("width", "height", "fovy", "f"),
    [(640, 480, 90.0, 240.0), (640, 480, 60.0, 240.0 * math.sqrt(3)), (1280, 720, 90.0, 360.0)],
)
def test_intrinsics_from_fovy(width: int, height: int, fovy: float, f: float) -> None:
    k = CameraIntrinsics.from_fovy(width, height, fovy)
    assert (k.fx, k.fy) == pytest.approx((f, f))
    assert (k.cx, k.cy) == ((width - 1) / 2, (height - 1) / 2)


def test_depth_to_cloud_back_projects_each_pixel_onto_its_ray() -> None:
    k = CameraIntrinsics.from_fovy(64, 48, 60.0)
    rng = np.random.default_rng(1)
    depth = rng.uniform(0.5, 3.0, (48, 64)).astype(np.float32)
    depth[0, 0], depth[1, 1], depth[2, 2] = 0.0, np.inf, 9.0
    colors = rng.integers(0, 255, (48, 64, 3), dtype=np.uint8)
    cloud = depth_to_cloud(depth, k, colors, frame_id="cam", stamp=2.5, max_depth=5.0)
    assert (
        cloud.shape == (48, 64) and len(cloud) == 48 * 64 and cloud.frame_id == "cam" and cloud.stamp == 2.5
    )
    grid = cloud.points.reshape(48, 64, 3)
    assert np.isnan(grid[0, 0]).all() and np.isnan(grid[1, 1]).all() and np.isnan(grid[2, 2]).all()
    valid = np.isfinite(cloud.points).all(axis=1)
    pixels = k.project(cloud.points[valid])
    v, u = np.divmod(np.flatnonzero(valid), 64)
    np.testing.assert_allclose(pixels, np.stack([u, v], axis=1), atol=1e-3)
    np.testing.assert_allclose(cloud.points[valid, 2], depth.reshape(-1)[valid], rtol=1e-6)
    np.testing.assert_array_equal(cloud.colors, colors.reshape(-1, 3))


def test_depth_to_cloud_rejects_a_depth_image_of_another_size() -> None:
    with pytest.raises(PerceptionError, match=r"\(64, 48\).*\(32, 24\)"):
        depth_to_cloud(np.ones((48, 64)), CameraIntrinsics.from_fovy(32, 24, 60.0))


def test_transform_moves_points_and_keeps_nan_and_organisation() -> None:
    cloud = PointCloud(np.array([[1.0, 0.0, 0.0], [np.nan, np.nan, np.nan]]), frame_id="a", shape=(1, 2))
    moved = cloud.transformed(_pose(math.pi / 2, (0.0, 0.0, 1.0)), "b")
    np.testing.assert_allclose(moved.points[0], [0.0, 1.0, 1.0], atol=1e-12)
    assert np.isnan(moved.points[1]).all() and moved.shape == (1, 2) and moved.frame_id == "b"


def test_centroid_ignores_missing_points_and_refuses_an_empty_cloud() -> None:
    cloud = PointCloud(np.array([[0.0, 0.0, 0.0], [2.0, 4.0, 6.0], [np.nan, 0.0, 0.0]]))
    np.testing.assert_allclose(cloud.centroid(), [1.0, 2.0, 3.0])
    with pytest.raises(PerceptionError, match="no points"):
        PointCloud(np.full((2, 3), np.nan)).centroid()


def test_bad_shapes_are_refused_with_what_was_given() -> None:
    with pytest.raises(PerceptionError, match=r"Nx3.*\(4,\)"):
        PointCloud(np.zeros(4))
    with pytest.raises(PerceptionError, match="colours"):
        PointCloud(np.zeros((2, 3)), np.zeros((3, 3)))


# A box 0.2 x 0.1 x 0.1 m at (1, 0, 0) turned 90 degrees about z: it spans 0.1 in x and 0.2 in y.
BOX_POSE = _pose(math.pi / 2, (1.0, 0.0, 0.0))
BOX_SIZE = (0.2, 0.1, 0.1)


@pytest.mark.parametrize(
    ("point", "inside"),
    [
        ((1.0, 0.0, 0.0), True),
        ((1.0, 0.09, 0.0), True),  # along the box's long side, now world y
        ((1.09, 0.0, 0.0), False),  # would be inside the unturned box
        ((1.0, 0.0, 0.06), False),
        ((1.04, -0.09, 0.04), True),
        ((np.nan, 0.0, 0.0), False),
    ],
)
def test_crop_and_remove_split_a_cloud_at_a_posed_box(point: tuple[float, ...], inside: bool) -> None:
    cloud = PointCloud(np.array([point, (5.0, 5.0, 5.0)]), np.array([[1, 2, 3], [4, 5, 6]]))
    kept, removed = crop_box(cloud, BOX_POSE, BOX_SIZE), remove_box(cloud, BOX_POSE, BOX_SIZE)
    assert len(kept) == (1 if inside else 0)
    assert len(removed) == (1 if inside or np.isnan(point[0]) else 2)
    if inside:
        np.testing.assert_array_equal(kept.colors, [[1, 2, 3]])


def test_a_negative_box_size_is_refused() -> None:
    with pytest.raises(PerceptionError, match="box size"):
        crop_box(PointCloud(np.zeros((1, 3))), np.eye(4), (0.1, -0.1, 0.1))


def test_voxel_grid_keeps_one_averaged_point_per_occupied_voxel() -> None:
    points = np.array([[0.01, 0.01, 0.01], [0.03, 0.03, 0.03], [0.11, 0.01, 0.01], [np.nan, 0.0, 0.0]])
    colors = np.array([[0, 0, 0], [100, 100, 100], [255, 0, 0], [1, 1, 1]])
    result = voxel_downsample(PointCloud(points, colors, frame_id="w"), 0.05)
    order = np.argsort(result.points[:, 0])
    np.testing.assert_allclose(result.points[order], [[0.02, 0.02, 0.02], [0.11, 0.01, 0.01]])
    np.testing.assert_array_equal(result.colors[order], [[50, 50, 50], [255, 0, 0]])
    with pytest.raises(PerceptionError, match="positive"):
        voxel_downsample(PointCloud(points), 0.0)


def test_merging_overlapping_clouds_does_not_double_the_points() -> None:
    rng = np.random.default_rng(3)
    plane = np.column_stack([rng.uniform(0, 1, 5000), rng.uniform(0, 1, 5000), np.zeros(5000)])
    a, b = (
        PointCloud(plane, frame_id="world", stamp=1.0),
        PointCloud(plane + 1e-4, frame_id="world", stamp=2.0),
    )
    merged = merge_clouds([a, b], 0.05)
    # 10 000 points on a 1 m square at 5 cm: one point per occupied 5 cm cell (20 x 20, a few more where
    # the second copy's offset crosses a cell border).
    assert 400 <= len(merged) <= 21 * 21, len(merged)
    assert merged.stamp == 2.0 and merged.frame_id == "world"


def test_merging_clouds_in_different_frames_says_which() -> None:
    with pytest.raises(PerceptionError, match=r"'camera'.*'world'"):
        merge_clouds(
            [PointCloud(np.zeros((1, 3)), frame_id="world"), PointCloud(np.zeros((1, 3)), frame_id="camera")],
            0.1,
        )
