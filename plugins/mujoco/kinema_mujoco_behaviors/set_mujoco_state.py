"""SetMujocoState: put the simulated robot (and scene) into a given state."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import PortInfo, ServiceClientBehavior, input_port
from kinema.drivers.mujoco.names import SET_STATE_SERVICE


class SetMujocoState(ServiceClientBehavior["kinema_msgs/srv/SetMujocoState"]):
    """Sets the simulator's joints to ``robot_state`` (after resetting to ``keyframe`` when given).

    Sim time keeps running; motions in progress are aborted and the controllers hold the new state.
    Deactivate the command controllers around it (as "Reset MuJoCo Robot" does) so nothing fights the jump.
    """

    subcategory = "MuJoCo Simulation"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "robot_state",
                None,
                "{joint_state_msg}",
                "Joint positions to set (a RobotState, e.g. from CreateRobotState or "
                "LoadRobotJointStateFromYaml, or a JointState). The default entry is what MoveIt Pro's "
                "lab_sim objectives imply ('Load MuJoCo Robot State' writes {joint_state_msg}).",
            ),
            input_port("keyframe", str, "", "MJCF keyframe to reset the whole scene to first ('' for none)."),
            input_port("service_name", str, SET_STATE_SERVICE, "The simulator's SetMujocoState service."),
            input_port("timeout", float, 5.0, "Seconds to wait for the simulator."),
        ]

    def get_response_timeout(self) -> float:
        return float(self.get_input("timeout"))

    def create_request(self) -> dict[str, Any]:
        keyframe = str(self.get_input_or("keyframe", ""))
        result = self.try_get_input("robot_state")
        state = result.value if result.error is None else None
        if state is None and not keyframe:
            raise_missing(self, result.error)
        joint_state = getattr(state, "joint_state", state)
        request: dict[str, Any] = {"keyframe": keyframe}
        if joint_state is not None:
            request["joint_state"] = {
                "name": [str(n) for n in joint_state.name],
                "position": [float(p) for p in joint_state.position],
            }
        return request

    def process_response(self, response: Any) -> bool:
        if not response.success:
            self.logger.publish_failure(
                f"SetMujocoState: the simulator refused the state: {response.message}"
            )
            return False
        return True


def raise_missing(behavior: Any, reason: str | None) -> None:
    """Fail the run: neither a robot state nor a keyframe was given."""
    from kinema.behaviors import MissingInputsError

    raise MissingInputsError(
        behavior.full_path,
        {"robot_state": f"{reason}; give a robot state (e.g. from CreateRobotState) or a keyframe"},
    )
