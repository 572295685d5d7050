"""AttachURDF: bind a URDF object of the planning scene to a robot link, so it moves with the robot."""

from __future__ import annotations

from kinema.behaviors import PortInfo, SyncBehavior, input_port
from kinema.behaviors.cell_ports import cell_input_port
from kinema.bt import NodeStatus
from kinema.errors import KinemaError, did_you_mean

from ..messages.ports import fails_on_bad_input, port_error, read_input
from .urdf_scene import urdf_in_world, world_T_link


class AttachURDF(SyncBehavior):
    """Attaches URDF object ``urdf_name`` (added by AddURDF) to ``parent_link_name`` where it is now.

    From then on it moves with that link: plans check it against the world and against the robot's links
    except ``parent_link_name`` and ``allowed_collision_links`` (the links it may touch, such as the
    flange it sits on), ``kinema view`` draws it on the link, and GetCurrentPlanningScene lists it among
    the robot state's attached objects. Fails when the object is not in the scene, is attached already,
    or the link is not the robot's.
    """

    subcategory = "Motion - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("urdf_name", str, "", "Id of the URDF object (as AddURDF named it)."),
            cell_input_port("parent_link_name", str, "tool_frame", "The robot link the object moves with."),
            input_port(
                "allowed_collision_links",
                list[str],
                "",
                "Robot links the object may touch (besides parent_link_name), e.g. link_5;link_6.",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from ..motion.planning_resources import robot_model

        name = str(read_input(self, "urdf_name")).strip()
        link = str(read_input(self, "parent_link_name")).strip()
        allowed = [str(v).strip() for v in self.get_input_or("allowed_collision_links", []) if str(v).strip()]
        try:
            model = robot_model(self.context, "AttachURDF")
        except KinemaError as error:
            self.logger.publish_failure(f"AttachURDF: {error}")
            return NodeStatus.FAILURE
        unknown = [a for a in allowed if a not in model.link_names]
        if unknown:
            raise port_error(
                self,
                "allowed_collision_links",
                f"names {unknown[0]!r}, which is no link of the robot",
                did_you_mean(unknown[0], model.link_names),
            )
        try:
            urdf_in_world(self, name)
            self.context.planning_scene.attach(name, link, world_T_link(self, link), allowed)
        except KinemaError as error:
            self.logger.publish_failure(f"AttachURDF: {error}")
            return NodeStatus.FAILURE
        return NodeStatus.SUCCESS
