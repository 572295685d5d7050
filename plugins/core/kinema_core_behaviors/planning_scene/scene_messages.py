"""Between ``moveit_msgs`` planning-scene messages and Kinema's :class:`kinema.motion.PlanningScene`.

A ``CollisionObject`` message becomes a world object of primitives placed in the world: its pose (in
``header.frame_id``) times each primitive's pose. Boxes, spheres and cylinders are kept as they are;
a mesh is checked as its bounding box. Cones and planes are refused with the shapes that work. The
other way, the scene's world objects become ``PlanningScene.world.collision_objects`` in ``world``
(the environment, the cell itself, is drawn and checked but not listed, as MoveIt lists only objects
added to the world).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from kinema.errors import ObjectiveError
from kinema.runtime.planning_scene_service import collision_object_dict, planning_scene_message
from kinema.transforms import pose_from_message
from kinema.viz.topics import PLANNING_SCENE_TOPIC, PLANNING_SCENE_TYPE

if TYPE_CHECKING:
    from kinema.motion import CollisionObject, FrameTree

__all__ = [
    "PLANNING_SCENE_TOPIC",
    "PLANNING_SCENE_TYPE",
    "collision_object_dict",
    "object_pose_of",
    "planning_scene_message",
    "primitives_of",
]

COLLISION_OBJECT_TYPE = "moveit_msgs/msg/CollisionObject"
BOX, SPHERE, CYLINDER, CONE = 1, 2, 3, 4
ADD, REMOVE, APPEND, MOVE = 0, 1, 2, 3
_SUPPORTED = "BOX (1), SPHERE (2), CYLINDER (3) primitives and meshes"


def primitive(shape_type: int, dimensions: list[float], world_T: np.ndarray, what: str) -> CollisionObject:
    """A placed primitive from a ``shape_msgs/SolidPrimitive`` type and dimensions (full sizes).

    Raises:
        ObjectiveError: an unsupported type or the wrong number of dimensions.
    """
    from kinema.motion import CollisionObject

    needed = {BOX: 3, SPHERE: 1, CYLINDER: 2}
    if shape_type not in needed:
        kind = {CONE: "CONE (4)"}.get(shape_type, f"type {shape_type}")
        raise ObjectiveError(f"{what} is a {kind}, which Kinema cannot check; supported: {_SUPPORTED}")
    if len(dimensions) < needed[shape_type]:
        raise ObjectiveError(
            f"{what} needs {needed[shape_type]} dimensions, got {len(dimensions)}: {list(dimensions)}"
        )
    if shape_type == BOX:
        return CollisionObject("", "box", tuple(0.5 * float(d) for d in dimensions[:3]), world_T)
    if shape_type == SPHERE:
        return CollisionObject("", "sphere", (float(dimensions[0]),), world_T)
    height, radius = float(dimensions[0]), float(dimensions[1])
    return CollisionObject("", "cylinder", (radius, 0.5 * height), world_T)


def object_pose_of(message: Any, frames: FrameTree | None) -> np.ndarray:
    """The world pose of a ``moveit_msgs/CollisionObject``'s own ``pose`` (given in ``header.frame_id``).

    Raises:
        ObjectiveError: a frame the tree does not know.
    """
    frame = str(message.header.frame_id)
    world_T_frame = np.eye(4) if frames is None else frames.world_T(frame)
    return world_T_frame @ pose_from_message(message.pose)


def primitives_of(message: Any, frames: FrameTree | None) -> list[CollisionObject]:
    """The world-placed primitives of a ``moveit_msgs/CollisionObject``.

    Raises:
        ObjectiveError: unsupported shapes, mismatched pose lists, or a frame the tree does not know.
    """
    world_T_object = object_pose_of(message, frames)
    shapes: list[CollisionObject] = []
    name = str(message.id)
    if len(message.primitive_poses) != len(message.primitives):
        raise ObjectiveError(
            f"collision object {name!r} has {len(message.primitives)} primitives but "
            f"{len(message.primitive_poses)} primitive_poses"
        )
    for k, (shape, pose) in enumerate(zip(message.primitives, message.primitive_poses, strict=True)):
        placed = world_T_object @ pose_from_message(pose)
        shapes.append(
            primitive(int(shape.type), [float(d) for d in shape.dimensions], placed, f"{name} primitive {k}")
        )
    if len(message.mesh_poses) != len(message.meshes):
        raise ObjectiveError(
            f"collision object {name!r} has {len(message.meshes)} meshes but "
            f"{len(message.mesh_poses)} mesh_poses"
        )
    for k, (mesh, pose) in enumerate(zip(message.meshes, message.mesh_poses, strict=True)):
        vertices = np.array([[v.x, v.y, v.z] for v in mesh.vertices], dtype=float)
        if len(vertices) == 0:
            raise ObjectiveError(f"collision object {name!r} mesh {k} has no vertices")
        low, high = vertices.min(axis=0), vertices.max(axis=0)
        centre = np.eye(4)
        centre[:3, 3] = 0.5 * (low + high)
        placed = world_T_object @ pose_from_message(pose) @ centre
        from kinema.motion import CollisionObject

        half = tuple(max(0.5 * float(h - lo), 1e-4) for lo, h in zip(low, high, strict=True))
        shapes.append(CollisionObject("", "box", half, placed))
    if len(message.planes):
        raise ObjectiveError(
            f"collision object {name!r} has planes, which Kinema cannot check; supported: {_SUPPORTED}"
        )
    return shapes
