"""AddCollisionBox: put a box into the planning scene."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import KinemaError

from ..messages.conversions import POSE_STAMPED_TYPE, pose_matrix
from ..messages.ports import fails_on_bad_input, message_input, port_error, read_floats, read_message
from ..motion.planning_resources import robot_model
from ..poses.frame_tree import current_frame_tree


class AddCollisionBox(SyncBehavior):
    """Adds a box of ``dimensions`` (x;y;z, full sizes in metres) centred at ``pose`` under ``object_id``.

    The pose may be in any frame of the cell (``grasp_link`` puts the box in front of the gripper as it
    is now); the box stays where it was placed in the world. Every later plan avoids it and ``kinema
    view`` draws it. With ``overwrite`` false an existing object of the same id fails the behavior.
    """

    subcategory = "Perception - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("object_id", str, "box", "Id of the box in the planning scene."),
            input_port(
                "dimensions",
                list[float],
                "0.1;0.1;0.1",
                "Size x;y;z (m) along the pose's axes (default not public; a 10 cm cube).",
            ),
            message_input("pose", POSE_STAMPED_TYPE, "{pose}", "Where the box's centre is."),
            input_port("overwrite", bool, False, "Replace an object of the same id instead of failing."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        from kinema.motion import CollisionObject

        object_id = str(self.get_input("object_id")).strip()
        if not object_id:
            raise port_error(self, "object_id", "is empty", "give the box an id (e.g. 'table')")
        size = read_floats(self, "dimensions", 3, "x;y;z (m)")
        if not all(np.isfinite(v) and v > 0 for v in size):
            raise port_error(self, "dimensions", f"= {size}", "each size must be > 0 m")
        frame, matrix = pose_matrix(read_message(self, "pose"), "pose")
        try:
            robot_model(self.context, "AddCollisionBox")
            world_T_box = (
                matrix
                if frame in ("", "world")
                else current_frame_tree(self).transform(matrix, frame, "world")
            )
            box = CollisionObject(object_id, "box", tuple(0.5 * v for v in size), world_T_box)
            self.context.planning_scene.add_world_object(
                object_id, [box], replace=bool(self.get_input("overwrite"))
            )
        except KinemaError as error:
            self.logger.publish_failure(f"AddCollisionBox: {error}")
            return NodeStatus.FAILURE
        return NodeStatus.SUCCESS
