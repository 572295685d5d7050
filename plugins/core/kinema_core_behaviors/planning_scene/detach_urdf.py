"""DetachURDF: put a URDF object the robot carries back into the world where it is now."""

from __future__ import annotations

from kinema.behaviors import PortInfo, SyncBehavior, input_port
from kinema.bt import NodeStatus
from kinema.errors import KinemaError, MotionError

from ..messages.ports import fails_on_bad_input, read_input
from ..motion.planning_resources import robot_model
from .urdf_scene import known, world_T_link


class DetachURDF(SyncBehavior):
    """Detaches URDF object ``urdf_name`` from the robot: it stays in the planning scene, fixed in the world
    where its link holds it now (a tool put down in its holder). Fails when no URDF object of that id is
    attached.
    """

    subcategory = "Motion - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [input_port("urdf_name", str, "", "Id of the attached URDF object.")]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        name = str(read_input(self, "urdf_name")).strip()
        try:
            robot_model(self.context, "DetachURDF")
            scene = self.context.planning_scene
            attached = scene.attached_objects().get(name)
            if attached is None or not attached.urdf:
                held = sorted(oid for oid, item in scene.attached_objects().items() if item.urdf)
                raise MotionError(
                    f"no URDF object {name!r} is attached to the robot; "
                    + (f"attached: {', '.join(held)}" if held else f"none is attached ({known(scene, name)})")
                )
            scene.detach(name, world_T_link(self, attached.link))
        except KinemaError as error:
            self.logger.publish_failure(f"DetachURDF: {error}")
            return NodeStatus.FAILURE
        return NodeStatus.SUCCESS
