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
    result = plan_cartesian_path(checker, start, [T1])
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
    result = plan_cartesian_path(checker, start, [T])
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
    assert plan_cartesian_path(checker, start, square).fraction == pytest.approx(1.0)
    with pytest.raises(MotionError, match="at least one waypoint"):
        plan_cartesian_path(checker, start, [])
