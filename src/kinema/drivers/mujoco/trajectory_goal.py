"""Check a ``control_msgs/action/FollowJointTrajectory`` goal and turn it into arrays the controller uses.

Rules follow ros2_control's joint trajectory controller: joint names must be joints of the controller
(a goal may move a subset; the others hold), every point gives a position per joint and, if any point
gives velocities or accelerations, all do; times from start increase strictly. A tolerance of 0 means
"use the controller's default", a negative one "do not check" — except ``goal_time_tolerance``, where
0 or negative means the default, so a goal always ends. Unlike ros2_control, a rejected goal is
accepted and at once aborted with ``error_code``/``error_string``, so the client learns why (for
example the list of valid joint names).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinema.drivers.mujoco.trajectory_sampling import MAX_SAMPLES

SUCCESSFUL = 0
INVALID_GOAL = -1
INVALID_JOINTS = -2
OLD_HEADER_TIMESTAMP = -3
PATH_TOLERANCE_VIOLATED = -4
GOAL_TOLERANCE_VIOLATED = -5

# Points may sit this far outside a joint's range (numerical noise from planners and timing).
LIMIT_SLACK = 1e-3


class GoalRejected(Exception):
    """The goal cannot run; ``code`` is a FollowJointTrajectory result error code."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code
        self.message = message


@dataclass(frozen=True)
class ToleranceDefaults:
    """The controller's tolerances, used where a goal leaves one at 0 (m or rad; m/s or rad/s; s).

    ``math.inf`` disables a check.
    """

    path_position: float = 0.1
    path_velocity: float = math.inf
    goal_position: float = 0.01
    goal_velocity: float = 0.05
    goal_time: float = 1.0


@dataclass(frozen=True)
class TrajectoryGoal:
    """A checked trajectory goal.

    Attributes:
        joint_names: the goal's joints, in its column order.
        joint_indices: position of each of them in the controller's joint list.
        times: time from start of each point, shape ``(K,)``, s.
        positions / velocities / accelerations: shape ``(K, n)``; the last two may be None.
        start_stamp: sim time the trajectory starts at (``header.stamp``), None for "now".
        path_position_tolerance / path_velocity_tolerance: per joint, ``inf`` = unchecked.
        goal_position_tolerance / goal_velocity_tolerance: per joint, checked at the end.
        goal_time_tolerance: how long after the last point the goal tolerances may take to hold, s.
    """

    joint_names: tuple[str, ...]
    joint_indices: np.ndarray
    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray | None
    accelerations: np.ndarray | None
    start_stamp: float | None
    path_position_tolerance: np.ndarray
    path_velocity_tolerance: np.ndarray
    goal_position_tolerance: np.ndarray
    goal_velocity_tolerance: np.ndarray
    goal_time_tolerance: float

    @property
    def duration(self) -> float:
        """Time from start of the last point, s."""
        return float(self.times[-1])


def _resolve(value: float, default: float) -> float:
    if value > 0.0:
        return float(value)
    if value < 0.0:
        return math.inf
    return default


def _duration(message: Any) -> float:
    return float(message.sec) + float(message.nanosec) * 1e-9


def _check_names(names: Sequence[str], valid: Sequence[str], what: str) -> None:
    unknown = [name for name in names if name not in valid]
    if unknown:
        listing = ", ".join(valid)
        raise GoalRejected(
            INVALID_JOINTS,
            f"{what}: unknown joint{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))}; "
            f"this controller moves: {listing}",
        )


def _column(rows: list[Any], n: int, field: str, optional: bool) -> np.ndarray | None:
    sizes = {len(row) for row in rows}
    if optional and sizes == {0}:
        return None
    if sizes != {n}:
        bad = next(i for i, row in enumerate(rows) if len(row) != n)
        raise GoalRejected(
            INVALID_GOAL,
            f"point {bad} has {len(rows[bad])} {field} for {n} joints"
            + (f" (give {field} for every point or for none)" if optional else ""),
        )
    return np.asarray([np.asarray(row, dtype=float) for row in rows], dtype=float)


def _tolerances(
    entries: Sequence[Any],
    names: tuple[str, ...],
    valid: Sequence[str],
    default: tuple[float, float],
    what: str,
) -> tuple[np.ndarray, np.ndarray]:
    position = np.full(len(names), default[0])
    velocity = np.full(len(names), default[1])
    _check_names([entry.name for entry in entries], valid, what)
    for entry in entries:
        if entry.name in names:
            column = names.index(entry.name)
            position[column] = _resolve(float(entry.position), default[0])
            velocity[column] = _resolve(float(entry.velocity), default[1])
    return position, velocity


def parse_trajectory_goal(
    goal: Any,
    controller_joints: Sequence[str],
    limits: Mapping[str, tuple[float, float]],
    defaults: ToleranceDefaults,
    dt: float,
) -> TrajectoryGoal:
    """Check ``goal`` (a FollowJointTrajectory goal message) against the controller.

    Args:
        goal: the ``control_msgs/action/FollowJointTrajectory_Goal``.
        controller_joints: the joints the controller commands.
        limits: position range of each limited joint (m or rad).
        defaults: tolerances used where the goal leaves 0.
        dt: the control period, s (bounds the trajectory's length).

    Raises:
        GoalRejected: with the error code and a message naming the problem (and valid joint names).
    """
    trajectory = goal.trajectory
    if goal.multi_dof_trajectory.joint_names or goal.multi_dof_trajectory.points:
        raise GoalRejected(INVALID_GOAL, "multi-DOF trajectories are not supported by this controller")
    names = tuple(str(name) for name in trajectory.joint_names)
    if not names:
        raise GoalRejected(
            INVALID_JOINTS, f"the trajectory names no joints; valid: {', '.join(controller_joints)}"
        )
    duplicates = sorted({name for name in names if names.count(name) > 1})
    if duplicates:
        raise GoalRejected(INVALID_JOINTS, f"joint names appear twice: {', '.join(duplicates)}")
    _check_names(names, controller_joints, "trajectory")
    points = list(trajectory.points)
    if not points:
        raise GoalRejected(INVALID_GOAL, "the trajectory has no points")
    n = len(names)
    times = np.array([_duration(point.time_from_start) for point in points])
    if times[0] < 0.0 or np.any(np.diff(times) <= 0.0):
        bad = int(np.argmax(np.diff(times) <= 0.0)) + 1 if len(times) > 1 else 0
        raise GoalRejected(
            INVALID_GOAL,
            f"time_from_start must increase strictly from point to point (point {bad}: {times[bad]:.6g} s)",
        )
    if times[-1] / dt > MAX_SAMPLES:
        raise GoalRejected(
            INVALID_GOAL, f"the trajectory lasts {times[-1]:.0f} s, longer than this controller runs"
        )
    positions = _column([point.positions for point in points], n, "positions", optional=False)
    velocities = _column([point.velocities for point in points], n, "velocities", optional=True)
    accelerations = _column([point.accelerations for point in points], n, "accelerations", optional=True)
    assert positions is not None
    if accelerations is not None and velocities is None:
        raise GoalRejected(INVALID_GOAL, "points give accelerations but no velocities")
    for label, values in (
        ("positions", positions),
        ("velocities", velocities),
        ("accelerations", accelerations),
    ):
        if values is not None and not np.all(np.isfinite(values)):
            raise GoalRejected(INVALID_GOAL, f"the trajectory's {label} contain NaN or infinite values")
    for column, name in enumerate(names):
        if name not in limits:
            continue
        low, high = limits[name]
        outside = np.flatnonzero(
            (positions[:, column] < low - LIMIT_SLACK) | (positions[:, column] > high + LIMIT_SLACK)
        )
        if outside.size:
            row = int(outside[0])
            raise GoalRejected(
                INVALID_GOAL,
                f"point {row}: {name} = {positions[row, column]:.6g} "
                f"is outside its limits [{low:.6g}, {high:.6g}]",
            )
    stamp = _duration(trajectory.header.stamp)
    path_position, path_velocity = _tolerances(
        goal.path_tolerance,
        names,
        controller_joints,
        (defaults.path_position, defaults.path_velocity),
        "path_tolerance",
    )
    goal_position, goal_velocity = _tolerances(
        goal.goal_tolerance,
        names,
        controller_joints,
        (defaults.goal_position, defaults.goal_velocity),
        "goal_tolerance",
    )
    return TrajectoryGoal(
        joint_names=names,
        joint_indices=np.array([list(controller_joints).index(name) for name in names], dtype=int),
        times=times,
        positions=positions,
        velocities=velocities,
        accelerations=accelerations,
        start_stamp=stamp if stamp > 0.0 else None,
        path_position_tolerance=path_position,
        path_velocity_tolerance=path_velocity,
        goal_position_tolerance=goal_position,
        goal_velocity_tolerance=goal_velocity,
        # Unlike the joint tolerances a negative time does not switch the check off: a goal that never
        # meets its tolerances must end some time, so anything but a positive time means the default.
        goal_time_tolerance=max(_duration(goal.goal_time_tolerance), 0.0) or defaults.goal_time,
    )
