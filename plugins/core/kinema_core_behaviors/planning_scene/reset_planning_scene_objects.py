"""ResetPlanningSceneObjects: remove every collision object objectives added to the planning scene."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import KinemaError

from ..motion.planning_resources import robot_model


class ResetPlanningSceneObjects(SyncBehavior):
    """Removes all world collision objects (what AddCollisionBox / AddCollisionObject added); the cell's
    own geometry stays. Used by the core "Reset Planning Scene" subtree.

    ``apply_planning_scene_service`` is accepted as in MoveIt Pro; Kinema's planning scene lives in the
    agent, so no service is called.
    """

    subcategory = "Perception - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "apply_planning_scene_service",
                str,
                "/apply_planning_scene",
                "MoveIt Pro's planning scene service (unused: the scene is in the agent).",
            ),
        ]

    def tick(self) -> NodeStatus:
        try:
            robot_model(self.context, "ResetPlanningSceneObjects")
            self.context.planning_scene.reset_world()
        except KinemaError as error:
            self.logger.publish_failure(f"ResetPlanningSceneObjects: {error}")
            return NodeStatus.FAILURE
        return NodeStatus.SUCCESS
