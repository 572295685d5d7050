"""GetJointState: the robot's current joint state."""

from __future__ import annotations

from kinema.behaviors import AsyncBehavior, FormerSpelling, PortInfo, input_port, output_port
from kinema.errors import KinemaError, did_you_mean

from ..messages.conversions import joint_state_message
from .joint_states import joint_state_monitor


class GetJointState(AsyncBehavior):
    """Writes the next ``/joint_states`` message received (for ``planning_group_name``'s joints, or all).

    It waits for a message newer than its start, so the state is never older than the behavior.
    """

    subcategory = "Motion - Planning"
    former_spellings = (FormerSpelling("GetRobotJointState"),)

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("planning_group_name", str, "", "Keep only this group's joints ('' keeps all)."),
            input_port("timeout", float, 2.0, "Seconds to wait for a joint state."),
            input_port(
                "planning_scene",
                None,
                "",
                "MoveIt Pro's planning scene input (moveit_msgs/PlanningScene); the state comes from "
                "/joint_states, so it is accepted and not needed.",
            ),
            output_port(
                "joint_state",
                None,
                "{robot_joint_state}",
                "The joint state (sensor_msgs/JointState). Default from the corpus: "
                "save_robot_joint_state.xml saves {robot_joint_state} right after a GetJointState with "
                "default ports.",
            ),
        ]

    def do_work(self) -> bool:
        group = str(self.get_input_or("planning_group_name", ""))
        try:
            message = joint_state_monitor(self.context, "GetJointState").fresh(
                float(self.get_input("timeout"))
            )
        except KinemaError as error:
            self.logger.publish_failure(f"GetJointState: {error}")
            return False
        names = [str(n) for n in message.name]
        positions = [float(p) for p in message.position]
        if group:
            model = self.context.robot_model
            if model is None or group not in model.groups:
                valid = list(model.groups) if model is not None else []
                self.logger.publish_failure(
                    f"GetJointState: unknown planning group {group!r}; {did_you_mean(group, valid)}"
                )
                return False
            members = model.group(group).joint_names
            index = {n: i for i, n in enumerate(names)}
            missing = [n for n in members if n not in index]
            if missing:
                self.logger.publish_failure(f"GetJointState: /joint_states lacks {', '.join(missing)}")
                return False
            names, positions = list(members), [positions[index[n]] for n in members]
        self.set_output("joint_state", joint_state_message(names, positions))
        return True
