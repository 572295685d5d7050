"""PlanCartesianPath: a timed trajectory moving the tool in straight lines through poses."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import AsyncBehavior, PortInfo, input_port, output_port
from kinema.errors import KinemaError, ObjectiveError, did_you_mean

from ..messages.conversions import pose_matrix, trajectory_message
from .joint_states import joint_state_monitor
from .planned_trajectory import publish_planned_trajectory
from .planning_resources import collision_checker, robot_model

WORLD_FRAMES = ("", "world")


class PlanCartesianPath(AsyncBehavior):
    """Plans the tool link through ``path`` (PoseStamped waypoints) in straight lines from the current state.

    Each pose is in ``world`` or in a robot link's frame (taken at the start state). IK is solved every
    ``ik_cartesian_space_density`` metres along the lines, seeded by the previous solution. Fails naming
    where and why the line could not be followed (no IK solution, a joint jump, a collision); the
    result is timed under the scaled joint limits.
    """

    subcategory = "Motion - Planning"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "path", None, "{path}", "Poses to pass through (a list of geometry_msgs/PoseStamped)."
            ),
            input_port("planning_group_name", str, "manipulator", "The planning group that moves."),
            input_port(
                "tip_links", list[str], "", "The tool frame that follows the path ('': the group's tip)."
            ),
            input_port(
                "position_only", bool, False, "Follow the positions only, leave the orientation free."
            ),
            input_port("ik_cartesian_space_density", float, 0.005, "Distance (m) between IK solutions."),
            input_port("link_padding", float, 0.0, "Clearance (m) kept between the robot and the scene."),
            input_port(
                "velocity_scale_factor", float, 1.0, "Fraction of the joints' velocity limits, (0, 1]."
            ),
            input_port(
                "acceleration_scale_factor",
                float,
                1.0,
                "Fraction of the joints' acceleration limits, (0, 1].",
            ),
            output_port(
                "joint_trajectory_msg",
                None,
                "{joint_trajectory_msg}",
                "The timed trajectory (trajectory_msgs/JointTrajectory).",
            ),
        ]

    def do_work(self) -> bool:
        from kinema.motion import fk, plan_cartesian_path, time_parameterize

        try:
            group = str(self.get_input("planning_group_name"))
            model = robot_model(self.context, "PlanCartesianPath")
            if group not in model.groups:
                return self._fail(
                    f"unknown planning group {group!r}; {did_you_mean(group, list(model.groups))}"
                )
            tips = [t.strip() for t in self.get_input_or("tip_links", []) if t.strip()]
            if len(tips) > 1:
                return self._fail(f"one tip link at a time is supported, got {', '.join(tips)}")
            tip = tips[0] if tips else model.group(group).tip_link
            poses = self._poses()
            start = joint_state_monitor(self.context, "PlanCartesianPath").positions(model.joint_names)
            targets = []
            for frame, matrix in poses:
                targets.append(matrix if frame in WORLD_FRAMES else fk(model, start, frame) @ matrix)
            checker = collision_checker(
                self.context, "PlanCartesianPath", float(self.get_input("link_padding"))
            )
            result = plan_cartesian_path(
                checker,
                start,
                targets,
                group,
                tip,
                max_step=float(self.get_input("ik_cartesian_space_density")),
                position_only=bool(self.get_input("position_only")),
            )
            if result.fraction < 1.0 - 1e-6:
                return self._fail(
                    f"could follow only {100 * result.fraction:.0f} % of the path: {result.reason}"
                )
            if self.stop_requested():
                return False
            trajectory = time_parameterize(
                result.path,
                model,
                float(self.get_input("velocity_scale_factor")),
                float(self.get_input("acceleration_scale_factor")),
            )
        except KinemaError as error:
            return self._fail(str(error))
        message = trajectory_message(trajectory)
        self.set_output("joint_trajectory_msg", message)
        publish_planned_trajectory(self, message)
        return True

    def _poses(self) -> list[tuple[str, Any]]:
        value = self.get_input("path")
        items = list(value) if isinstance(value, list | tuple) else [value]
        if not items:
            raise ObjectiveError("path is empty")
        return [pose_matrix(item, f"path[{i}]") for i, item in enumerate(items)]

    def _fail(self, reason: str) -> bool:
        self.logger.publish_failure(f"PlanCartesianPath: planning failed: {reason}")
        return False
