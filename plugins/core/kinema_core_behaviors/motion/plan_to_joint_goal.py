"""PlanToJointGoal: a collision-free, timed trajectory from the current state to a joint goal."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import AsyncBehavior, FormerSpelling, PortInfo, input_port, output_port
from kinema.behaviors.cell_ports import cell_input_port
from kinema.errors import KinemaError, did_you_mean

from ..messages.conversions import joint_positions, trajectory_message
from ..messages.ports import speed_scale_ports
from .joint_states import joint_state_monitor
from .planned_trajectory import publish_planned_trajectory
from .planning_resources import collision_checker, robot_model


def no_orientation_constraint(value: Any) -> bool:
    """True for the ways objectives say "no orientation constraint" (unset, '', '[]')."""
    if value is None:
        return True
    if isinstance(value, str):
        return value.strip() in ("", "[]")
    if isinstance(value, list | tuple):
        return len(value) == 0
    return False


class PlanToJointGoal(AsyncBehavior):
    """Plans from the robot's current joint state to ``joint_goal`` for ``planning_group_name``.

    The start is the latest ``/joint_states``; the path keeps ``link_padding`` metres between the
    robot and the planning scene (a straight joint-space move when that is collision-free, else OMPL,
    or Kinema's seeded RRT-Connect when ``seed`` is set), and is timed with the joint limits scaled by
    the velocity and acceleration factors, ``trajectory_sampling_rate`` points per second.
    Fails with the planner's reason: unknown joints, a goal outside the limits or in collision, or no
    path within ``planning_time`` (or ``max_iterations`` samples of the seeded search).
    """

    subcategory = "Motion - Planning"
    former_spellings = (
        FormerSpelling(
            dropped={
                "keep_orientation": "planning keeps no orientation constraint yet (orientation_constraint "
                "takes only '[]')",
                "keep_orientation_tolerance": "it only bounds keep_orientation",
            },
            accepted_values={"keep_orientation": ("false", "False", "FALSE", "0")},
        ),
    )

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "joint_goal",
                None,
                "{target_joint_state}",
                "Goal joint state (sensor_msgs/JointState; written out: {name: [...], position: [...]} "
                "or {joint: value, ...}).",
            ),
            cell_input_port("planning_group_name", str, "planning_group", "The planning group that moves."),
            input_port("link_padding", float, 0.01, "Clearance (m) kept between the robot and the scene."),
            *speed_scale_ports(),
            input_port(
                "orientation_constraint",
                None,
                "[]",
                "Keep the tool's orientation (not supported yet: only '[]', no constraint, is accepted).",
            ),
            input_port("planner_id", str, "RRTConnect", "OMPL planner used when a straight move collides."),
            input_port("planning_time", float, 1.0, "Seconds the planner may search."),
            input_port(
                "seed",
                int,
                "",
                "Random seed of the search when the straight move collides. Unset: OMPL's planner_id, "
                "whose generator is process-wide (the same request may take another path later). A "
                "number: Kinema's seeded RRT-Connect, which gives the same path for the same request and "
                "seed in any process (planner_id must then be RRTConnect).",
            ),
            input_port(
                "max_iterations",
                int,
                5000,
                "Samples the seeded search may draw before it fails (> 0). Applies only with seed set: "
                "OMPL's planners are bounded by planning_time alone.",
            ),
            input_port(
                "trajectory_sampling_rate",
                float,
                100.0,
                "Points per second of the timed trajectory (Hz, > 0): points at most 1/rate apart, "
                "spread evenly over its duration (MoveIt Pro's default is not public; Kinema's: 100).",
            ),
            output_port(
                "joint_trajectory_msg",
                None,
                "{joint_trajectory_msg}",
                "The timed trajectory (trajectory_msgs/JointTrajectory).",
            ),
        ]

    def do_work(self) -> bool:
        from kinema.motion import PLANNERS, PlanningOptions, plan_joint_goal, time_parameterize

        goal_value = self.get_input("joint_goal")
        group = str(self.get_input("planning_group_name"))
        padding = float(self.get_input("link_padding"))
        velocity_scale = float(self.get_input("velocity_scale_factor"))
        acceleration_scale = float(self.get_input("acceleration_scale_factor"))
        planner = str(self.get_input("planner_id"))
        if not no_orientation_constraint(self.get_input("orientation_constraint")):
            return self._fail("orientation constraints are not supported yet; pass '[]'")
        if planner not in PLANNERS:
            return self._fail(f"unknown planner_id {planner!r}; {did_you_mean(planner, PLANNERS)}")
        seed = int(self.get_input("seed")) if "seed" in self.config.input_ports else None
        max_iterations = int(self.get_input("max_iterations"))
        if max_iterations <= 0:
            return self._fail(f"max_iterations must be > 0 samples, got {max_iterations}")
        rate = float(self.get_input("trajectory_sampling_rate"))
        if not rate > 0:
            return self._fail(f"trajectory_sampling_rate must be > 0 points per second, got {rate:g}")
        try:
            goal = joint_positions(goal_value, "joint_goal")
            model = robot_model(self.context, "PlanToJointGoal")
            if group not in model.groups:
                return self._fail(
                    f"unknown planning group {group!r}; {did_you_mean(group, list(model.groups))}"
                )
            if not goal:
                return self._fail("joint_goal names no joint")
            start = joint_state_monitor(self.context, "PlanToJointGoal").current_positions(
                model.joint_names, self.context.clock
            )
            checker = collision_checker(self.context, "PlanToJointGoal", padding)
            options = PlanningOptions(
                planner=planner,
                timeout=float(self.get_input("planning_time")),
                seed=seed,
                max_iterations=max_iterations,
            )
            path = plan_joint_goal(checker, start, goal, group, options)
            if self.stop_requested():
                return False
            trajectory = time_parameterize(
                path, model, velocity_scale, acceleration_scale, sample_period=1.0 / rate
            )
        except KinemaError as error:
            return self._fail(str(error))
        message = trajectory_message(trajectory)
        self.set_output("joint_trajectory_msg", message)
        publish_planned_trajectory(self, message)
        return True

    def _fail(self, reason: str) -> bool:
        self.logger.publish_failure(f"PlanToJointGoal: planning failed: {reason}")
        return False
