"""A joint trajectory controller, as ros2_control's ``joint_trajectory_controller`` behaves.

It commands position actuators: every control period (one physics step) it looks up the desired
position and velocity of the running trajectory and sets ``ctrl = q_des + (kv/kp)·qd_des`` — the
velocity feed-forward that keeps a position servo from lagging by ``kv·v/kp``. While the trajectory
runs it checks the path tolerances; after its last point it waits up to the goal time tolerance for the
goal tolerances to hold.

Starting where the arm is: a trajectory is planned from the joint state the planner read, and when it
preempts a motion (the old goal's cancel still on its way, or the arm still braking) the arm is no longer
there when the goal arrives. Starting the table at its first point would then abort it "0.000 s into
the trajectory". Instead, when the arm is off the first point or moving differently (beyond the goal's
own goal tolerances), the trajectory is shifted by a lead-in during which a smooth segment takes the arm
from its actual position and speed to the first point; a goal started from rest where it was planned
is tracked unchanged.

Stopping (a cancel, a failed check): holding the position the joints had when the stop came would let
them overshoot and ring at the servo's own bandwidth for a few hundred milliseconds. Instead the
controller brakes: each step it commands a pure velocity feedback ``F = -K·qd`` with ``K`` sized from
each joint's effective inertia so the speed roughly halves every step, and once the joints are still it
holds them where they stopped. A deactivation or a state reset holds at once.

All methods run on the physics thread.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinema.drivers.mujoco.execution import Execution
from kinema.drivers.mujoco.model_index import JointInfo
from kinema.drivers.mujoco.trajectory_goal import (
    GOAL_TOLERANCE_VIOLATED,
    INVALID_GOAL,
    OLD_HEADER_TIMESTAMP,
    PATH_TOLERANCE_VIOLATED,
    SUCCESSFUL,
    TrajectoryGoal,
)
from kinema.drivers.mujoco.trajectory_sampling import SampledTrajectory, sample_trajectory

log = logging.getLogger(__name__)

count_nonzero = np.count_nonzero


Index = np.ndarray | slice


def _index(addresses: np.ndarray) -> Index:
    """A slice when the addresses are consecutive (a view: much cheaper per step), else the array."""
    if len(addresses) and np.array_equal(addresses, np.arange(addresses[0], addresses[0] + len(addresses))):
        return slice(int(addresses[0]), int(addresses[0]) + len(addresses))
    return addresses


@dataclass
class _Running:
    execution: Execution
    goal: TrajectoryGoal
    table: SampledTrajectory
    start: float
    qpos: Index
    qvel: Index
    ctrl: Index
    # ctrl per table row: position plus the velocity feed-forward, computed once per goal.
    commands: np.ndarray
    check_path_velocity: bool
    row: int = 0


# Braking: the fraction of a joint's speed removed per step (stable below 2 for a decoupled joint; the
# margin covers the coupling between joints), when the joints count as still, and the longest brake.
BRAKE_GAIN = 0.5
BRAKE_DONE_SPEED = 0.002
BRAKE_TIMEOUT = 0.1
# Lead-in onto a trajectory that does not start where the arm is: long enough to cover the gap at
# LEAD_IN_SPEED and to turn the arm's speed around at LEAD_IN_ACCELERATION (rad or m, per second).
LEAD_IN_SPEED = 1.0
LEAD_IN_ACCELERATION = 4.0
LEAD_IN_MIN = 0.1


@dataclass
class _Brake:
    started: float
    # ctrl = q + slope * qd gives the force -K·qd through the position servo.
    slope: np.ndarray


def _result(code: int, message: str) -> dict[str, Any]:
    return {"error_code": code, "error_string": message}


def _violations(
    names: tuple[str, ...], values: np.ndarray | None, tolerance: np.ndarray, what: str
) -> list[str]:
    if values is None:
        return []
    return [
        f"{names[i]} {what} {values[i]:+.4f} (tolerance {tolerance[i]:.4g})"
        for i in np.flatnonzero(np.abs(values) > tolerance)
    ]


def _lead_in(goal: TrajectoryGoal, actual: np.ndarray, actual_velocity: np.ndarray) -> float:
    """Seconds to add before ``goal``'s first point so that the arm can get there from its actual state.

    0 when the arm is at the first point and moves as it says (within the goal's goal tolerances), and
    when the first point is given a time of its own to be reached (ros2_control then interpolates from
    the commanded state over that time, and so does this controller).
    """
    if float(goal.times[0]) >= LEAD_IN_MIN:
        return 0.0
    first = goal.positions[0]
    first_velocity = goal.velocities[0] if goal.velocities is not None else np.zeros_like(first)
    gap = np.abs(actual - first)
    speed_gap = np.abs(actual_velocity - first_velocity)
    if (gap <= goal.goal_position_tolerance).all() and (speed_gap <= goal.goal_velocity_tolerance).all():
        return 0.0
    needed = max(
        LEAD_IN_MIN,
        1.5 * float(gap.max()) / LEAD_IN_SPEED + float(speed_gap.max()) / LEAD_IN_ACCELERATION,
    )
    return needed - float(goal.times[0])


class JointTrajectoryController:
    """Tracks ``FollowJointTrajectory`` goals on a set of position-actuated joints.

    Args:
        name: the controller's name (``joint_trajectory_controller``).
        joints: the joints it commands (each with an actuator).
        feedforward: ``kv/kp`` of each joint's position actuator, s.
        dt: the control period (the physics step), s.
        gains: ``kp`` of each joint's position actuator (N/m or N·m/rad); with ``inertia``, stops brake.
        inertia: returns each joint's effective inertia (kg or kg·m², the mass matrix diagonal) in the
            current state; without it a stop holds the position the joints had.
        touching: names what the robot touches in the current state (see ``contacts.py``); a goal that
            aborts on a tolerance says it.
    """

    type_name = "joint_trajectory_controller/JointTrajectoryController"

    def __init__(
        self,
        name: str,
        joints: list[JointInfo],
        feedforward: np.ndarray,
        dt: float,
        gains: np.ndarray | None = None,
        inertia: Callable[[Any], np.ndarray] | None = None,
        touching: Callable[[Any], list[str]] | None = None,
    ) -> None:
        self.name = name
        self.dt = dt
        self.joints = joints
        self.joint_names = [joint.name for joint in joints]
        self.active = False
        self._qpos = np.array([joint.qpos_address for joint in joints], dtype=int)
        self._qvel = np.array([joint.dof_address for joint in joints], dtype=int)
        self._ctrl = np.array([joint.actuator for joint in joints], dtype=int)
        self._feedforward = np.asarray(feedforward, dtype=float)
        # What the controller last commanded (the start state of the next trajectory).
        self._command = np.zeros(len(joints))
        self._command_velocity = np.zeros(len(joints))
        self._running: _Running | None = None
        self._gains = None if gains is None else np.asarray(gains, dtype=float)
        self._inertia = inertia
        self._touching = touching
        self._brake: _Brake | None = None
        # Added to the running goal's set points (its joints), e.g. by the admittance: the position offset,
        # and the offset with its velocity feed-forward for ctrl. None: the trajectory as it is.
        self._offset: np.ndarray | None = None
        self._offset_command: np.ndarray | None = None

    @property
    def command_interfaces(self) -> list[str]:
        """``<joint>/position`` for each joint."""
        return [f"{name}/position" for name in self.joint_names]

    @property
    def state_interfaces(self) -> list[str]:
        """Position and velocity of each joint."""
        return [f"{name}/{kind}" for name in self.joint_names for kind in ("position", "velocity")]

    @property
    def busy(self) -> bool:
        """True while a goal runs."""
        return self._running is not None

    @property
    def braking(self) -> bool:
        """True while the joints are being brought to a stop."""
        return self._brake is not None

    # -- lifecycle -------------------------------------------------------------------------------

    def activate(self, data: Any) -> None:
        """Start commanding: hold the joints where they are (no jump to a stale set point)."""
        self.active = True
        self._hold(data)

    def deactivate(self, data: Any) -> None:
        """Stop commanding (actuators keep their last set point); a running goal is aborted."""
        self._end(data, "aborted", _result(INVALID_GOAL, f"{self.name} was deactivated"), hold=False)
        if self._brake is not None:
            self._hold(data)
        self.active = False

    def on_state_reset(self, data: Any) -> None:
        """The simulation state was set from outside: abort a running goal and hold the new positions."""
        self._end(data, "aborted", _result(INVALID_GOAL, "the simulation state was reset"), hold=False)
        self._brake = None
        if self.active:
            self._hold(data)
        else:
            self._command[:] = data.qpos[self._qpos]
            self._command_velocity[:] = 0.0

    def shutdown(self, reason: str) -> None:
        """The driver stops: end a running goal without touching the simulation."""
        if self._running is not None:
            self._running.execution.finish("aborted", _result(INVALID_GOAL, reason))
            self._running = None

    # -- goals -----------------------------------------------------------------------------------

    def start(self, execution: Execution, goal: TrajectoryGoal, data: Any) -> None:
        """Begin tracking ``goal``; a goal already running is aborted (preempted)."""
        if not self.active:
            execution.finish(
                "aborted",
                _result(
                    INVALID_GOAL,
                    f"{self.name} is inactive; activate it with /controller_manager/switch_controller",
                ),
            )
            return
        now = float(data.time)
        if goal.start_stamp is not None and goal.start_stamp + goal.duration < now:
            execution.finish(
                "aborted",
                _result(
                    OLD_HEADER_TIMESTAMP,
                    f"the trajectory was stamped to start at {goal.start_stamp:.3f} s and would have ended "
                    f"before now ({now:.3f} s sim time)",
                ),
            )
            return
        if self._running is not None:
            self._running.execution.finish(
                "aborted", _result(INVALID_GOAL, f"preempted by a newer goal at sim time {now:.3f} s")
            )
        self._settle_command()
        if self._brake is not None:
            # Interrupting a stop: start from where the joints are, at the speed they still have.
            self._brake = None
            self._command[:] = data.qpos[self._qpos]
            self._command_velocity[:] = data.qvel[self._qvel]
        columns = goal.joint_indices
        # Joints this goal leaves out hold the last desired position (without a preempted goal's
        # velocity feed-forward, which would offset them).
        others = np.setdiff1d(np.arange(len(self.joints)), columns)
        if others.size:
            self._command_velocity[others] = 0.0
            data.ctrl[self._ctrl[others]] = self._command[others]
        times = goal.times
        start_positions = self._command[columns]
        start_velocities = self._command_velocity[columns]
        if goal.start_stamp is None:
            actual = data.qpos[self._qpos[columns]]
            actual_velocity = data.qvel[self._qvel[columns]]
            lead_in = _lead_in(goal, actual, actual_velocity)
            if lead_in > 0.0:
                log.info(
                    "%s: the arm is off the trajectory's start (by up to %.3f); leading it in over %.3f s",
                    self.name,
                    float(np.abs(actual - goal.positions[0]).max()),
                    lead_in,
                )
                times = goal.times + lead_in
                start_positions, start_velocities = actual.copy(), actual_velocity.copy()
        table = sample_trajectory(
            times,
            goal.positions,
            goal.velocities,
            goal.accelerations,
            start_positions,
            start_velocities,
            self.dt,
        )
        self._running = _Running(
            execution=execution,
            goal=goal,
            table=table,
            start=goal.start_stamp if goal.start_stamp is not None else now,
            qpos=_index(self._qpos[columns]),
            qvel=_index(self._qvel[columns]),
            ctrl=_index(self._ctrl[columns]),
            commands=table.positions + self._feedforward[columns] * table.velocities,
            check_path_velocity=not math.isinf(goal.path_velocity_tolerance.min()),
        )
        log.debug(
            "%s: tracking %d points over %.3f s from sim time %.3f s",
            self.name,
            len(goal.times),
            goal.duration,
            now,
        )

    def cancel(self, execution: Execution, data: Any) -> None:
        """Stop the goal of ``execution`` now: brake the joints to a stop and hold them there."""
        running = self._running
        if running is None or running.execution is not execution:
            execution.finish("canceled", _result(SUCCESSFUL, "canceled before it started"))
            return
        now = float(data.time)
        self._end(
            data,
            "canceled",
            _result(SUCCESSFUL, f"canceled at sim time {now:.3f} s; holding position"),
            hold=True,
        )

    def update(self, data: Any) -> None:
        """One control period: command the desired state and check the tolerances (or brake)."""
        if self._brake is not None:
            self._brake_step(data)
            return
        running = self._running
        if running is None:
            return
        elapsed = float(data.time) - running.start
        if elapsed < 0.0:
            return  # stamped to start later: keep holding
        table = running.table
        row = running.row = table.index_at(elapsed)
        desired = table.positions[row]
        offset = self._offset
        if offset is not None:
            desired = desired + offset
        goal = running.goal
        error = data.qpos[running.qpos] - desired
        if elapsed <= table.duration:
            velocity_error = (
                data.qvel[running.qvel] - table.velocities[row] if running.check_path_velocity else None
            )
            # np.count_nonzero rather than ndarray.any() (~0.2 against ~1 us on a handful of joints): this
            # runs every physics step.
            if count_nonzero(np.abs(error) > goal.path_position_tolerance) or (
                velocity_error is not None
                and count_nonzero(np.abs(velocity_error) > goal.path_velocity_tolerance)
            ):
                self._fail(
                    data,
                    PATH_TOLERANCE_VIOLATED,
                    f"path tolerance violated {elapsed:.3f} s into the trajectory",
                    _violations(goal.joint_names, error, goal.path_position_tolerance, "off by")
                    + _violations(
                        goal.joint_names, velocity_error, goal.path_velocity_tolerance, "speed off by"
                    ),
                )
                return
        else:
            speed = data.qvel[running.qvel]
            # All within (a NaN is not): counted, as above.
            if count_nonzero(np.abs(error) <= goal.goal_position_tolerance) == error.size and (
                count_nonzero(np.abs(speed) <= goal.goal_velocity_tolerance) == speed.size
            ):
                self._end(data, "succeeded", _result(SUCCESSFUL, ""), hold=False)
                return
            if elapsed > table.duration + goal.goal_time_tolerance:
                self._fail(
                    data,
                    GOAL_TOLERANCE_VIOLATED,
                    f"goal tolerance still violated {elapsed - table.duration:.3f} s after the last point",
                    _violations(goal.joint_names, error, goal.goal_position_tolerance, "off by")
                    + _violations(goal.joint_names, speed, goal.goal_velocity_tolerance, "still moving at"),
                )
                return
        if self._offset_command is None:
            data.ctrl[running.ctrl] = running.commands[row]
        else:
            data.ctrl[running.ctrl] = running.commands[row] + self._offset_command

    def post_feedback(self, data: Any) -> None:
        """Post the running goal's desired, actual and error state (called at the publish rate)."""
        running = self._running
        if running is None:
            return
        stamp = float(data.time)
        row = running.table.index_at(stamp - running.start)
        # Copies of what changes; the message is built only when the goal's thread takes it.
        actual = data.qpos[running.qpos].copy()
        actual_velocity = data.qvel[running.qvel].copy()
        table, joint_names = running.table, running.goal.joint_names
        offset = None if self._offset is None else self._offset.copy()

        def feedback() -> dict[str, Any]:
            desired = table.positions[row] if offset is None else table.positions[row] + offset
            desired_velocity = table.velocities[row]
            return {
                "header": {"stamp": {"sec": int(stamp), "nanosec": int((stamp % 1.0) * 1e9)}},
                "joint_names": list(joint_names),
                "desired": {"positions": desired.tolist(), "velocities": desired_velocity.tolist()},
                "actual": {"positions": actual.tolist(), "velocities": actual_velocity.tolist()},
                "error": {
                    "positions": (desired - actual).tolist(),
                    "velocities": (desired_velocity - actual_velocity).tolist(),
                },
            }

        running.execution.post_feedback(feedback)

    # -- internals -------------------------------------------------------------------------------

    def _fail(self, data: Any, code: int, what: str, violations: list[str]) -> None:
        message = f"{what} (sim time {float(data.time):.3f} s): {'; '.join(violations)}"
        touched = self._touching(data) if self._touching is not None else []
        if touched:
            # Most often why the arm is off: something is in its way.
            message += f"; the robot touches {', '.join(touched)}"
        log.warning("%s: %s", self.name, message)
        self._end(data, "aborted", _result(code, message), hold=True)

    def _end(self, data: Any, status: Any, result: dict[str, Any], *, hold: bool) -> None:
        running = self._running
        if running is None:
            return
        self._settle_command()
        self._running = None
        if hold:
            self._stop(data)
        else:
            self._command_velocity[:] = 0.0
        running.execution.finish(status, result)

    def _settle_command(self) -> None:
        """Record what the running goal commands now (kept lazily: the per-step path only writes ctrl)."""
        running = self._running
        if running is not None:
            columns = running.goal.joint_indices
            self._command[columns] = running.table.positions[running.row]
            self._command_velocity[columns] = running.table.velocities[running.row]
            if self._offset is not None:
                self._command[columns] += self._offset

    def _stop(self, data: Any) -> None:
        """Brake the joints to a stop (then hold), or hold at once when braking is not configured."""
        if self._gains is None or self._inertia is None:
            self._hold(data)
            return
        stiffness = BRAKE_GAIN * self._inertia(data) / self.dt
        self._brake = _Brake(float(data.time), self._feedforward - stiffness / self._gains)
        self._brake_step(data)

    def _brake_step(self, data: Any) -> None:
        brake = self._brake
        assert brake is not None
        speed = data.qvel[self._qvel]
        if np.abs(speed).max() < BRAKE_DONE_SPEED or float(data.time) - brake.started > BRAKE_TIMEOUT:
            self._brake = None
            self._hold(data)
            return
        data.ctrl[self._ctrl] = data.qpos[self._qpos] + brake.slope * speed

    def _hold(self, data: Any) -> None:
        self._command[:] = data.qpos[self._qpos]
        self._command_velocity[:] = 0.0
        data.ctrl[self._ctrl] = self._command
