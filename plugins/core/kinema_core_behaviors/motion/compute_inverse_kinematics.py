"""ComputeInverseKinematics: a collision-free joint state putting each tip link at its target pose."""

from __future__ import annotations

import math
from typing import Any

from kinema.behaviors import AsyncBehavior, PortInfo, input_port
from kinema.behaviors.cell_ports import cell_input_port
from kinema.errors import KinemaError, did_you_mean

from ..messages.conversions import JOINT_STATE_TYPE, joint_state_message, pose_matrix
from ..messages.ports import fails_on_bad_input, message_output, port_error, read_input, read_vector
from .joint_states import joint_state_monitor
from .planning_resources import collision_checker, robot_model

WORLD_FRAMES = ("", "world")


class ComputeInverseKinematics(AsyncBehavior):
    """Finds joints of ``planning_group_name`` putting each ``tip_links[i]`` at ``target_poses[i]``.

    All tips are solved together (damped least squares on the stacked tip errors), seeded from the
    robot's current joint state, so the answer stays on the current elbow/wrist branch when one exists
    there; random restarts inside the joint limits follow while ``ik_timeout_s`` lasts. A solution is
    within the joint limits and keeps ``link_padding`` metres from the planning scene and between the
    robot's links. The ``solution`` holds the group's joints only, so PlanToJointGoal (or "Move to Joint
    State") can take it as its goal. Fails naming the tips and the remaining error when no solution is
    found (out of reach, or every solution collides).
    """

    subcategory = "Motion - Planning"
    description = (
        "A collision-free joint state putting each tip link at its target pose (multi-tip IK), seeded "
        "from the current state."
    )

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            cell_input_port("planning_group_name", str, "planning_group", "The planning group that moves."),
            input_port(
                "target_poses",
                None,
                "{target_poses}",
                "One pose per tip link (a vector of geometry_msgs/PoseStamped, e.g. from PushBackVector), "
                "each in world or a frame of the cell (a robot link is taken at the current state).",
            ),
            input_port(
                "tip_links",
                list[str],
                "",
                "The links to place, one per target pose (';'-separated); '' with one pose: the config's "
                "robot.tool_frame, else the group's tip.",
            ),
            input_port(
                "planning_scene_msg",
                None,
                "{planning_scene}",
                "The planning scene (from GetCurrentPlanningScene). Accepted as in MoveIt Pro; collisions "
                "are checked against the runtime's planning scene, which is what it describes.",
            ),
            input_port(
                "ik_timeout_s",
                float,
                0.05,
                "Seconds (> 0) during which random restarts may begin after the attempt from the current "
                "state, which always runs to its end (Kinema's Python IK takes milliseconds per attempt, "
                "so a MoveIt Pro timeout of 0.01 s would otherwise allow none). Kinema's default: 0.05.",
            ),
            input_port(
                "link_padding",
                float,
                0.01,
                "Clearance (m) kept between the robot and the scene (Kinema's default 0.01 is "
                "PlanToJointGoal's, so a solution is a goal it accepts).",
            ),
            message_output(
                "solution",
                JOINT_STATE_TYPE,
                "{solution}",
                "The group's joint positions reaching every target.",
            ),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        from kinema.motion import IkOptions, ik_tips

        group = str(self.get_input("planning_group_name"))
        timeout = float(read_input(self, "ik_timeout_s"))
        if not (math.isfinite(timeout) and timeout > 0):
            raise port_error(self, "ik_timeout_s", f"= {timeout:g}", "expected seconds > 0")
        padding = float(read_input(self, "link_padding"))
        if not (math.isfinite(padding) and padding >= 0):
            raise port_error(self, "link_padding", f"= {padding:g}", "expected metres >= 0")
        poses = read_vector(self, "target_poses")
        if not poses:
            raise port_error(self, "target_poses", "is empty", "push one PoseStamped per tip link")
        try:
            model = robot_model(self.context, "ComputeInverseKinematics")
        except KinemaError as error:
            return self._fail(str(error))
        if group not in model.groups:
            raise port_error(
                self, "planning_group_name", f"= {group!r}", did_you_mean(group, list(model.groups))
            )
        tips = self._tips(model, group, len(poses))
        try:
            monitor = joint_state_monitor(self.context, "ComputeInverseKinematics")
            seed = monitor.current_positions(model.joint_names, self.context.clock)
            from ..poses.frame_tree import current_frame_tree

            tree = current_frame_tree(self, joint_state=joint_state_message(model.joint_names, seed))
            targets = []
            for index, (tip, pose) in enumerate(zip(tips, poses, strict=True)):
                frame, matrix = pose_matrix(pose, f"target_poses[{index}]")
                targets.append((tip, matrix if frame in WORLD_FRAMES else tree.world_T(frame) @ matrix))
            checker = collision_checker(self.context, "ComputeInverseKinematics", padding)
            solution = ik_tips(
                model,
                targets,
                seed,
                group,
                options=IkOptions(timeout=timeout),
                accept=lambda q: not checker.in_collision(q),
            )
        except KinemaError as error:
            return self._fail(str(error))
        joints = model.group(group).joint_names
        values = [float(solution[model.index(name)]) for name in joints]
        self.set_output("solution", joint_state_message(joints, values))
        return True

    def _tips(self, model: Any, group: str, count: int) -> list[str]:
        """The tip links, one per target pose, each a link of the robot."""
        tips = [str(t).strip() for t in read_vector(self, "tip_links")] if self._has("tip_links") else []
        tips = [t for t in tips if t]
        if not tips and count == 1:
            cell = self.context.cell
            default = cell.tool_frame if cell is not None and cell.tool_frame else model.group(group).tip_link
            tips = [default] if default else []
        if len(tips) != count:
            raise port_error(
                self,
                "tip_links",
                f"names {len(tips)} link(s) for {count} target pose(s)",
                "give one tip link per pose, in the same order",
            )
        for tip in tips:
            if tip not in model.link_names:
                raise port_error(self, "tip_links", f"names {tip!r}", did_you_mean(tip, model.link_names))
        if len(set(tips)) != len(tips):
            raise port_error(
                self, "tip_links", f"= {';'.join(tips)!r} names a link twice", "one pose per link"
            )
        return tips

    def _has(self, port: str) -> bool:
        return port in self.config.input_ports

    def _fail(self, reason: str) -> bool:
        self.logger.publish_failure(f"ComputeInverseKinematics: {reason}")
        return False
