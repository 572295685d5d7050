from __future__ import annotations

import numpy as np
import pytest

from kinema.errors import MotionError
from kinema.motion import JointPath, JointTrajectory, plan_joint_goal, time_parameterize


def _limits(model, names):
    idx = [model.index(n) for n in names]
    return model.max_velocity[idx], model.max_acceleration[idx]


@pytest.fixture
def pick_path(checker, waypoint_q, arm_goal):
    return plan_joint_goal(
        checker, waypoint_q("3 Waypoint Mid Point"), arm_goal("3 Waypoint Pick Pose"), group="manipulator"
    )


@pytest.mark.parametrize(("vscale", "ascale"), [(1.0, 1.0), (0.5, 0.25), (0.1, 1.0)])
def test_sampled_trajectory_respects_scaled_limits(model, pick_path, vscale, ascale):
    traj = time_parameterize(pick_path, model, vscale, ascale)
    vmax, amax = _limits(model, traj.joint_names)
    ts = np.arange(0.0, traj.duration, 0.001)
    samples = [traj.sample(t) for t in ts]
    q = np.array([s[0] for s in samples])
    qd = np.array([s[1] for s in samples])
    assert np.all(np.abs(traj.velocities) <= vmax * vscale * (1 + 1e-6))
    assert np.all(np.abs(traj.accelerations) <= amax * ascale * (1 + 1e-6))
    # Between the points too: interpolated and finite-difference velocities stay within the limits.
    assert np.all(np.abs(qd) <= vmax * vscale * 1.01)
    assert np.all(np.abs(np.diff(q, axis=0) / 0.001) <= vmax * vscale * 1.01)
    fd_acc = np.diff(qd, axis=0) / 0.001
    assert np.percentile(np.abs(fd_acc) / (amax * ascale), 99) <= 1.05


def test_trajectory_starts_and_ends_at_rest_on_the_path(model, pick_path):
    traj = time_parameterize(pick_path, model)
    np.testing.assert_allclose(traj.positions[0], pick_path.positions[0])
    np.testing.assert_allclose(traj.positions[-1], pick_path.positions[-1])
    assert np.all(traj.velocities[0] == 0) and np.all(traj.velocities[-1] == 0)
    # The straight path is followed: every sample lies on the segment between start and goal.
    a, b = pick_path.positions[0], pick_path.positions[-1]
    u = (b - a) / np.linalg.norm(b - a)
    off_line = (traj.positions - a) - np.outer((traj.positions - a) @ u, u)
    assert np.abs(off_line).max() < 0.01


def test_slower_scale_takes_longer(model, pick_path):
    fast = time_parameterize(pick_path, model, 1.0, 1.0)
    slow = time_parameterize(pick_path, model, 0.5, 0.5)
    # Halving both limits stretches an acceleration-bound move by sqrt(2), a velocity-bound one by 2.
    assert 1.41 * fast.duration < slow.duration < 2.01 * fast.duration


def test_zero_length_path_gives_a_single_point(model, waypoint_q):
    q = waypoint_q("Home")[:7]
    names = model.group("manipulator").joint_names
    traj = time_parameterize(JointPath(names, np.array([q, q])), model)
    assert traj.duration == 0.0
    np.testing.assert_allclose(traj.sample(1.0)[0], q)


@pytest.mark.parametrize("scale", [0.0, -0.5, 1.5])
def test_bad_scale_factors_are_rejected(model, pick_path, scale):
    with pytest.raises(MotionError, match="scale factor must be in \\(0, 1\\]"):
        time_parameterize(pick_path, model, velocity_scale=scale)


def test_sample_is_exact_at_points_and_clamped_outside():
    names = ("a", "b")
    traj = JointTrajectory(
        names,
        np.array([0.0, 1.0, 2.0]),
        np.array([[0.0, 0.0], [1.0, 2.0], [2.0, 2.0]]),
        np.array([[0.0, 0.0], [1.0, 1.0], [0.0, 0.0]]),
        np.zeros((3, 2)),
    )
    np.testing.assert_allclose(traj.sample(1.0)[0], [1.0, 2.0])
    np.testing.assert_allclose(traj.sample(1.0)[1], [1.0, 1.0])
    np.testing.assert_allclose(traj.sample(-1.0)[0], [0.0, 0.0])
    np.testing.assert_allclose(traj.sample(5.0)[0], [2.0, 2.0])
    assert 0.0 < traj.sample(0.5)[0][0] < 1.0


def test_malformed_trajectory_is_rejected():
    with pytest.raises(MotionError, match="times must increase"):
        JointTrajectory(("a",), np.array([0.0, 0.0]), np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((2, 1)))
    with pytest.raises(MotionError, match="positions must have shape"):
        JointTrajectory(("a",), np.array([0.0]), np.zeros((1, 2)), np.zeros((1, 1)), np.zeros((1, 1)))


def test_from_points_fills_in_velocities_so_motion_does_not_stop_at_points():
    traj = JointTrajectory.from_points(["a"], [0.0, 1.0, 2.0], [[0.0], [1.0], [2.0]])
    assert traj.velocities[:, 0].tolist() == [0.0, 1.0, 0.0]
    assert traj.sample(1.0)[1][0] == pytest.approx(1.0)
    with pytest.raises(MotionError, match="times must increase"):
        JointTrajectory.from_points(["a"], [0.0, 0.0], [[0.0], [1.0]])


def test_from_points_rejects_mismatched_lengths():
    with pytest.raises(MotionError, match="needs 2 rows of 2 values"):
        JointTrajectory.from_points(["a", "b"], [0.0, 1.0], [[0.0, 1.0], [1.0]])


def test_a_grid_toppra_cannot_solve_is_retried_on_a_finer_uniform_one(model, pick_path, monkeypatch):
    import toppra.algorithm as algo

    solve = algo.TOPPRA.compute_trajectory
    grids: list[int] = []

    def fails_on_the_automatic_grid(self, *args, **kwargs):
        grids.append(len(self.gridpoints))
        # The automatic grid is not uniform; the retry's is.
        uniform = np.allclose(np.diff(self.gridpoints), np.diff(self.gridpoints)[0])
        return solve(self, *args, **kwargs) if uniform else None

    monkeypatch.setattr(algo.TOPPRA, "compute_trajectory", fails_on_the_automatic_grid)
    traj = time_parameterize(pick_path, model)
    assert len(grids) >= 2 and grids[1] == 2 * grids[0] + 1, grids
    np.testing.assert_allclose(traj.positions[-1], pick_path.positions[-1])

    # When no grid works, the path is timed segment by segment from rest to rest, within the limits.
    monkeypatch.setattr(algo.TOPPRA, "compute_trajectory", lambda self, *a, **k: None)
    slow = time_parameterize(pick_path, model)
    np.testing.assert_allclose(slow.positions[0], pick_path.positions[0])
    np.testing.assert_allclose(slow.positions[-1], pick_path.positions[-1])
    idx = [model.index(n) for n in pick_path.joint_names]
    assert np.all(np.abs(slow.velocities) <= model.max_velocity[idx] * (1 + 1e-9))
    assert np.all(np.abs(slow.accelerations) <= model.max_acceleration[idx] * (1 + 1e-9))
    # every waypoint of the path is passed, at rest
    for waypoint in pick_path.positions:
        assert np.min(np.abs(slow.positions - waypoint).max(axis=1)) < 1e-3


def test_timing_many_paths_adds_no_log_handlers(model, pick_path):
    """Nothing grows with use: timing a path once per run must not add a handler to toppra's logger each
    time (``toppra.setup_logging`` did: one StreamHandler per timed path in a long-running agent)."""
    import logging

    toppra_logger = logging.getLogger("toppra")
    time_parameterize(pick_path, model)
    before = list(toppra_logger.handlers)
    for _ in range(20):
        time_parameterize(pick_path, model)
    assert toppra_logger.handlers == before
    assert len(toppra_logger.handlers) <= 1
    assert toppra_logger.level == logging.WARNING


def test_timing_a_path_loads_neither_matplotlib_nor_scipy_and_toppra_still_can() -> None:
    """toppra imports matplotlib.pyplot (plots) and scipy.interpolate (its own splines) at its top, for parts
    timing never uses (about 30 and 35 MB in every agent); they load only when something uses them, and
    then they are the real ones."""
    import subprocess
    import sys

    script = """
import sys
import numpy as np
from kinema.motion import JointPath, RobotDescription, time_parameterize
model = RobotDescription.lab_sim().load_model()
arm = model.group("manipulator").joint_names
path = JointPath(tuple(arm), np.array([np.zeros(len(arm)), np.full(len(arm), 0.3)]))
trajectory = time_parameterize(path, model)
assert trajectory.duration > 0
print("matplotlib" in sys.modules, "scipy" in sys.modules)
import toppra
spline = toppra.SplineInterpolator([0.0, 1.0, 2.0], [[0.0], [1.0], [0.0]], bc_type="clamped")
print(float(spline(1.0)[0]), "scipy.interpolate" in sys.modules)
import toppra.algorithm.algorithm as algorithm
import matplotlib.pyplot
print(algorithm.plt.plot is matplotlib.pyplot.plot)
"""
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["False", "False", "1.0", "True", "True"]
