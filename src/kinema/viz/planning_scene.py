"""The planning scene's collision objects drawn in meshcat: what objectives added, that plans avoid.

The agent publishes its planning scene (``moveit_msgs/PlanningScene``, latched) on
``/monitored_planning_scene`` whenever it changes; each message is the whole scene, so every message
redraws the layer: translucent green boxes, spheres and cylinders under ``<root>/<object id>/<k>``.
"""

from __future__ import annotations

from typing import Any

import meshcat.geometry as g
import numpy as np

from kinema.transforms import pose_from_message
from kinema.viz import scene_commands as sc
from kinema.viz.geom_shapes import safe_name
from kinema.viz.meshcat_server import Command

BOX, SPHERE, CYLINDER = 1, 2, 3
COLOR = 0x33CC66
OPACITY = 0.45
# meshcat's cylinders run along y; MoveIt's along z.
_Y_TO_Z = np.array([[1.0, 0, 0, 0], [0, 0, -1.0, 0], [0, 1.0, 0, 0], [0, 0, 0, 1.0]])


def _shape(primitive: Any) -> tuple[Any, np.ndarray] | None:
    kind, dims = int(primitive.type), [float(d) for d in primitive.dimensions]
    material = g.MeshPhongMaterial(color=COLOR, opacity=OPACITY, transparent=True)
    if kind == BOX and len(dims) >= 3:
        return g.Mesh(g.Box(dims[:3]), material), np.eye(4)
    if kind == SPHERE and dims:
        return g.Mesh(g.Sphere(dims[0]), material), np.eye(4)
    if kind == CYLINDER and len(dims) >= 2:
        return g.Mesh(g.Cylinder(dims[0], dims[1]), material), _Y_TO_Z
    return None


class PlanningSceneLayer:
    """Turns planning-scene messages into meshcat commands under ``root``."""

    def __init__(self, root: str) -> None:
        self.root = root
        self.object_ids: list[str] = []

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
            world_T_object = world_T_frame @ pose_from_message(obj.pose)
            base = f"{self.root}/{safe_name(str(obj.id), 'object')}"
            self.object_ids.append(str(obj.id))
            for k, (primitive, pose) in enumerate(zip(obj.primitives, obj.primitive_poses, strict=False)):
                shape = _shape(primitive)
                if shape is None:
                    continue
                mesh, correction = shape
                path = f"{base}/{k}"
                commands.append(sc.set_object(path, mesh))
                commands.append(sc.set_transform(path, world_T_object @ pose_from_message(pose) @ correction))
        return commands
