"""AddCollisionObject: apply a ``moveit_msgs/CollisionObject`` to the planning scene."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import KinemaError

from ..messages.ports import PortValueError, fails_on_bad_input, message_input, port_error, read_message
from ..motion.planning_resources import robot_model
from ..poses.frame_tree import current_frame_tree


class AddCollisionObject(SyncBehavior):
    """Applies ``collision_object`` (in any frame of the cell) to the planning scene, as MoveIt does.

    The message's ``operation``: ADD puts the object there (with ``overwrite`` false an existing object of
    the same id fails the behavior); REMOVE removes the object of that id; APPEND adds the message's
    shapes to the object of that id (creating it when there is none); MOVE puts the existing object at
    the message's ``pose``, its shapes moving with it (shapes in a MOVE message are ignored, with a
    warning, as MoveIt ignores them). Boxes, spheres and cylinders are checked exactly, meshes as their
    bounding box; cones and planes fail the behavior.
    """

    subcategory = "Perception - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        from kinema.motion.planning_scene_messages import (
            COLLISION_OBJECT_TYPE,
        )

        return [
            message_input(
                "collision_object", COLLISION_OBJECT_TYPE, "{collision_object}", "The object to add."
            ),
            input_port("overwrite", bool, False, "Replace an object of the same id instead of failing."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.motion.planning_scene_messages import (
            collision_object_message,
            object_pose_of,
            primitives_of,
        )

        message = read_message(self, "collision_object")
        object_id = str(message.id)
        if not object_id:
            raise port_error(self, "collision_object", "has an empty id", "set the message's id field")
        operation = int(message.operation)
        ops = collision_object_message()
        valid = ", ".join(f"{op} ({getattr(ops, op)})" for op in ("ADD", "REMOVE", "APPEND", "MOVE"))
        try:
            robot_model(self.context, "AddCollisionObject")
            scene = self.context.planning_scene
            if operation not in (ops.ADD, ops.REMOVE, ops.APPEND, ops.MOVE):
                raise port_error(
                    self, "collision_object", f"has operation {operation}", f"valid operations: {valid}"
                )
            if operation == ops.REMOVE:
                scene.remove_world_object(object_id)
                return NodeStatus.SUCCESS
            frame = str(message.header.frame_id)
            frames = None if frame in ("", "world") else current_frame_tree(self)
            if operation == ops.MOVE:
                if len(message.primitives) or len(message.meshes) or len(message.planes):
                    self.logger.publish_warn(
                        f"AddCollisionObject: MOVE of {object_id!r} ignores the shapes in the message"
                    )
                scene.move_world_object(object_id, object_pose_of(message, frames))
                return NodeStatus.SUCCESS
            if operation == ops.APPEND:
                scene.append_to_world_object(
                    object_id, primitives_of(message, frames), object_pose_of(message, frames)
                )
                return NodeStatus.SUCCESS
            scene.add_world_object(
                object_id,
                primitives_of(message, frames),
                replace=bool(self.get_input("overwrite")),
                pose=object_pose_of(message, frames),
            )
        except PortValueError:
            raise
        except KinemaError as error:
            self.logger.publish_failure(f"AddCollisionObject: {error}")
            return NodeStatus.FAILURE
        return NodeStatus.SUCCESS
