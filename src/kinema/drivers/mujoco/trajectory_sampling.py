"""Sample a timed joint trajectory at the control period, the way ros2_control's trajectory controller
interpolates it.

Between two points the interpolation depends on what the points give: positions only → linear,
positions and velocities → cubic Hermite, positions, velocities and accelerations → quintic. When the
first point is later than time 0, a segment from the start state (where the joints are commanded to be
when the trajectory starts) leads to it. Sampling once per goal keeps the physics loop to a table
lookup per step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# Longer trajectories would need a table too large to keep in memory (an hour at 2 ms is 1.8 M rows).
MAX_SAMPLES = 2_000_000


@dataclass(frozen=True)
class SampledTrajectory:
    """A trajectory sampled every ``dt`` seconds from its start.

    Attributes:
        dt: sample period, s.
        positions: shape ``(N, n)``; row ``i`` is the desired position at ``i * dt`` (the last row is
            the final point, at :attr:`duration`).
        velocities: shape ``(N, n)``, desired velocities at the same instants.
        duration: time from start of the last point, s.
    """

    dt: float
    positions: np.ndarray
    velocities: np.ndarray
    duration: float

    def index_at(self, elapsed: float) -> int:
        """Row for ``elapsed`` seconds after the start (clamped to the table)."""
        if elapsed <= 0.0:
            return 0
        return min(int(elapsed / self.dt + 0.5), len(self.positions) - 1)


def _coefficients(
    p0: np.ndarray,
    v0: np.ndarray | None,
    a0: np.ndarray | None,
    p1: np.ndarray,
    v1: np.ndarray | None,
    a1: np.ndarray | None,
    h: np.ndarray,
) -> np.ndarray:
    """Polynomial coefficients ``c[k]`` (``q = Σ c_k τ^k``) of each segment, shape ``(6, S, n)``."""
    h = h[:, None]
    c = np.zeros((6, *p0.shape))
    c[0] = p0
    dp = p1 - p0
    if v0 is None or v1 is None:
        c[1] = dp / h
        return c
    c[1] = v0
    if a0 is None or a1 is None:
        c[2] = (3.0 * dp - (2.0 * v0 + v1) * h) / h**2
        c[3] = (-2.0 * dp + (v0 + v1) * h) / h**3
        return c
    c[2] = a0 / 2.0
    c[3] = (20.0 * dp - (8.0 * v1 + 12.0 * v0) * h - (3.0 * a0 - a1) * h**2) / (2.0 * h**3)
    c[4] = (-30.0 * dp + (14.0 * v1 + 16.0 * v0) * h + (3.0 * a0 - 2.0 * a1) * h**2) / (2.0 * h**4)
    c[5] = (12.0 * dp - 6.0 * (v1 + v0) * h + (a1 - a0) * h**2) / (2.0 * h**5)
    return c


def sample_trajectory(
    times: np.ndarray,
    positions: np.ndarray,
    velocities: np.ndarray | None,
    accelerations: np.ndarray | None,
    start_positions: np.ndarray,
    start_velocities: np.ndarray,
    dt: float,
) -> SampledTrajectory:
    """Sample a trajectory every ``dt`` seconds.

    Args:
        times: time from start of each point, shape ``(K,)``, s, non-negative and strictly increasing.
        positions: shape ``(K, n)``.
        velocities: shape ``(K, n)`` or None (linear interpolation).
        accelerations: shape ``(K, n)`` or None (needs ``velocities``; quintic when given).
        start_positions: where the joints are commanded to be when the trajectory starts, shape ``(n,)``.
        start_velocities: their commanded velocities then, shape ``(n,)``.
        dt: sample period, s.

    Returns:
        The sampled trajectory; a single point at time 0 gives a one-row table.
    """
    times = np.asarray(times, dtype=float)
    positions = np.asarray(positions, dtype=float)
    if times[0] > 0.0:
        times = np.concatenate([[0.0], times])
        positions = np.vstack([start_positions, positions])
        if velocities is not None:
            velocities = np.vstack([start_velocities, velocities])
        if accelerations is not None:
            accelerations = np.vstack([np.zeros_like(start_positions), accelerations])
    duration = float(times[-1])
    if len(times) == 1:
        return SampledTrajectory(dt, positions.copy(), np.zeros_like(positions), duration)
    sample_times = np.append(np.arange(0.0, duration, dt), duration)
    segment = np.clip(np.searchsorted(times, sample_times, side="right") - 1, 0, len(times) - 2)
    tau = (sample_times - times[segment])[:, None]
    h = np.diff(times)
    coefficients = _coefficients(
        positions[:-1],
        None if velocities is None else velocities[:-1],
        None if accelerations is None else accelerations[:-1],
        positions[1:],
        None if velocities is None else velocities[1:],
        None if accelerations is None else accelerations[1:],
        h,
    )[:, segment]
    q = np.zeros_like(tau * coefficients[0])
    qd = np.zeros_like(q)
    # Horner's scheme for the position and its derivative.
    for k in range(5, -1, -1):
        q = q * tau + coefficients[k]
        if k > 0:
            qd = qd * tau + k * coefficients[k]
    # The table ends where the trajectory ends: exactly on the last point, at its velocity (zero when
    # the points give none, since the controller then holds there).
    q[-1] = positions[-1]
    qd[-1] = velocities[-1] if velocities is not None else 0.0
    return SampledTrajectory(dt, q, qd, duration)
