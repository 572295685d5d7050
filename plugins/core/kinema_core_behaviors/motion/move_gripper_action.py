"""MoveGripperAction: open or close a gripper through its GripperCommand action."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import ActionClientBehavior, PortInfo, input_port
from kinema.behaviors.cell_ports import cell_input_port


class MoveGripperAction(ActionClientBehavior["control_msgs/action/GripperCommand"]):
    """Sends the gripper to ``position`` and waits until it gets there or stalls on an object.

    A stall counts as success: closing on an object stops short of the commanded position, and that
    is a grasp. The gripper controller aborting, or no result within ``timeout`` seconds, fails.
    """

    subcategory = "Motion - Execute"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            cell_input_port(
                "gripper_command_action_name",
                str,
                "gripper_action",
                "The GripperCommand action of the gripper controller.",
            ),
            input_port(
                "position",
                float,
                0.0,
                "Target position of the gripper joint (m or rad; the config's robot.gripper says where "
                "open and closed are).",
            ),
            input_port("max_effort", float, 0.0, "Effort limit (0: the controller's default)."),
            input_port("timeout", float, 10.0, "Seconds to wait for the gripper to finish."),
        ]

    def get_action_name(self) -> str:
        return str(self.get_input("gripper_command_action_name"))

    def get_result_timeout(self) -> float | None:
        timeout = float(self.get_input("timeout"))
        return timeout if timeout > 0 else None

    def create_goal(self) -> dict[str, Any]:
        position, max_effort = self.get_required_inputs("position", "max_effort")
        return {"command": {"position": float(position), "max_effort": float(max_effort)}}

    def process_result(self, result: Any) -> bool:
        outcome = result.result
        if not result.succeeded:
            self.logger.publish_failure(
                f"MoveGripperAction: the gripper goal ended {result.status_name} at position "
                f"{outcome.position:.4f} (target {float(self.get_input('position')):.4f})"
            )
            return False
        if outcome.reached_goal or outcome.stalled:
            return True
        self.logger.publish_failure(
            f"MoveGripperAction: the gripper stopped at {outcome.position:.4f} without reaching "
            f"{float(self.get_input('position')):.4f} or grasping an object"
        )
        return False
