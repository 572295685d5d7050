"""Time parameterization with toppra: the fastest timing of a path under velocity/acceleration limits."""

from __future__ import annotations

import itertools
import logging

import numpy as np

from kinema.errors import MotionError
from kinema.motion.clamped_spline import ClampedCubicSpline
from kinema.motion.robot_model import RobotModel
from kinema.motion.toppra_import import import_toppra
from kinema.motion.trajectory import JointPath, JointTrajectory

log = logging.getLogger(__name__)

# toppra enforces the limits at its grid points only; between them the spline can exceed them (up to ~20 %
# with chord-length parameterization). The limits are therefore derated and the result verified by sampling.
_DERATE = 0.9
_CHECK_DT = 0.002


def _densify(points: np.ndarray, max_step: float) -> np.ndarray:
    out = [points[0]]
    for a, b in itertools.pairwise(points):
        n = max(1, int(np.ceil(np.abs(b - a).max() / max_step)))
        out.extend(a + (b - a) * (k / n) for k in range(1, n + 1))
    return np.array(out)


def _sample_times(duration: float, sample_period: float, uniform: bool) -> np.ndarray:
    """Times of the returned points: ``0, T, 2T, ...`` and the end when ``uniform``, else evenly spread
    with spacing at most ``T``.

    Uniform spacing is what a controller sampling at a fixed rate expects; a last interval shorter than a
    thousandth of ``T`` is merged into the one before, so times always increase by a usable step.
    """
    if not uniform:
        count = max(2, int(np.ceil(duration / sample_period)) + 1)
        return np.linspace(0.0, duration, count)
    times = np.arange(0.0, duration, sample_period)
    if duration - times[-1] < 1e-3 * sample_period and len(times) > 1:
        times = times[:-1]
    return np.r_[times, duration]


def _rest_to_rest(
    names: tuple[str, ...],
    points: np.ndarray,
    vmax: np.ndarray,
    amax: np.ndarray,
    sample_period: float,
    uniform: bool = False,
) -> JointTrajectory:
    """Time each straight segment of ``points`` with a joint-synchronised trapezoid, at rest at each point."""
    pieces: list[tuple[np.ndarray, np.ndarray, float, float, float]] = []  # start, delta, T, t_acc, u_peak
    for a, b in itertools.pairwise(points):
        delta = b - a
        moving = np.abs(delta) > 0
        u_speed = float(np.min(vmax[moving] / np.abs(delta[moving])))  # path parameter u in [0, 1]
        u_accel = float(np.min(amax[moving] / np.abs(delta[moving])))
        if u_speed * u_speed / u_accel >= 1.0:  # triangular: never reaches full speed
            t_acc = float(np.sqrt(1.0 / u_accel))
            pieces.append((a, delta, 2 * t_acc, t_acc, u_accel * t_acc))
        else:
            t_acc = u_speed / u_accel
            pieces.append((a, delta, 1.0 / u_speed + t_acc, t_acc, u_speed))
    duration = sum(piece[2] for piece in pieces)
    times = _sample_times(duration, sample_period, uniform)
    q = np.zeros((len(times), len(names)))
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    begin = 0.0
    for index, (a, delta, total, t_acc, peak) in enumerate(pieces):
        last = index == len(pieces) - 1
        inside = (times >= begin) & ((times <= begin + total) if last else (times < begin + total))
        t = times[inside] - begin
        accel = peak / t_acc
        t_dec = total - t_acc
        u = np.where(
            t < t_acc,
            0.5 * accel * t * t,
            np.where(
                t <= t_dec, 0.5 * peak * t_acc + peak * (t - t_acc), 1.0 - 0.5 * accel * (total - t) ** 2
            ),
        )
        ud = np.where(t < t_acc, accel * t, np.where(t <= t_dec, peak, accel * (total - t)))
        udd = np.where(t < t_acc, accel, np.where(t <= t_dec, 0.0, -accel))
        q[inside] = a + np.outer(np.clip(u, 0.0, 1.0), delta)
        qd[inside] = np.outer(ud, delta)
        qdd[inside] = np.outer(udd, delta)
        begin += total
    qd[0] = qd[-1] = 0.0
    q[0], q[-1] = points[0], points[-1]
    return JointTrajectory(names, times, q, qd, qdd)


def time_parameterize(
    path: JointPath,
    model: RobotModel,
    velocity_scale: float = 1.0,
    acceleration_scale: float = 1.0,
    *,
    sample_period: float = 0.01,
    max_step: float = 0.05,
    uniform_sampling: bool = False,
) -> JointTrajectory:
    """Time ``path`` as fast as the joints' velocity and acceleration limits (times the scale factors) allow.

    The trajectory starts and ends at rest, follows the path within ~0.01 rad (it is splined through the
    path densified to ``max_step``), and its sampled velocities and accelerations stay within the scaled
    limits.

    Args:
        path: the joint path to time.
        model: gives the joints' ``max_velocity`` and ``max_acceleration``.
        velocity_scale: fraction of the velocity limits to use, in (0, 1].
        acceleration_scale: fraction of the acceleration limits to use, in (0, 1].
        sample_period: spacing of the returned points, seconds (at most this, spread evenly over the
            duration, unless ``uniform_sampling``).
        max_step: largest joint change between spline knots (rad or m).
        uniform_sampling: points exactly ``sample_period`` apart from 0, plus one at the end (a
            trajectory "sampled at a rate", as MoveIt Pro's ``trajectory_sampling_rate`` asks).

    Raises:
        MotionError: a scale factor outside (0, 1], a joint without finite limits, or the limits still
            exceeded after derating (when toppra finds no timing at all, the path is timed rest to rest
            at each waypoint).
    """
    ta = import_toppra()
    algo, constraint = ta.algorithm, ta.constraint

    for label, value in (("velocity", velocity_scale), ("acceleration", acceleration_scale)):
        if not 0.0 < value <= 1.0:
            raise MotionError(f"{label} scale factor must be in (0, 1], got {value}")
    idx = [model.index(n) for n in path.joint_names]
    vmax = model.max_velocity[idx] * velocity_scale
    amax = model.max_acceleration[idx] * acceleration_scale
    for name, v, a in zip(path.joint_names, vmax, amax, strict=True):
        if not (np.isfinite(v) and np.isfinite(a)):
            raise MotionError(
                f"joint {name!r} has no velocity or acceleration limit (set them in joint_limits.yaml)"
            )
    points = np.asarray(path.positions, dtype=float)
    keep = np.r_[True, np.abs(np.diff(points, axis=0)).max(axis=1) > 1e-9]
    points = points[keep]
    n = len(path.joint_names)
    if len(points) < 2:
        zeros = np.zeros((1, n))
        return JointTrajectory(path.joint_names, np.zeros(1), points[:1].copy(), zeros, zeros.copy())
    wp = _densify(points, max_step)
    # Chord length in joint units (not normalised to [0, 1]): toppra's automatic grid is spaced in s units.
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(wp, axis=0), axis=1))]
    # Only toppra's level: ta.setup_logging() adds a stderr handler to the "toppra" logger at every call,
    # so a long-running agent gained one (with its formatter and lock) per timed path, without bound, and
    # printed each toppra warning once per handler. Its records reach the process's own log through the
    # root logger.
    logging.getLogger("toppra").setLevel(logging.WARNING)
    spline = ClampedCubicSpline(s, wp)
    derate = _DERATE
    for _ in range(4):
        constraints = [
            constraint.JointVelocityConstraint(np.c_[-vmax * derate, vmax * derate]),
            constraint.JointAccelerationConstraint(np.c_[-amax * derate, amax * derate]),
        ]
        instance = algo.TOPPRA(constraints, spline, parametrizer="ParametrizeConstAccel")
        traj = instance.compute_trajectory(0, 0)
        if traj is None:
            # toppra's reachability solver can fail numerically on one grid (seen once in hundreds of
            # preempted moves); the same problem on a uniform grid twice as fine is solved.
            grid = np.linspace(s[0], s[-1], 2 * len(instance.gridpoints) + 1)
            retry = algo.TOPPRA(constraints, spline, gridpoints=grid, parametrizer="ParametrizeConstAccel")
            traj = retry.compute_trajectory(0, 0)
        if traj is None:
            # Still none (stressed run 114: a straight 0.055 rad path, twice): time the path's straight
            # segments one by one instead, each from rest to rest, which is always feasible.
            log.warning(
                "toppra found no feasible time parameterization for the path (%d waypoints, %.4f rad long; "
                "grids of %d and %d points): timing it segment by segment, stopping at each waypoint",
                len(points),
                s[-1],
                len(instance.gridpoints),
                len(grid),
            )
            return _rest_to_rest(path.joint_names, points, vmax, amax, sample_period, uniform_sampling)
        ts = np.arange(0.0, traj.duration, _CHECK_DT)
        over = max(
            float(np.max(np.abs(traj(ts, 1)) / vmax)),
            float(np.max(np.abs(traj(ts, 2)) / amax)),
        )
        if over <= 1.0:
            break
        derate /= over * 1.02
    else:
        raise MotionError(
            f"toppra's trajectory exceeds the joint limits by {100 * (over - 1):.0f} % after derating"
        )
    times = _sample_times(float(traj.duration), sample_period, uniform_sampling)
    q, qd, qdd = traj(times), traj(times, 1), traj(times, 2)
    qd[0] = qd[-1] = 0.0
    q[0], q[-1] = points[0], points[-1]
    return JointTrajectory(path.joint_names, times, q, qd, qdd)
