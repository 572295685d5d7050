"""PlanCartesianPath: a timed trajectory moving the tool in straight lines through poses."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import AsyncBehavior, PortInfo, input_port, output_port
from kinema.behaviors.cell_ports import cell_input_port
from kinema.errors import KinemaError, ObjectiveError, did_you_mean

from ..messages.conversions import pose_matrix, trajectory_message
from ..messages.ports import speed_scale_ports
from .joint_states import joint_state_monitor
from .planned_trajectory import publish_planned_trajectory
from .planning_resources import collision_checker, robot_model

WORLD_FRAMES = ("", "world")


class PlanCartesianPath(AsyncBehavior):
    """Plans the tool link through ``path`` (PoseStamped waypoints) in straight lines from the current state.

    Each pose is in ``world`` or in a robot link's frame (taken at the start state). IK is solved every
    ``ik_cartesian_space_density`` metres along the lines, seeded by the previous solution; interior
    corners are rounded by ``blending_radius`` (a circular arc tangent to both lines). Fails naming
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
            cell_input_port("planning_group_name", str, "planning_group", "The planning group that moves."),
            input_port(
                "tip_links",
                list[str],
                "",
                "The tool frame that follows the path ('': the config's robot.tool_frame, else the "
                "group's tip).",
            ),
            input_port(
                "tip_link",
                str,
                "",
                "One tool frame, as MoveIt Pro's older objectives name it: the same as tip_links with one "
                "link (give one of the two).",
            ),
            input_port(
                "position_only", bool, False, "Follow the positions only, leave the orientation free."
            ),
            input_port("ik_cartesian_space_density", float, 0.005, "Distance (m) between IK solutions."),
            input_port("link_padding", float, 0.0, "Clearance (m) kept between the robot and the scene."),
            *speed_scale_ports(),
            input_port(
                "ik_joint_space_density",
                float,
                0.1,
                "Largest joint change (rad or m) allowed between consecutive IK solutions; a larger jump "
                "stops the path (the arm would flip).",
            ),
            input_port(
                "tip_offset",
                list[float],
                "0;0;0;0;0;0",
                "Offset x;y;z;roll;pitch;yaw (m, rad) of the point that follows the path, in the tip "
                "link's frame.",
            ),
            input_port(
                "trajectory_sampling_rate",
                int,
                100,
                "Points per second of the timed trajectory (MoveIt Pro's default is not public; Kinema's: "
                "100, its planners' rate).",
            ),
            input_port(
                "trajectory_timing",
                str,
                "[{mode: time_optimal}]",
                "How the path is timed: [{mode: time_optimal}] (the only mode; time-optimal under the "
                "scaled joint limits).",
            ),
            input_port(
                "blending_radius",
                float,
                0.02,
                "Corner rounding (m), >= 0: the tool leaves the straight lines this far before each "
                "interior pose and joins the next line this far after it, along a circular arc tangent "
                "to both (clamped to half the shorter neighbouring line), its orientation turning along "
                "the arc; the first and last poses are reached exactly. 0 passes through every pose.",
            ),
            input_port(
                "max_optimizer_iterations",
                int,
                1,
                "MoveIt Pro's path optimizer iterations (its meaning is not public). Accepted and not "
                "applied: as a cap on Kinema's per-sample IK, the corpus's 1 fails ordinary paths (one "
                "damped least-squares step from the previous sample can miss the 0.1 mm tolerance), "
                "so each sample's IK keeps its own cap of 50 iterations.",
            ),
            output_port(
                "joint_trajectory_msg",
                None,
                "{joint_trajectory_msg}",
                "The timed trajectory (trajectory_msgs/JointTrajectory).",
            ),
            output_port(
                "debug_solution",
                None,
                "{debug_solution}",
                "The solution to show for approval (WaitForMTCSolutionApproval): the same trajectory.",
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
            single = str(self.get_input_or("tip_link", "")).strip()
            if single and tips and tips != [single]:
                return self._fail(
                    f"tip_link {single!r} and tip_links {';'.join(tips)!r} disagree; give one of the two"
                )
            tips = tips or ([single] if single else [])
            if len(tips) > 1:
                return self._fail(f"one tip link at a time is supported, got {', '.join(tips)}")
            rate = float(self.get_input("trajectory_sampling_rate"))
            if not rate > 0:
                return self._fail(f"trajectory_sampling_rate must be > 0 points per second, got {rate:g}")
            cell = self.context.cell
            tip = tips[0] if tips else (cell.tool_frame if cell and cell.tool_frame else None)
            tip = tip or model.group(group).tip_link
            timing = self._timing()
            if timing is not None:
                return self._fail(timing)
            tip_from_offset = self._tip_offset()
            if isinstance(tip_from_offset, str):
                return self._fail(tip_from_offset)
            jump = float(self.get_input("ik_joint_space_density"))
            if not jump > 0:
                return self._fail(f"ik_joint_space_density must be > 0, got {jump}")
            radius = float(self.get_input("blending_radius"))
            if not radius >= 0:
                return self._fail(f"blending_radius must be >= 0 (m), got {radius}")
            poses = self._poses()
            start = joint_state_monitor(self.context, "PlanCartesianPath").current_positions(
                model.joint_names, self.context.clock
            )
            targets = []
            for frame, matrix in poses:
                world_T_point = matrix if frame in WORLD_FRAMES else fk(model, start, frame) @ matrix
                targets.append(world_T_point @ tip_from_offset)
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
                jump_threshold=jump,
                position_only=bool(self.get_input("position_only")),
                blending_radius=radius,
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
                sample_period=1.0 / rate,
            )
        except KinemaError as error:
            return self._fail(str(error))
        message = trajectory_message(trajectory)
        self.set_output("joint_trajectory_msg", message)
        self.set_output("debug_solution", message)
        publish_planned_trajectory(self, message)
        return True

    def _timing(self) -> str | None:
        """None when ``trajectory_timing`` asks for what Kinema does, else the reason it cannot."""
        import yaml

        text = str(self.get_input("trajectory_timing")).strip()
        try:
            value = yaml.safe_load(text) if text else []
        except yaml.YAMLError as error:
            return f"trajectory_timing {text!r} is not YAML: {error.problem}"
        entries = value if isinstance(value, list) else [value]
        for entry in entries:
            mode = entry.get("mode") if isinstance(entry, dict) else entry
            if mode not in (None, "time_optimal"):
                return f"trajectory_timing mode {mode!r} is not supported; valid: time_optimal"
        return None

    def _tip_offset(self) -> Any:
        """``tip_T_point`` inverted (what the tip must do so the offset point follows the path)."""
        import numpy as np

        from kinema.transforms import rotation_from_euler

        values = [float(v) for v in self.get_input("tip_offset")]
        if len(values) not in (3, 6):
            return f"tip_offset needs 6 values x;y;z;roll;pitch;yaw (or 3, x;y;z), got {len(values)}"
        tip_T_point = np.eye(4)
        tip_T_point[:3, 3] = values[:3]
        if len(values) == 6:
            tip_T_point[:3, :3] = rotation_from_euler(values[3:])
        return np.linalg.inv(tip_T_point)

    def _poses(self) -> list[tuple[str, Any]]:
        value = self.get_input("path")
        items = list(value) if isinstance(value, list | tuple) else [value]
        if not items:
            raise ObjectiveError("path is empty")
        return [pose_matrix(item, f"path[{i}]") for i, item in enumerate(items)]

    def _fail(self, reason: str) -> bool:
        self.logger.publish_failure(f"PlanCartesianPath: planning failed: {reason}")
        return False
