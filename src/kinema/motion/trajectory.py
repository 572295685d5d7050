"""Joint paths (geometry only) and timed joint trajectories (what a trajectory controller executes)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from kinema.errors import MotionError


@dataclass(frozen=True, eq=False)  # holds numpy arrays: compare fields explicitly
class JointPath:
    """A piecewise-linear path in joint space, not yet timed.

    Attributes:
        joint_names: the joints the path moves, in column order.
        positions: waypoints, shape ``(N, n)`` (m / rad); consecutive waypoints are joined by straight lines.
    """

    joint_names: tuple[str, ...]
    positions: np.ndarray

    @property
    def length(self) -> float:
        """Sum of the Euclidean joint-space lengths of the segments."""
        return (
            float(np.linalg.norm(np.diff(self.positions, axis=0), axis=1).sum())
            if len(self.positions) > 1
            else 0.0
        )


@dataclass(frozen=True, eq=False)  # holds numpy arrays: compare fields explicitly
class JointTrajectory:
    """A timed joint trajectory, like ``trajectory_msgs/JointTrajectory``.

    Attributes:
        joint_names: joint of each column.
        times: time from start of each point, shape ``(N,)``, seconds, starting at 0 and increasing.
        positions: shape ``(N, n)``, m / rad.
        velocities: shape ``(N, n)``, m/s / rad/s.
        accelerations: shape ``(N, n)``, m/s² / rad/s².
    """

    joint_names: tuple[str, ...]
    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray

    def __post_init__(self) -> None:
        n, k = len(self.times), len(self.joint_names)
        for label, arr in (
            ("positions", self.positions),
            ("velocities", self.velocities),
            ("accelerations", self.accelerations),
        ):
            if arr.shape != (n, k):
                raise MotionError(f"trajectory {label} must have shape ({n}, {k}), got {arr.shape}")
        if n == 0:
            raise MotionError("a trajectory needs at least one point")
        if n > 1 and np.any(np.diff(self.times) <= 0):
            raise MotionError("trajectory times must increase strictly")

    @classmethod
    def from_points(
        cls,
        joint_names: Sequence[str],
        times: Sequence[float],
        positions: Sequence[Sequence[float]],
        velocities: Sequence[Sequence[float]] | None = None,
        accelerations: Sequence[Sequence[float]] | None = None,
    ) -> JointTrajectory:
        """Build a trajectory from plain lists (a received ``trajectory_msgs/JointTrajectory``, say).

        Missing velocities are estimated by central differences (zero at both ends), so :meth:`sample`
        passes through the points smoothly instead of stopping at each; missing accelerations are zero.

        Raises:
            MotionError: inconsistent lengths or times that do not increase.
        """
        shape = (len(times), len(joint_names))
        try:
            t = np.asarray(times, dtype=float)
            q = np.asarray(positions, dtype=float).reshape(shape)
            if velocities is None or len(velocities) == 0:
                qd = np.zeros_like(q)
                if len(t) > 2:
                    qd[1:-1] = (q[2:] - q[:-2]) / (t[2:] - t[:-2])[:, None]
            else:
                qd = np.asarray(velocities, dtype=float).reshape(shape)
            if accelerations is None or len(accelerations) == 0:
                qdd = np.zeros_like(q)
            else:
                qdd = np.asarray(accelerations, dtype=float).reshape(shape)
        except ValueError as exc:
            raise MotionError(
                f"a trajectory of {shape[0]} points over {shape[1]} joints ({', '.join(joint_names)}) "
                f"needs {shape[0]} rows of {shape[1]} values each: {exc}"
            ) from exc
        return cls(tuple(joint_names), t, q, qd, qdd)

    @property
    def duration(self) -> float:
        """Time of the last point, seconds."""
        return float(self.times[-1])

    def sample(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """State at time ``t`` (clamped to ``[0, duration]``): positions, velocities, accelerations ``(n,)``.

        Between points, positions follow the cubic Hermite spline through the points' positions and
        velocities (so velocities are continuous); accelerations are interpolated linearly.
        """
        times = self.times
        if t <= times[0] or len(times) == 1:
            return self.positions[0].copy(), self.velocities[0].copy(), self.accelerations[0].copy()
        if t >= times[-1]:
            return self.positions[-1].copy(), self.velocities[-1].copy(), self.accelerations[-1].copy()
        i = int(np.searchsorted(times, t, side="right")) - 1
        h = times[i + 1] - times[i]
        s = (t - times[i]) / h
        p0, p1 = self.positions[i], self.positions[i + 1]
        m0, m1 = self.velocities[i] * h, self.velocities[i + 1] * h
        s2, s3 = s * s, s * s * s
        q = (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * m1
        dq = (
            (6 * s2 - 6 * s) * p0 + (3 * s2 - 4 * s + 1) * m0 + (-6 * s2 + 6 * s) * p1 + (3 * s2 - 2 * s) * m1
        ) / h
        a = self.accelerations[i] + s * (self.accelerations[i + 1] - self.accelerations[i])
        return q, dq, a
