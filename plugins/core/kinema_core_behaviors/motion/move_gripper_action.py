"""MoveGripperAction: open or close a gripper through its GripperCommand action."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import ActionClientBehavior, PortInfo, input_port
from kinema.behaviors.cell_ports import cell_input_port


class MoveGripperAction(ActionClientBehavior["control_msgs/action/GripperCommand"]):
    """Sends the gripper to ``position`` and waits until it gets there or stalls on an object.

    As MoveIt Pro's gripper controllers are set up (``allow_stalling: true``), both endings succeed: the
    fingers reaching ``position`` (``reached_goal``) and the fingers stopping short of it on an object
    (``stalled``). A pick that must hold something sets ``require_grasp``: then reaching ``position``
    means the gripper closed on nothing, and the behavior fails saying so (a ``ForceSuccess`` around the
    pick lets it go on anyway). The gripper controller aborting, or no result within ``timeout`` seconds,
    fails.
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
            input_port(
                "require_grasp",
                bool,
                False,
                "Kinema's grasp check (MoveIt Pro's MoveGripperAction has no such port: its controller "
                "succeeds either way). True: the goal must end stalled on an object; a gripper that reaches "
                "`position` (the controller's reached_goal: nothing between the fingers) fails with 'the "
                "gripper closed on nothing'. Set it on the close of a pick; False (default): reaching "
                "`position` succeeds, as closing an empty gripper on purpose should.",
            ),
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
        target = float(self.get_input("position"))
        if not result.succeeded:
            self.logger.publish_failure(
                f"MoveGripperAction: the gripper goal ended {result.status_name} at position "
                f"{outcome.position:.4f} (target {target:.4f})"
            )
            return False
        if outcome.reached_goal and bool(self.get_input("require_grasp")):
            self.logger.publish_failure(
                f"MoveGripperAction: the gripper closed on nothing: it reached {outcome.position:.4f} "
                f"(target {target:.4f}) without stopping on an object, and require_grasp is true. Check "
                "that the object is where the gripper closed (in simulation, after a cancelled pick, "
                "`kinema sim reset` puts the objects back), or wrap the pick in ForceSuccess to go on "
                "without it."
            )
            return False
        if outcome.reached_goal or outcome.stalled:
            return True
        self.logger.publish_failure(
            f"MoveGripperAction: the gripper stopped at {outcome.position:.4f} without reaching "
            f"{target:.4f} or grasping an object"
        )
        return False
