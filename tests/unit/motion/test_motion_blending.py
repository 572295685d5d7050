"""Corner blending geometry: circular arcs tangent to both lines, clamped, ends kept."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from kinema.motion.blending import blended_pieces


def _pose(xyz: tuple[float, float, float], yaw: float = 0.0) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = xyz
    pose[:3, :3] = Rotation.from_euler("z", yaw).as_matrix()
    return pose


def _trace(pieces, n: int = 400) -> np.ndarray:
    return np.array([p.pose_at(t) for p in pieces for t in np.linspace(0.0, 1.0, n)])


def test_a_right_angle_is_rounded_by_an_arc_of_the_radius():
    corner = (0.1, 0.0, 0.0)
    pieces = blended_pieces([_pose((0, 0, 0)), _pose(corner), _pose((0.1, 0.1, 0))], 0.02)
    assert [p.center is not None for p in pieces] == [False, True, False]
    arc = pieces[1]
    np.testing.assert_allclose(arc.start, [0.08, 0, 0], atol=1e-12)
    np.testing.assert_allclose(arc.end, [0.1, 0.02, 0], atol=1e-12)
    assert arc.length == pytest.approx(0.02 * np.pi / 2)
    trace = _trace(pieces)[:, :3, 3]
    closest = np.linalg.norm(trace - corner, axis=1).min()
    assert closest == pytest.approx(0.02 * (np.sqrt(2) - 1), abs=1e-6)
    # every arc point stays 0.02 from the centre: a circle, tangent where it meets the lines
    on_arc = np.array([arc.pose_at(t)[:3, 3] for t in np.linspace(0, 1, 50)])
    np.testing.assert_allclose(np.linalg.norm(on_arc - arc.center, axis=1), 0.02, atol=1e-12)
    np.testing.assert_allclose(trace[0], [0, 0, 0])
    np.testing.assert_allclose(trace[-1], [0.1, 0.1, 0], atol=1e-12)


def test_the_path_is_continuous_and_its_direction_too():
    poses = [_pose((0, 0, 0)), _pose((0.1, 0, 0.05)), _pose((0.15, 0.1, 0)), _pose((0.0, 0.2, 0.1))]
    pieces = blended_pieces(poses, 0.03)
    for before, after in itertools.pairwise(pieces):
        np.testing.assert_allclose(before.pose_at(1.0)[:3, 3], after.pose_at(0.0)[:3, 3], atol=1e-12)
        out_dir = before.pose_at(1.0)[:3, 3] - before.pose_at(1 - 1e-6)[:3, 3]
        in_dir = after.pose_at(1e-6)[:3, 3] - after.pose_at(0.0)[:3, 3]
        cos = out_dir @ in_dir / np.linalg.norm(out_dir) / np.linalg.norm(in_dir)
        assert cos > 1 - 1e-6, f"direction turns by {np.degrees(np.arccos(min(cos, 1))):.2f} deg at a joint"


def test_orientation_turns_along_the_blend_without_a_jump():
    poses = [_pose((0, 0, 0), 0.0), _pose((0.1, 0, 0), 0.4), _pose((0.1, 0.1, 0), 0.8)]
    trace = _trace(blended_pieces(poses, 0.02), 200)
    yaws = Rotation.from_matrix(trace[:, :3, :3]).as_euler("xyz")[:, 2]
    assert yaws[0] == pytest.approx(0.0) and yaws[-1] == pytest.approx(0.8)
    assert np.all(np.diff(yaws) >= -1e-9) and np.abs(np.diff(yaws)).max() < 0.01


def test_the_radius_is_clamped_to_half_the_shorter_line():
    poses = [_pose((0, 0, 0)), _pose((0.04, 0, 0)), _pose((0.04, 0.2, 0))]
    arc = blended_pieces(poses, 0.05)[1]
    np.testing.assert_allclose(arc.start, [0.02, 0, 0], atol=1e-12)  # half of the 4 cm line
    np.testing.assert_allclose(arc.end, [0.04, 0.02, 0], atol=1e-12)
    # two blends sharing a short line meet in its middle, no straight piece left between them
    zigzag = [_pose((0, 0, 0)), _pose((0.1, 0, 0)), _pose((0.1, 0.02, 0)), _pose((0.2, 0.02, 0))]
    kinds = [p.center is not None for p in blended_pieces(zigzag, 0.05)]
    assert kinds == [False, True, True, False]


def test_radius_zero_straight_lines_and_reversals_pass_through_the_waypoints():
    poses = [_pose((0, 0, 0)), _pose((0.1, 0, 0)), _pose((0.1, 0.1, 0))]
    pieces = blended_pieces(poses, 0.0)
    assert [p.center for p in pieces] == [None, None]
    np.testing.assert_allclose(pieces[0].end, [0.1, 0, 0])
    straight = blended_pieces([_pose((0, 0, 0)), _pose((0.1, 0, 0)), _pose((0.2, 0, 0))], 0.02)
    assert all(p.center is None for p in straight)
    back = blended_pieces([_pose((0, 0, 0)), _pose((0.1, 0, 0)), _pose((0.0, 0, 0))], 0.02)
    assert all(p.center is None for p in back)
    np.testing.assert_allclose(back[0].end, [0.1, 0, 0])


def test_a_negative_radius_is_refused():
    with pytest.raises(ValueError, match="blending radius must be >= 0"):
        blended_pieces([_pose((0, 0, 0)), _pose((0.1, 0, 0))], -0.01)
