"""The planning scene's collision objects drawn in meshcat: what objectives added, that plans avoid.

The agent publishes its planning scene (``moveit_msgs/PlanningScene``, latched) on
``/monitored_planning_scene`` whenever it changes; each message is the whole scene, so every message
redraws the layer: translucent green boxes, spheres and cylinders under ``<root>/<object id>/<k>``,
read by :mod:`kinema.motion.planning_scene_messages` as the planner reads them (a primitive the planner
cannot check is not drawn). Objects attached to the robot (``robot_state.attached_collision_objects``,
in their link's frame) are drawn under ``<root>/attached/<object id>``, a node that :meth:`follow` keeps
at its link's pose as the robot moves.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import meshcat.geometry as g
import numpy as np

from kinema.errors import ObjectiveError
from kinema.motion.planning_scene_messages import object_pose_of, primitive
from kinema.transforms import TransformError, pose_from_message
from kinema.viz import scene_commands as sc
from kinema.viz.geom_shapes import safe_name
from kinema.viz.meshcat_server import Command

if TYPE_CHECKING:
    from kinema.motion.planning_scene import CollisionObject

COLOR = 0x33CC66
OPACITY = 0.45
# meshcat's cylinders run along y; MoveIt's along z.
_Y_TO_Z = np.array([[1.0, 0, 0, 0], [0, 0, -1.0, 0], [0, 1.0, 0, 0], [0, 0, 0, 1.0]])


def _shape(obj: CollisionObject) -> tuple[Any, np.ndarray]:
    """The meshcat mesh of a placed primitive and the turn from meshcat's axes to the primitive's."""
    material = g.MeshPhongMaterial(color=COLOR, opacity=OPACITY, transparent=True)
    if obj.shape == "box":
        return g.Mesh(g.Box([2 * s for s in obj.size]), material), np.eye(4)
    if obj.shape == "sphere":
        return g.Mesh(g.Sphere(obj.size[0]), material), np.eye(4)
    radius, half_length = obj.size
    return g.Mesh(g.Cylinder(2 * half_length, radius), material), _Y_TO_Z


class PlanningSceneLayer:
    """Turns planning-scene messages into meshcat commands under ``root``."""

    def __init__(self, root: str) -> None:
        self.root = root
        self.object_ids: list[str] = []
        # attached object id -> (its meshcat node, its link); and the link poses last sent
        self.attached: dict[str, tuple[str, str]] = {}
        self._sent: dict[str, np.ndarray] = {}

    def update(self, scene: Any, frame_pose: Any = None) -> list[Command]:
        """Commands drawing the collision objects of ``scene`` (replacing what was drawn before).

        Args:
            scene: a ``moveit_msgs/PlanningScene``.
            frame_pose: ``frame_id -> 4x4 or None``, for objects not given in ``world``.
        """
        commands: list[Command] = [sc.delete(self.root)]
        self.object_ids = []
        for obj in scene.world.collision_objects:
            frame = str(obj.header.frame_id)
            world_T_frame = np.eye(4)
            if frame not in ("", "world") and frame_pose is not None:
                world_T_frame = frame_pose(frame)
                if world_T_frame is None:
                    continue
            try:
                world_T_object = world_T_frame @ object_pose_of(obj, None)
            except TransformError:
                continue  # a pose with a NaN in it: nothing to draw where the planner cannot place it
            base = f"{self.root}/{safe_name(str(obj.id), 'object')}"
            self.object_ids.append(str(obj.id))
            for k, (shape, pose) in enumerate(zip(obj.primitives, obj.primitive_poses, strict=False)):
                dimensions = [float(d) for d in shape.dimensions]
                try:
                    placed = primitive(
                        int(shape.type), dimensions, world_T_object @ pose_from_message(pose), ""
                    )
                except (ObjectiveError, TransformError):
                    continue  # a shape the planner cannot check (a cone), or a primitive pose with a NaN
                mesh, correction = _shape(placed)
                path = f"{base}/{k}"
                commands.append(sc.set_object(path, mesh))
                commands.append(sc.set_transform(path, placed.world_T_object @ correction))
        self.attached = {}
        self._sent = {}
        robot_state = getattr(scene, "robot_state", None)
        for item in getattr(robot_state, "attached_collision_objects", []) or []:
            obj = item.object
            base = f"{self.root}/attached/{safe_name(str(obj.id), 'object')}"
            self.attached[str(obj.id)] = (base, str(item.link_name))
            for k, (shape, pose) in enumerate(zip(obj.primitives, obj.primitive_poses, strict=False)):
                try:
                    placed = primitive(
                        int(shape.type), [float(d) for d in shape.dimensions], pose_from_message(pose), ""
                    )
                except (ObjectiveError, TransformError):
                    continue
                mesh, correction = _shape(placed)
                commands.append(sc.set_object(f"{base}/{k}", mesh))
                commands.append(sc.set_transform(f"{base}/{k}", placed.world_T_object @ correction))
        if frame_pose is not None:
            commands += self.follow(frame_pose)
        return commands

    def follow(self, frame_pose: Any) -> list[Command]:
        """Commands moving each attached object to its link's pose, for the links that moved.

        Args:
            frame_pose: ``link -> world_T_link (4x4) or None``; an object whose link is unknown to the
                view is left where it was last placed.
        """
        commands: list[Command] = []
        for base, link in self.attached.values():
            pose = frame_pose(link)
            if pose is None:
                continue
            last = self._sent.get(base)
            if last is None or np.abs(pose - last).max() > 1e-5:
                self._sent[base] = np.array(pose, dtype=float)
                commands.append(sc.set_transform(base, pose))
        return commands
