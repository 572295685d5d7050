"""IsAnyObjectAttached and WhichObjectIsAttached: what the robot carries, read from a planning scene."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from ..messages.ports import fails_on_bad_input, message_input, read_message, read_vector


def _attached_ids(node: Any) -> list[str]:
    scene = read_message(node, "planning_scene")
    return [str(item.object.id) for item in scene.robot_state.attached_collision_objects]


def _scene_port() -> PortInfo:
    from kinema.motion.planning_scene_messages import PLANNING_SCENE_TYPE

    return message_input(
        "planning_scene",
        PLANNING_SCENE_TYPE,
        "{planning_scene}",
        "The scene to look in (from GetCurrentPlanningScene).",
    )


class IsAnyObjectAttached(SyncBehavior):
    """Succeeds when ``planning_scene``'s robot state has an attached object (a tool AttachURDF bound to a
    link, say); fails, saying so, when the robot carries nothing."""

    subcategory = "Motion - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [_scene_port()]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        if _attached_ids(self):
            return NodeStatus.SUCCESS
        self.logger.publish_info("IsAnyObjectAttached: no object is attached to the robot")
        return NodeStatus.FAILURE


class WhichObjectIsAttached(SyncBehavior):
    """Writes to ``object_name`` the first of ``object_names`` that is attached in ``planning_scene`` and
    succeeds; fails, naming what is attached, when none of them is."""

    subcategory = "Motion - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            _scene_port(),
            input_port(
                "object_names",
                list[str],
                "",
                "The objects to look for, in order (e.g. suction_gripper;inspector).",
            ),
            output_port("object_name", str, "{object_name}", "The first of object_names that is attached."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        attached = _attached_ids(self)
        names = read_vector(self, "object_names") if "object_names" in self.config.input_ports else []
        wanted = [str(v).strip() for v in names if str(v).strip()]
        for name in wanted:
            if name in attached:
                self.set_output("object_name", name)
                return NodeStatus.SUCCESS
        self.logger.publish_info(
            f"WhichObjectIsAttached: none of {', '.join(wanted) or '(no names)'} is attached; "
            + (f"attached: {', '.join(attached)}" if attached else "nothing is attached")
        )
        return NodeStatus.FAILURE
