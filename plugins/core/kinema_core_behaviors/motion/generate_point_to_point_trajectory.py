"""GeneratePointToPointTrajectory: a timed straight joint-space move between two given states."""

from __future__ import annotations

import math
from typing import Any

from kinema.behaviors import AsyncBehavior, PortInfo, input_port
from kinema.behaviors.cell_ports import cell_input_port
from kinema.errors import KinemaError, did_you_mean

from ..messages.conversions import TRAJECTORY_TYPE, joint_positions, trajectory_message
from ..messages.ports import fails_on_bad_input, message_output, port_error, read_input, speed_scale_ports
from .planning_resources import robot_model

# Speeds below this (rad/s or m/s) count as at rest: a simulated arm that has stopped still reports a
# little velocity.
AT_REST = 0.01
STATE_DESCRIPTION = (
    "(sensor_msgs/JointState, or a RobotJointState as CreateRobotState's robot_state; from "
    "CreateRobotState's joint_state_msg, GetJointState or GetRobotStateFromTrajectory)"
)


def state_velocities(value: Any) -> dict[str, float]:
    """The velocities a joint state gives by joint name (none when its ``velocity`` is empty)."""
    state = getattr(value, "joint_state", value)
    names = [str(n) for n in getattr(state, "name", [])]
    velocities = [float(v) for v in getattr(state, "velocity", [])]
    return dict(zip(names, velocities, strict=False)) if len(velocities) == len(names) else {}


class GeneratePointToPointTrajectory(AsyncBehavior):
    """Times a straight joint-space move of ``planning_group_name`` from ``start_state`` to ``target_state``.

    The move starts and ends at rest and is as fast as the joints' velocity and acceleration limits,
    scaled by the factors, allow (Kinema's toppra timing). Points are ``1 / trajectory_sampling_rate``
    apart (plus one at the end) and their ``time_from_start`` begins at ``start_time``, so a trajectory
    generated from a state part-way along another can be stitched onto it. As in MoveIt Pro, nothing is
    planned and nothing is checked for collisions: the joints move in a straight line between the states
    (check the result with ValidateTrajectory, or plan with PlanToJointGoal, when the scene matters).
    Fails naming the port when a state misses a joint of the group, names a joint outside it, lies outside
    the joint limits or is not at rest.
    """

    subcategory = "Motion - Planning"
    description = "A timed straight joint-space move between two given joint states, sampled at a rate."

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("start_state", None, "{start_state}", f"Where the move starts {STATE_DESCRIPTION}."),
            input_port(
                "target_state",
                None,
                "{target_state}",
                f"Where the move ends {STATE_DESCRIPTION}. Its velocities, if given, must be zero: the "
                "move ends at rest.",
            ),
            cell_input_port("planning_group_name", str, "planning_group", "The planning group that moves."),
            *speed_scale_ports(),
            input_port(
                "jerk_scale_factor",
                float,
                1.0,
                "Fraction of the joints' jerk limits, (0, 1]. Checked and not applied: Kinema's timing "
                "bounds velocity and acceleration only (the robot model has no jerk limits).",
            ),
            input_port(
                "start_time",
                float,
                0.0,
                "time_from_start of the first point (s, >= 0); every point is offset by it.",
            ),
            input_port(
                "trajectory_sampling_rate",
                float,
                100.0,
                "Points per second (Hz, > 0): points are exactly 1/rate apart, plus one at the end "
                "(MoveIt Pro's default is not public; Kinema's: 100, its planners' rate).",
            ),
            message_output(
                "joint_trajectory_msg",
                TRAJECTORY_TYPE,
                "{joint_trajectory_msg}",
                "The timed trajectory over the group's joints.",
            ),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        import dataclasses

        import numpy as np

        from kinema.motion import JointPath, time_parameterize

        group_name = str(self.get_input("planning_group_name"))
        factors = {
            port: float(read_input(self, port))
            for port in ("velocity_scale_factor", "acceleration_scale_factor", "jerk_scale_factor")
        }
        for port, factor in factors.items():
            if not 0.0 < factor <= 1.0:
                raise port_error(self, port, f"= {factor:g}", "expected a fraction in (0, 1]")
        start_time = float(read_input(self, "start_time"))
        if not (math.isfinite(start_time) and start_time >= 0.0):
            raise port_error(self, "start_time", f"= {start_time:g}", "expected seconds >= 0")
        rate = float(read_input(self, "trajectory_sampling_rate"))
        if not (math.isfinite(rate) and rate > 0.0):
            raise port_error(
                self, "trajectory_sampling_rate", f"= {rate:g}", "expected points per second > 0"
            )
        try:
            model = robot_model(self.context, "GeneratePointToPointTrajectory")
        except KinemaError as error:
            return self._fail(str(error))
        if group_name not in model.groups:
            raise port_error(
                self, "planning_group_name", f"= {group_name!r}", did_you_mean(group_name, list(model.groups))
            )
        joints = model.group(group_name).joint_names
        start = self._positions("start_state", joints, group_name, model, outside_allowed=True)
        target = self._positions("target_state", joints, group_name, model, outside_allowed=False)
        try:
            trajectory = time_parameterize(
                JointPath(joints, np.array([start, target])),
                model,
                factors["velocity_scale_factor"],
                factors["acceleration_scale_factor"],
                sample_period=1.0 / rate,
                uniform_sampling=True,
            )
        except KinemaError as error:
            return self._fail(str(error))
        shifted = dataclasses.replace(trajectory, times=trajectory.times + start_time)
        self.set_output("joint_trajectory_msg", trajectory_message(shifted))
        return True

    def _positions(
        self, port: str, joints: tuple[str, ...], group: str, model: Any, *, outside_allowed: bool
    ) -> list[float]:
        """The group's joint positions in ``port``'s state, checked: complete, in limits, at rest."""
        from kinema.errors import ObjectiveError

        value = read_input(self, port)
        try:
            given = joint_positions(value, port)
        except ObjectiveError as error:
            raise port_error(self, port, str(error)) from None
        missing = [name for name in joints if name not in given]
        if missing:
            raise port_error(
                self,
                port,
                f"lacks joint(s) {', '.join(missing)} of group {group!r}",
                f"give every joint of the group: {', '.join(joints)}",
            )
        extra = [name for name in given if name not in joints]
        if extra and not outside_allowed:
            raise port_error(
                self,
                port,
                f"names joint(s) {', '.join(extra)} outside group {group!r}",
                f"the move reaches only the group's joints: {', '.join(joints)}",
            )
        moving = {n: v for n, v in state_velocities(value).items() if n in joints and abs(v) > AT_REST}
        if moving:
            name, speed = next(iter(moving.items()))
            raise port_error(
                self,
                port,
                f"is moving ({name} at {speed:g}/s)",
                "Kinema's point-to-point moves start and end at rest: give velocities of 0 (or none)",
            )
        tolerance = 1e-2 if outside_allowed else 1e-6  # encoders report a hair past a stop
        for name in joints:
            i = model.index(name)
            if not model.lower[i] - tolerance <= given[name] <= model.upper[i] + tolerance:
                raise port_error(
                    self,
                    port,
                    f"puts {name} at {given[name]:.4f}, outside its limits",
                    f"valid: [{model.lower[i]:.4f}, {model.upper[i]:.4f}]",
                )
        return [min(max(given[n], model.lower[model.index(n)]), model.upper[model.index(n)]) for n in joints]

    def _fail(self, reason: str) -> bool:
        self.logger.publish_failure(f"GeneratePointToPointTrajectory: {reason}")
        return False
