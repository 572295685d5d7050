"""Checking FollowJointTrajectory goals: what is rejected (with which code and words) and what is accepted."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from kinema.drivers.mujoco.trajectory_goal import (
    INVALID_GOAL,
    INVALID_JOINTS,
    GoalRejected,
    ToleranceDefaults,
    parse_trajectory_goal,
)
from kinema.transport import from_dict

JOINTS = ["rail", "pan", "lift"]
LIMITS = {"rail": (-1.0, 1.0), "lift": (-math.pi, 0.0)}
DEFAULTS = ToleranceDefaults(path_position=0.1, goal_position=0.01, goal_velocity=0.05, goal_time=1.0)


def goal(**fields: Any) -> Any:
    data: dict[str, Any] = {
        "trajectory": {
            "joint_names": ["rail", "pan", "lift"],
            "points": [
                {"positions": [0.0, 0.0, -1.0], "time_from_start": {"sec": 0}},
                {"positions": [0.5, 1.0, -0.5], "time_from_start": {"sec": 1}},
            ],
        }
    }
    data.update(fields)
    return from_dict("control_msgs/action/FollowJointTrajectory_Goal", data)


def points(*rows: dict[str, Any]) -> dict[str, Any]:
    return {"trajectory": {"joint_names": ["rail", "pan", "lift"], "points": list(rows)}}


def parse(message: Any) -> Any:
    return parse_trajectory_goal(message, JOINTS, LIMITS, DEFAULTS, 0.002)


@pytest.mark.parametrize(
    ("fields", "code", "words"),
    [
        (
            {"trajectory": {"joint_names": ["rail", "pann"], "points": []}},
            INVALID_JOINTS,
            ["'pann'", "rail, pan, lift"],
        ),
        ({"trajectory": {"joint_names": [], "points": []}}, INVALID_JOINTS, ["no joints", "rail, pan, lift"]),
        ({"trajectory": {"joint_names": ["pan", "pan"], "points": []}}, INVALID_JOINTS, ["twice", "pan"]),
        (points(), INVALID_GOAL, ["no points"]),
        (
            points(
                {"positions": [0, 0, -1], "time_from_start": {"sec": 1}},
                {"positions": [0, 0, -1], "time_from_start": {"sec": 1}},
            ),
            INVALID_GOAL,
            ["increase strictly", "point 1"],
        ),
        (
            points({"positions": [0, 0], "time_from_start": {"sec": 1}}),
            INVALID_GOAL,
            ["point 0 has 2 positions for 3 joints"],
        ),
        (
            points(
                {"positions": [0, 0, -1], "velocities": [0, 0, 0], "time_from_start": {"sec": 1}},
                {"positions": [0, 0, -1], "time_from_start": {"sec": 2}},
            ),
            INVALID_GOAL,
            ["velocities", "every point or for none"],
        ),
        (
            points({"positions": [0, 0, -1], "accelerations": [0, 0, 0], "time_from_start": {"sec": 1}}),
            INVALID_GOAL,
            ["accelerations but no velocities"],
        ),
        (
            points({"positions": [0, 0, 0.5], "time_from_start": {"sec": 1}}),
            INVALID_GOAL,
            ["lift", "outside its limits"],
        ),
        (points({"positions": [0, float("nan"), -1], "time_from_start": {"sec": 1}}), INVALID_GOAL, ["NaN"]),
        (
            {"multi_dof_trajectory": {"joint_names": ["base"]}},
            INVALID_GOAL,
            ["multi-DOF"],
        ),
        (
            {"path_tolerance": [{"name": "elbow", "position": 0.1}]},
            INVALID_JOINTS,
            ["path_tolerance", "'elbow'"],
        ),
    ],
)
def test_bad_goals_are_rejected_with_a_code_and_a_reason(
    fields: dict[str, Any], code: int, words: list[str]
) -> None:
    with pytest.raises(GoalRejected) as raised:
        parse(goal(**fields))
    assert raised.value.code == code
    for word in words:
        assert word in raised.value.message


def test_a_good_goal_becomes_arrays() -> None:
    parsed = parse(goal())
    assert parsed.joint_names == ("rail", "pan", "lift")
    assert parsed.joint_indices.tolist() == [0, 1, 2]
    np.testing.assert_allclose(parsed.times, [0.0, 1.0])
    assert parsed.positions.shape == (2, 3)
    assert parsed.velocities is None and parsed.accelerations is None
    assert parsed.start_stamp is None
    assert parsed.duration == 1.0


def test_a_subset_of_joints_in_any_order_maps_to_the_controllers_columns() -> None:
    message = goal(
        trajectory={
            "joint_names": ["lift", "rail"],
            "points": [{"positions": [-1, 0], "time_from_start": {"sec": 1}}],
        }
    )
    assert parse(message).joint_indices.tolist() == [2, 0]


def test_tolerances_zero_means_default_negative_means_unchecked() -> None:
    message = goal(
        path_tolerance=[{"name": "pan", "position": 0.3}, {"name": "lift", "position": -1.0}],
        goal_tolerance=[{"name": "rail", "position": 0.002, "velocity": -1.0}],
        goal_time_tolerance={"sec": 0, "nanosec": 500_000_000},
    )
    parsed = parse(message)
    assert parsed.path_position_tolerance.tolist() == [0.1, 0.3, math.inf]
    assert parsed.goal_position_tolerance.tolist() == [0.002, 0.01, 0.01]
    assert parsed.goal_velocity_tolerance.tolist() == [math.inf, 0.05, 0.05]
    assert parsed.goal_time_tolerance == 0.5
    assert parse(goal()).goal_time_tolerance == 1.0
    assert parse(goal(goal_time_tolerance={"sec": -1})).goal_time_tolerance == 1.0


def test_a_stamped_trajectory_keeps_its_start_time() -> None:
    message = goal()
    message.trajectory.header.stamp.sec = 12
    message.trajectory.header.stamp.nanosec = 500_000_000
    assert parse(message).start_stamp == 12.5
