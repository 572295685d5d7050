"""CreateStationaryTrajectory: a trajectory that holds the robot still for a while."""

from __future__ import annotations

import math

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from ..messages.conversions import JOINT_STATE_TYPE, TRAJECTORY_TYPE, joint_positions
from ..messages.ports import fails_on_bad_input, message_input, message_output, port_error, read_message


class CreateStationaryTrajectory(SyncBehavior):
    """Writes a trajectory that stays at ``joint_state`` for ``trajectory_duration`` seconds.

    Two points with the same positions and zero velocities, at 0 and at the duration: executing it
    keeps the controller holding the arm (MoveIt Pro uses it to run admittance control in place).
    """

    subcategory = "Motion - Planning"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("joint_state", JOINT_STATE_TYPE, "{joint_state}", "Where to stay."),
            input_port("trajectory_duration", float, 1.0, "How long to stay (s, > 0; default not public)."),
            message_output(
                "joint_trajectory_msg",
                TRAJECTORY_TYPE,
                "{joint_trajectory_msg}",
                "The stationary trajectory.",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.errors import ObjectiveError
        from kinema.transport import from_dict

        from ..messages.conversions import duration

        try:
            positions = joint_positions(read_message(self, "joint_state"), "joint_state")
        except ObjectiveError as error:
            raise port_error(self, "joint_state", str(error)) from None
        if not positions:
            raise port_error(self, "joint_state", "names no joint", "expected a state from GetJointState")
        seconds = float(self.get_input("trajectory_duration"))
        if not (math.isfinite(seconds) and seconds > 0):
            raise port_error(self, "trajectory_duration", f"= {seconds:g}", "expected a duration > 0 s")
        zeros = [0.0] * len(positions)
        points = [
            {
                "positions": list(positions.values()),
                "velocities": zeros,
                "accelerations": zeros,
                "time_from_start": duration(t),
            }
            for t in (0.0, seconds)
        ]
        message = from_dict(TRAJECTORY_TYPE, {"joint_names": list(positions), "points": points})
        self.set_output("joint_trajectory_msg", message)
        return NodeStatus.SUCCESS
