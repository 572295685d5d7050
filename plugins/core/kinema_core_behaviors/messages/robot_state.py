"""CreateRobotState: a robot state from joint names and positions."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port
from kinema.errors import did_you_mean

from .conversions import robot_state_message


class CreateRobotState(SyncBehavior):
    """Builds a robot state (``RobotJointState``) setting ``joint_names`` to ``positions``.

    When the runtime has a robot model, every name must be one of its joints.
    """

    subcategory = "Motion - Planning"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("joint_names", list[str], "", "Joint names (';'-separated)."),
            input_port("positions", list[float], "", "One position per joint (';'-separated)."),
            output_port("robot_state", None, "{robot_state}", "The robot state."),
        ]

    def tick(self) -> NodeStatus:
        names = [name.strip() for name in self.get_input("joint_names")]
        positions = list(self.get_input("positions"))
        if len(names) != len(positions):
            self.logger.publish_failure(
                f"CreateRobotState: {len(names)} joint names but {len(positions)} positions"
            )
            return NodeStatus.FAILURE
        if not names:
            self.logger.publish_failure("CreateRobotState: joint_names is empty")
            return NodeStatus.FAILURE
        model = self.context.robot_model
        if model is not None:
            known = list(model.joint_names)
            unknown = [name for name in names if name not in known]
            if unknown:
                self.logger.publish_failure(
                    f"CreateRobotState: unknown joint {unknown[0]!r}; {did_you_mean(unknown[0], known)}"
                )
                return NodeStatus.FAILURE
        self.set_output("robot_state", robot_state_message(names, positions))
        return NodeStatus.SUCCESS
