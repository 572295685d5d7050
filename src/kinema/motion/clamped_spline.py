"""A cubic spline through joint-space points, at rest at both ends: the geometric path that toppra times.

It is the curve of scipy's ``CubicSpline(knots, points, bc_type="clamped")`` (equal to rounding), built with
numpy alone, so timing a path loads no part of scipy: ``scipy.interpolate`` brings ``optimize``, ``sparse``,
``linalg``, ``special``, ``fft`` and ``spatial`` along, about 35 MB that every agent kept.

Between knots ``s[i] <= s < s[i + 1]`` the spline is ``q(s) = a + b ds + c ds^2 + d ds^3`` with
``ds = s - s[i]``; it passes through every point, its first and second derivatives are continuous, and its
first derivative is zero at the first and the last knot. Outside the knots the end pieces extend.
"""

from __future__ import annotations

import numpy as np

from kinema.errors import MotionError

__all__ = ["ClampedCubicSpline"]


class ClampedCubicSpline:
    """The clamped cubic spline through ``points`` at path positions ``knots``.

    Has what toppra asks of a geometric path (``toppra.interpolator.AbstractGeometricPath``): a call
    giving positions or derivatives, ``dof`` and ``path_interval``.

    Args:
        knots: ``(m,)`` path positions of the points, strictly increasing, ``m >= 2``.
        points: ``(m, dof)`` joint positions (rad or m).

    Raises:
        MotionError: fewer than two points, shapes that do not match, or knots that do not increase.
    """

    def __init__(self, knots: np.ndarray, points: np.ndarray) -> None:
        s = np.asarray(knots, dtype=float)
        q = np.asarray(points, dtype=float)
        if s.ndim != 1 or q.ndim != 2 or len(s) != len(q) or len(s) < 2:
            raise MotionError(
                f"a spline needs (m,) knots and (m, dof) points with m >= 2, got {s.shape} and {q.shape}"
            )
        h = np.diff(s)
        if not np.all(h > 0):
            raise MotionError("spline knots must increase strictly")
        slope = np.diff(q, axis=0) / h[:, None]
        tangent = _clamped_tangents(h, slope)
        # Per interval, the power-basis coefficients of ds^3, ds^2, ds, 1 (Hermite form of the tangents).
        t0, t1 = tangent[:-1], tangent[1:]
        hh = h[:, None]
        self._coefficients = np.stack(
            [(t0 + t1 - 2 * slope) / hh**2, (3 * slope - 2 * t0 - t1) / hh, t0, q[:-1]]
        )
        self._knots = s

    @property
    def dof(self) -> int:
        """The number of joints."""
        return int(self._coefficients.shape[2])

    @property
    def path_interval(self) -> np.ndarray:
        """``(2,)``: the first and the last knot."""
        return np.array([self._knots[0], self._knots[-1]])

    def __call__(self, positions: float | np.ndarray, order: int = 0) -> np.ndarray:
        """The spline (``order`` 0), its first or its second derivative at path ``positions``.

        A scalar position gives ``(dof,)``, an ``(n,)`` array ``(n, dof)``.
        """
        if order not in (0, 1, 2):
            raise ValueError(f"order must be 0, 1 or 2, got {order}")
        s = np.asarray(positions, dtype=float)
        flat = np.atleast_1d(s)
        index = np.clip(np.searchsorted(self._knots, flat, side="right") - 1, 0, len(self._knots) - 2)
        ds = (flat - self._knots[index])[:, None]
        d, c, b, a = self._coefficients[:, index]
        if order == 0:
            value = ((d * ds + c) * ds + b) * ds + a
        elif order == 1:
            value = (3 * d * ds + 2 * c) * ds + b
        else:
            value = 6 * d * ds + 2 * c
        return value[0] if s.ndim == 0 else value


def _clamped_tangents(h: np.ndarray, slope: np.ndarray) -> np.ndarray:
    """``(m, dof)`` first derivatives at the knots: zero at both ends, and inside the ones that make the
    second derivative continuous, from the tridiagonal system (for each inner knot ``i``)

    ``h[i] t[i-1] + 2 (h[i-1] + h[i]) t[i] + h[i-1] t[i+1] = 3 (h[i] slope[i-1] + h[i-1] slope[i])``,

    solved by elimination without pivoting (the Thomas algorithm), which is stable here because the system
    is diagonally dominant.
    """
    m = len(h) + 1
    tangent = np.zeros((m, slope.shape[1]))
    inner = m - 2
    if inner == 0:
        return tangent
    lower, diagonal, upper = h[1:], 2 * (h[:-1] + h[1:]), h[:-1]  # row k is inner knot k + 1
    rhs = 3 * (h[1:, None] * slope[:-1] + h[:-1, None] * slope[1:])
    # t[0] = t[m-1] = 0, so the first row's lower and the last row's upper term drop out.
    diag = diagonal.copy()
    for k in range(1, inner):
        factor = lower[k] / diag[k - 1]
        diag[k] -= factor * upper[k - 1]
        rhs[k] -= factor * rhs[k - 1]
    tangent[inner] = rhs[inner - 1] / diag[inner - 1]
    for k in range(inner - 2, -1, -1):
        tangent[k + 1] = (rhs[k] - upper[k] * tangent[k + 2]) / diag[k]
    return tangent
