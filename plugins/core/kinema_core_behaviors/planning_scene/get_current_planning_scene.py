"""GetCurrentPlanningScene: the planning scene as it is now."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior
from kinema.errors import KinemaError

from ..messages.ports import message_output
from ..motion.joint_states import joint_state_monitor
from ..motion.planning_resources import robot_model


class GetCurrentPlanningScene(SyncBehavior):
    """Writes the current planning scene: the world's collision objects and the robot's joint state.

    The collision objects are those objectives added (AddCollisionBox, AddCollisionObject), in ``world``;
    the cell's own geometry is part of every plan but not listed, as in MoveIt. The robot state is the
    latest ``/joint_states`` when a driver publishes one.
    """

    subcategory = "Perception - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        from kinema.motion.planning_scene_messages import PLANNING_SCENE_TYPE

        return [
            message_output(
                "planning_scene_msg", PLANNING_SCENE_TYPE, "{planning_scene}", "The current planning scene."
            ),
        ]

    def tick(self) -> NodeStatus:
        from kinema.motion.planning_scene_messages import planning_scene_message

        try:
            model = robot_model(self.context, "GetCurrentPlanningScene")
            scene = self.context.planning_scene
        except KinemaError as error:
            self.logger.publish_failure(f"GetCurrentPlanningScene: {error}")
            return NodeStatus.FAILURE
        joint_state = None
        if self.context.node is not None:
            try:
                joint_state = joint_state_monitor(self.context, "GetCurrentPlanningScene").latest(timeout=1.0)
            except KinemaError:
                joint_state = None  # no driver: a scene without a robot state, as MoveIt gives
        self.set_output("planning_scene_msg", planning_scene_message(scene, model.name, joint_state))
        return NodeStatus.SUCCESS
