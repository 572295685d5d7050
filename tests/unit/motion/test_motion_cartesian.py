from __future__ import annotations

import numpy as np
import pytest

from kinema.errors import MotionError
from kinema.motion import fk, plan_cartesian_path


def test_straight_descent_follows_the_line(model, checker, waypoint_q):
    start = waypoint_q("3 Waypoint Mid Point")
    T0 = fk(model, start, "grasp_link")
    T1 = T0.copy()
    T1[2, 3] -= 0.15
    result = plan_cartesian_path(checker, start, [T1], group="manipulator")
    assert result.fraction == pytest.approx(1.0)
    assert result.reason == ""
    cols = list(model.group("manipulator").indices)
    for row in result.path.positions:
        q = start.copy()
        q[cols] = row
        T = fk(model, q, "grasp_link")
        assert np.linalg.norm(T[:2, 3] - T0[:2, 3]) < 1e-3  # stays on the vertical line
        assert np.abs(T[:3, :3] - T0[:3, :3]).max() < 2e-3  # keeps the orientation
    q_end = start.copy()
    q_end[cols] = result.path.positions[-1]
    assert np.linalg.norm(fk(model, q_end, "grasp_link")[:3, 3] - T1[:3, 3]) < 1e-3


def test_path_into_the_table_stops_early_with_the_reason(model, checker, waypoint_q):
    start = waypoint_q("3 Waypoint Pick Pose")
    T = fk(model, start, "grasp_link")
    T[2, 3] -= 0.10  # 10 cm down from 25 mm above the table
    result = plan_cartesian_path(checker, start, [T], group="manipulator")
    assert 0.0 < result.fraction < 0.3
    assert "collision" in result.reason and "table" in result.reason


def test_several_waypoints_and_empty_input(model, checker, waypoint_q):
    start = waypoint_q("3 Waypoint Mid Point")
    T0 = fk(model, start, "grasp_link")
    square = []
    for dx, dy in [(0.05, 0.0), (0.05, 0.05), (0.0, 0.05), (0.0, 0.0)]:
        T = T0.copy()
        T[0, 3] += dx
        T[1, 3] += dy
        square.append(T)
    assert plan_cartesian_path(checker, start, square, group="manipulator").fraction == pytest.approx(1.0)
    with pytest.raises(MotionError, match="at least one waypoint"):
        plan_cartesian_path(checker, start, [], group="manipulator")


def _corner(model, start):
    """A 90-degree corner: 10 cm along +x, then 10 cm along +y, at the Mid Point's tool height."""
    T0 = fk(model, start, "grasp_link")
    corner = T0.copy()
    corner[0, 3] += 0.1
    end = corner.copy()
    end[1, 3] += 0.1
    return corner, end


def _tool_positions(model, start, rows):
    cols = list(model.group("manipulator").indices)
    out = []
    for row in rows:
        q = start.copy()
        q[cols] = row
        out.append(fk(model, q, "grasp_link")[:3, 3])
    return np.array(out)


@pytest.mark.parametrize("radius", [0.0, 0.03])
def test_a_blended_corner_is_cut_by_the_radius_and_keeps_moving(model, checker, waypoint_q, radius):
    from kinema.motion import time_parameterize

    start = waypoint_q("3 Waypoint Mid Point")
    corner, end = _corner(model, start)
    result = plan_cartesian_path(checker, start, [corner, end], blending_radius=radius, group="manipulator")
    assert result.fraction == pytest.approx(1.0), result.reason
    tool = _tool_positions(model, start, result.path.positions)
    closest = np.linalg.norm(tool - corner[:3, 3], axis=1).min()
    assert closest == pytest.approx(radius * (np.sqrt(2) - 1), abs=1e-3), f"closest approach {closest:.4f} m"
    np.testing.assert_allclose(tool[-1], end[:3, 3], atol=1e-3)  # the end is reached exactly

    trajectory = time_parameterize(result.path, model)
    timed = _tool_positions(model, start, trajectory.positions)
    speed = np.linalg.norm(np.diff(timed, axis=0), axis=1) / np.diff(trajectory.times)
    at_corner = speed[min(int(np.linalg.norm(timed - corner[:3, 3], axis=1).argmin()), len(speed) - 1)]
    if radius > 0:
        # the tool sweeps round the corner instead of stopping in it
        assert at_corner > 0.3 * speed.max(), f"{at_corner:.3f} m/s at the corner, peak {speed.max():.3f}"
    else:
        assert at_corner < 0.3 * speed.max(), f"{at_corner:.3f} m/s at the corner, peak {speed.max():.3f}"
    # no joint-velocity jump: between samples the velocities change no faster than the acceleration limits
    idx = [model.index(n) for n in trajectory.joint_names]
    dv = np.abs(np.diff(trajectory.velocities, axis=0)) / np.diff(trajectory.times)[:, None]
    assert np.all(dv <= model.max_acceleration[idx] * 1.05), dv.max(axis=0)


def test_radius_zero_is_the_exact_path_and_a_negative_radius_is_refused(model, checker, waypoint_q):
    start = waypoint_q("3 Waypoint Mid Point")
    corner, end = _corner(model, start)
    exact = plan_cartesian_path(checker, start, [corner, end], group="manipulator")
    zero = plan_cartesian_path(checker, start, [corner, end], blending_radius=0.0, group="manipulator")
    np.testing.assert_array_equal(exact.path.positions, zero.path.positions)
    with pytest.raises(MotionError, match="blending_radius must be >= 0"):
        plan_cartesian_path(checker, start, [corner, end], blending_radius=-0.01, group="manipulator")


def test_an_ik_iteration_cap_too_small_for_the_steps_stops_the_path(model, checker, waypoint_q):
    start = waypoint_q("3 Waypoint Mid Point")
    corner, end = _corner(model, start)
    # one IK sample every 10 cm: one damped least-squares step cannot land on it, fifty can
    hard = {"max_step": 0.1, "jump_threshold": 3.0}
    capped = plan_cartesian_path(checker, start, [corner, end], max_iterations=1, group="manipulator", **hard)
    assert capped.fraction < 1.0
    assert "the IK did not converge within 1 iteration(s)" in capped.reason, capped.reason
    roomy = plan_cartesian_path(checker, start, [corner, end], max_iterations=50, group="manipulator", **hard)
    assert roomy.fraction == pytest.approx(1.0), roomy.reason
    # on this easy corner one step per default 5 mm sample is enough
    fine = plan_cartesian_path(
        checker, start, [corner, end], blending_radius=0.02, max_iterations=1, group="manipulator"
    )
    assert fine.fraction == pytest.approx(1.0), fine.reason
