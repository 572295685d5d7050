"""GetRobotStateFromTrajectory: the joint state a trajectory passes through at a given time."""

from __future__ import annotations

from kinema.behaviors import FormerSpelling, NodeStatus, PortInfo, SyncBehavior, input_port

from ..messages.conversions import (
    JOINT_STATE_TYPE,
    TRAJECTORY_TYPE,
    joint_state_message,
    trajectory_from_message,
)
from ..messages.ports import fails_on_bad_input, message_input, message_output, port_error, read_message


class GetRobotStateFromTrajectory(SyncBehavior):
    """Writes the joint state of ``joint_trajectory_msg`` at ``time_from_reference`` seconds.

    The time counts from the trajectory's start (``from_start`` true) or back from its end (false);
    between two points the positions are interpolated linearly. A time outside the trajectory fails,
    naming its duration.
    """

    subcategory = "Motion - Planning"
    former_spellings = (FormerSpelling("GetTrajectoryStateAtTime"),)

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "joint_trajectory_msg", TRAJECTORY_TYPE, "{joint_trajectory_msg}", "The trajectory to sample."
            ),
            input_port(
                "from_start", bool, True, "Count time_from_reference from the start (else from the end)."
            ),
            input_port(
                "time_from_reference", float, 0.0, "Seconds from the start (or before the end), >= 0."
            ),
            message_output("joint_state", JOINT_STATE_TYPE, "{joint_state}", "The state at that time."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        message = read_message(self, "joint_trajectory_msg")
        from kinema.errors import ObjectiveError

        try:
            trajectory = trajectory_from_message(message, "joint_trajectory_msg")
        except ObjectiveError as error:
            raise port_error(
                self, "joint_trajectory_msg", str(error), "expected a trajectory with points"
            ) from None
        offset = float(self.get_input("time_from_reference"))
        duration = float(trajectory.times[-1])
        if not 0.0 <= offset <= duration + 1e-9:
            raise port_error(
                self,
                "time_from_reference",
                f"= {offset:g} s is outside the trajectory",
                f"valid: 0 .. {duration:g} s",
            )
        t = offset if bool(self.get_input("from_start")) else duration - offset
        positions = [
            float(np.interp(t, trajectory.times, trajectory.positions[:, j]))
            for j in range(len(trajectory.joint_names))
        ]
        self.set_output("joint_state", joint_state_message(trajectory.joint_names, positions))
        return NodeStatus.SUCCESS
