"""ExecuteTrajectoryWithAdmittance: run a trajectory on the admittance controller, with compliance."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import PortInfo
from kinema.behaviors.cell_ports import cell_input_port

from .execute_trajectory import ExecuteTrajectory


class ExecuteTrajectoryWithAdmittance(ExecuteTrajectory):
    """Sends ``joint_trajectory_msg`` with ``admittance_parameters_msg`` to the admittance controller.

    ExecuteTrajectory with its admittance ports, always as a FollowJointTrajectoryWithAdmittance goal:
    the trajectory, the compliance (none given: tracked rigidly) and the force/torque threshold (none
    given: the controller's default) travel together to the joint trajectory admittance controller, which
    is activated first when inactive. MoveIt Pro's port list of this behavior is not public; Kinema gives
    it ExecuteTrajectory's, with the config's admittance controller as the default action. Fails as
    ExecuteTrajectory does, and when the wrench on the tool passes the threshold.
    """

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        ports = super().provided_ports()
        action = cell_input_port(
            "controller_action_name",
            str,
            "admittance_controller_action",
            "The FollowJointTrajectoryWithAdmittance action of the admittance controller.",
        )
        return [action if port.name == "controller_action_name" else port for port in ports]

    def admittance_fields(self) -> dict[str, Any] | None:
        """The admittance part of the goal; present even when no admittance port is set."""
        return super().admittance_fields() or {"absolute_force_torque_threshold": []}
