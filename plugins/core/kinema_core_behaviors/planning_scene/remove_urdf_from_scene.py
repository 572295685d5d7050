"""RemoveURDFFromScene: take a URDF object out of the planning scene."""

from __future__ import annotations

from kinema.behaviors import PortInfo, SyncBehavior, input_port
from kinema.bt import NodeStatus
from kinema.errors import KinemaError

from ..messages.ports import fails_on_bad_input, read_input
from ..motion.planning_resources import robot_model
from .urdf_scene import urdf_in_world


class RemoveURDFFromScene(SyncBehavior):
    """Removes URDF object ``urdf_name`` (added by AddURDF) from the planning scene. An attached object must
    be detached first (DetachURDF), as in MoveIt Pro; the behavior fails then, and when there is no such
    object (naming those there are).
    """

    subcategory = "Motion - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [input_port("urdf_name", str, "", "Id of the URDF object to remove.")]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        name = str(read_input(self, "urdf_name")).strip()
        try:
            robot_model(self.context, "RemoveURDFFromScene")
            urdf_in_world(self, name)
            self.context.planning_scene.remove_world_object(name)
        except KinemaError as error:
            self.logger.publish_failure(f"RemoveURDFFromScene: {error}")
            return NodeStatus.FAILURE
        return NodeStatus.SUCCESS
