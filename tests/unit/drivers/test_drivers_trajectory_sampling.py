"""Sampling a timed trajectory the way ros2_control interpolates it."""

from __future__ import annotations

import numpy as np
import pytest

from kinema.drivers.mujoco.trajectory_sampling import sample_trajectory

DT = 0.002


def at(table: object, t: float) -> int:
    return table.index_at(t)  # type: ignore[attr-defined]


def test_positions_only_interpolate_linearly_and_end_at_rest() -> None:
    times = np.array([0.0, 1.0, 2.0])
    positions = np.array([[0.0, 1.0], [1.0, 1.0], [1.0, 3.0]])
    table = sample_trajectory(times, positions, None, None, positions[0], np.zeros(2), DT)
    np.testing.assert_allclose(table.positions[at(table, 0.5)], [0.5, 1.0], atol=1e-9)
    np.testing.assert_allclose(table.positions[at(table, 1.5)], [1.0, 2.0], atol=1e-9)
    np.testing.assert_allclose(table.velocities[at(table, 0.5)], [1.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(table.positions[-1], [1.0, 3.0])
    np.testing.assert_allclose(table.velocities[-1], [0.0, 0.0])
    assert table.duration == 2.0


@pytest.mark.parametrize("with_accelerations", [False, True])
def test_splines_pass_through_every_point_with_its_velocity(with_accelerations: bool) -> None:
    times = np.array([0.0, 0.5, 1.3, 2.0])
    positions = np.array([[0.0], [0.4], [1.0], [1.2]])
    velocities = np.array([[0.0], [1.0], [0.5], [0.0]])
    accelerations = np.array([[0.0], [0.5], [-1.0], [0.0]]) if with_accelerations else None
    table = sample_trajectory(times, positions, velocities, accelerations, positions[0], np.zeros(1), DT)
    for t, q, v in zip(times, positions, velocities, strict=True):
        row = at(table, t)
        assert row * DT == pytest.approx(t, abs=DT / 2) or row == len(table.positions) - 1
        np.testing.assert_allclose(table.positions[row], q, atol=1e-9)
        np.testing.assert_allclose(table.velocities[row], v, atol=1e-9)
    # The velocity column is the derivative of the position column.
    numeric = np.gradient(table.positions[:, 0], DT)
    np.testing.assert_allclose(numeric[1:-2], table.velocities[1:-2, 0], atol=5e-3)


def test_quintic_segments_honour_the_point_accelerations() -> None:
    times = np.array([0.0, 1.0])
    positions = np.array([[0.0], [1.0]])
    velocities = np.array([[0.0], [0.0]])
    accelerations = np.array([[2.0], [-3.0]])
    table = sample_trajectory(times, positions, velocities, accelerations, positions[0], np.zeros(1), DT)
    acceleration = np.gradient(table.velocities[:, 0], DT)
    # Extrapolate the central differences to the ends (the jerk is large there).
    assert 2 * acceleration[1] - acceleration[2] == pytest.approx(2.0, abs=0.01)
    assert 2 * acceleration[-2] - acceleration[-3] == pytest.approx(-3.0, abs=0.01)


def test_a_first_point_later_than_zero_starts_from_the_current_command() -> None:
    times = np.array([1.0])
    positions = np.array([[2.0]])
    table = sample_trajectory(times, positions, np.array([[0.0]]), None, np.array([1.0]), np.array([0.0]), DT)
    assert table.positions[0, 0] == pytest.approx(1.0)
    assert table.positions[at(table, 0.5), 0] == pytest.approx(1.5, abs=1e-6)
    assert table.positions[-1, 0] == pytest.approx(2.0)
    assert table.duration == 1.0


def test_a_single_point_at_zero_is_a_one_row_table() -> None:
    table = sample_trajectory(
        np.array([0.0]), np.array([[0.3, 0.4]]), None, None, np.zeros(2), np.zeros(2), DT
    )
    assert table.positions.shape == (1, 2)
    assert at(table, 5.0) == 0


def test_rows_are_clamped_to_the_table() -> None:
    times = np.array([0.0, 0.1])
    positions = np.array([[0.0], [1.0]])
    table = sample_trajectory(times, positions, None, None, positions[0], np.zeros(1), DT)
    assert at(table, -1.0) == 0
    assert at(table, 10.0) == len(table.positions) - 1
