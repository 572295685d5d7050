"""MPCSphereClearance: MPC pose tracking that keeps the robot clear of collision spheres."""

from __future__ import annotations

from typing import TYPE_CHECKING

from kinema.behaviors import PortInfo

from ..messages.ports import message_input
from .control_loop import MpcControlLoop, clearance_ports, common_ports

if TYPE_CHECKING:
    from kinema.motion.mpc import Obstacles

COLLISION_OBJECT = "moveit_msgs/msg/CollisionObject"


class MPCSphereClearance(MpcControlLoop):
    """Tracks ``target_pose`` as MPCPoseTracking does while keeping ``safe_distance`` from spheres.

    The spheres are the primitives of ``collision_sphere_object`` (a ``moveit_msgs/CollisionObject``, e.g.
    from CreateCollisionSpheresAtClosestPoints; boxes and cylinders count as their bounding spheres),
    read again whenever the port's value changes. ``gripper_site_name`` and each frame of ``link_sites``
    keep ``safe_distance`` from every sphere's surface, a constraint of each step's QP (linearised at the
    frames' planned positions): a target inside the clearance is approached only to its edge, and a frame
    that starts inside backs out. The rest (loop, controller, halting, ports) is as in MPCPoseTracking;
    defaults are the values lab_sim's objectives give (MoveIt Pro's own are not public).
    """

    clearance_weight_port = "sphere_clearance"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            *common_ports(horizon=0.1, site_tracking=1.0, warmup=256),
            message_input(
                "collision_sphere_object",
                COLLISION_OBJECT,
                "{collision_object}",
                "The spheres to keep clear of (moveit_msgs/CollisionObject).",
            ),
            *clearance_ports("sphere_clearance", 1.0, ""),
        ]

    def __init__(self, name: str, config: object = None) -> None:
        super().__init__(name, config)
        self._source: object = None
        self._obstacles: Obstacles | None = None

    def obstacles(self) -> Obstacles | None:
        message = self.get_input("collision_sphere_object")
        if message is not self._source:
            self._obstacles = self._spheres(message)
            self._source = message
        return self._obstacles

    def _spheres(self, message: object) -> Obstacles:
        import numpy as np

        from kinema.motion.mpc import Obstacles
        from kinema.motion.planning_scene_messages import primitives_of

        from ..poses.frame_tree import current_frame_tree

        if getattr(message, "primitives", None) is None:
            raise self._bad_object(message)
        frame = str(message.header.frame_id)  # type: ignore[attr-defined]
        tree = None if frame in ("", "world") else current_frame_tree(self)
        shapes = primitives_of(message, tree)
        centres = [np.asarray(shape.world_T_object, dtype=float)[:3, 3] for shape in shapes]
        radii = [
            float(shape.size[0]) if shape.shape == "sphere" else float(np.linalg.norm(shape.size))
            for shape in shapes
        ]
        return Obstacles.from_spheres(np.reshape(centres, (-1, 3)), np.asarray(radii, dtype=float))

    @staticmethod
    def _bad_object(message: object) -> Exception:
        from kinema.errors import ObjectiveError

        return ObjectiveError(
            "collision_sphere_object must be a moveit_msgs/CollisionObject (e.g. from "
            f"CreateCollisionSpheresAtClosestPoints), got {type(message).__name__}"
        )
