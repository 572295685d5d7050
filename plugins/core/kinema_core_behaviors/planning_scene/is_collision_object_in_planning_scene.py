"""IsCollisionObjectInPlanningScene: does a planning scene contain an object of that id?"""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from ..messages.ports import fails_on_bad_input, message_input, read_message


class IsCollisionObjectInPlanningScene(SyncBehavior):
    """Succeeds when ``planning_scene`` (from GetCurrentPlanningScene) has a collision object
    ``collision_object_name``; fails otherwise, naming the objects it has."""

    subcategory = "Perception - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        from kinema.motion.planning_scene_messages import PLANNING_SCENE_TYPE

        return [
            message_input("planning_scene", PLANNING_SCENE_TYPE, "{planning_scene}", "The scene to look in."),
            input_port("collision_object_name", str, "", "The id to look for."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        scene = read_message(self, "planning_scene")
        name = str(self.get_input("collision_object_name"))
        ids = [str(obj.id) for obj in scene.world.collision_objects]
        if name in ids:
            return NodeStatus.SUCCESS
        self.logger.publish_failure(
            f"IsCollisionObjectInPlanningScene: no collision object {name!r} in the planning scene; "
            f"it has {', '.join(repr(i) for i in ids) or 'none'}"
        )
        return NodeStatus.FAILURE
