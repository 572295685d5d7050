"""AddCollisionObject: apply a ``moveit_msgs/CollisionObject`` to the planning scene."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import KinemaError

from ..messages.ports import PortValueError, fails_on_bad_input, message_input, port_error, read_message
from ..motion.planning_resources import planning_scene, robot_model
from ..poses.frame_tree import current_frame_tree
from .scene_messages import ADD, COLLISION_OBJECT_TYPE, REMOVE, primitives_of


class AddCollisionObject(SyncBehavior):
    """Adds ``collision_object`` (its primitives and meshes, in any frame of the cell) to the planning scene.

    An object whose ``operation`` is REMOVE removes the object of that id instead. Boxes, spheres and
    cylinders are checked exactly, meshes as their bounding box; cones and planes fail the behavior. With
    ``overwrite`` false an existing object of the same id fails the behavior.
    """

    subcategory = "Perception - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "collision_object", COLLISION_OBJECT_TYPE, "{collision_object}", "The object to add."
            ),
            input_port("overwrite", bool, False, "Replace an object of the same id instead of failing."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        message = read_message(self, "collision_object")
        object_id = str(message.id)
        if not object_id:
            raise port_error(self, "collision_object", "has an empty id", "set the message's id field")
        operation = int(message.operation)
        try:
            model = robot_model(self.context, "AddCollisionObject")
            scene = planning_scene(self.context, model)
            if operation == REMOVE:
                scene.remove_world_object(object_id)
                return NodeStatus.SUCCESS
            if operation != ADD:
                raise port_error(
                    self,
                    "collision_object",
                    f"has operation {operation} (APPEND or MOVE)",
                    "Kinema applies ADD (0) and REMOVE (1); send the whole object with ADD and overwrite",
                )
            frame = str(message.header.frame_id)
            frames = None if frame in ("", "world") else current_frame_tree(self)
            scene.add_world_object(
                object_id, primitives_of(message, frames), replace=bool(self.get_input("overwrite"))
            )
        except PortValueError:
            raise
        except KinemaError as error:
            self.logger.publish_failure(f"AddCollisionObject: {error}")
            return NodeStatus.FAILURE
        return NodeStatus.SUCCESS
