"""SaveCurrentState: the robot's current state, kept on the blackboard to return to later."""

from __future__ import annotations

from kinema.behaviors import AsyncBehavior, PortInfo
from kinema.errors import KinemaError

from ..messages.ports import message_output
from .joint_states import joint_state_monitor

MOVEIT_ROBOT_STATE_TYPE = "moveit_msgs/msg/RobotState"
# How long to wait for /joint_states: MoveIt Pro's behavior has no timeout port; GetJointState's default.
TIMEOUT = 2.0


class SaveCurrentState(AsyncBehavior):
    """Writes the robot's current state, every joint of the next ``/joint_states`` message, to
    ``saved_robot_state``.

    The state is a ``moveit_msgs/RobotState`` whose joint state is that message as received (names,
    positions, velocities, efforts, stamp), so it is never older than the behavior. Planning behaviors
    that take a goal state (SetupMTCPlanToRobotState, SetupMTCCartesianMoveToRobotState) read it, to
    return to where the robot was. Fails when no joint state arrives within 2 s (no driver running).
    """

    subcategory = "Motion - Planning"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_output(
                "saved_robot_state",
                MOVEIT_ROBOT_STATE_TYPE,
                "{saved_robot_state}",
                "The robot's current state (all joints).",
            )
        ]

    def do_work(self) -> bool:
        from kinema.transport import from_dict
        from kinema.transport.messages import to_dict

        try:
            message = joint_state_monitor(self.context, "SaveCurrentState").fresh(TIMEOUT)
        except KinemaError as error:
            self.logger.publish_failure(f"SaveCurrentState: {error}")
            return False
        state = from_dict(MOVEIT_ROBOT_STATE_TYPE, {"joint_state": to_dict(message)})
        self.set_output("saved_robot_state", state)
        return True
