from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from kinema.errors import MotionError
from kinema.motion.clamped_spline import ClampedCubicSpline


@pytest.mark.parametrize("count", [2, 3, 4, 9, 120])
def test_the_curve_is_scipys_clamped_cubic_spline(count):
    rng = np.random.default_rng(count)
    knots = np.r_[0.0, np.cumsum(rng.uniform(0.001, 0.2, count - 1))]
    points = rng.normal(size=(count, 7))
    reference = CubicSpline(knots, points, bc_type="clamped")
    spline = ClampedCubicSpline(knots, points)
    # inside, on the knots, and beyond both ends (the end pieces extend)
    at = np.r_[rng.uniform(knots[0] - 0.1, knots[-1] + 0.1, 300), knots]
    for order in (0, 1, 2):
        expected = reference(at) if order == 0 else reference.derivative(order)(at)
        np.testing.assert_allclose(spline(at, order), expected, rtol=1e-10, atol=1e-10)


def test_passes_through_the_points_at_rest_at_both_ends():
    knots = np.array([0.0, 0.5, 2.0])
    points = np.array([[0.0, 1.0], [1.0, -1.0], [3.0, 0.5]])
    spline = ClampedCubicSpline(knots, points)
    np.testing.assert_allclose(spline(knots), points, atol=1e-12)
    np.testing.assert_allclose(spline(knots[[0, -1]], 1), np.zeros((2, 2)), atol=1e-12)
    assert spline(0.7).shape == (2,)
    assert spline(np.array([0.7, 0.8]), 2).shape == (2, 2)
    assert spline.dof == 2
    assert spline.path_interval.tolist() == [0.0, 2.0]


def test_two_points_give_the_smooth_step_between_them():
    spline = ClampedCubicSpline(np.array([0.0, 2.0]), np.array([[1.0], [3.0]]))
    u = np.linspace(0.0, 1.0, 11)
    np.testing.assert_allclose(spline(2 * u)[:, 0], 1.0 + 2.0 * (3 * u**2 - 2 * u**3), atol=1e-12)


@pytest.mark.parametrize(
    ("knots", "points", "message"),
    [
        ([0.0], [[1.0]], "m >= 2"),
        ([0.0, 1.0], [[1.0], [2.0], [3.0]], "m >= 2"),
        ([0.0, 1.0], [1.0, 2.0], "m >= 2"),
        ([0.0, 1.0, 1.0], [[1.0], [2.0], [3.0]], "increase strictly"),
    ],
)
def test_malformed_input_is_refused(knots, points, message):
    with pytest.raises(MotionError, match=message):
        ClampedCubicSpline(np.array(knots), np.array(points))


def test_an_order_above_two_is_refused():
    with pytest.raises(ValueError, match="order must be 0, 1 or 2"):
        ClampedCubicSpline(np.array([0.0, 1.0]), np.array([[0.0], [1.0]]))(0.5, 3)
