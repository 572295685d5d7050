"""Between :class:`kinema.motion.PlanningScene` and ``moveit_msgs`` planning-scene messages, both ways.

The one place that knows how a MoveIt message describes collision geometry; the agent's
``/get_planning_scene`` and ``/monitored_planning_scene``, the planning-scene behaviors and the 3D view all
convert here. Shape types and operations are the message classes' own constants
(``shape_msgs/SolidPrimitive.BOX``, ``moveit_msgs/CollisionObject.ADD``, ...), read from the transport's
type registry.

Messages to the scene: a ``CollisionObject`` becomes primitives placed in the world: its pose (in
``header.frame_id``) times each primitive's pose. Boxes, spheres and cylinders are kept as they are (MoveIt
gives full sizes, :class:`~kinema.motion.CollisionObject` half sizes); a mesh is checked as its bounding
box. Cones and planes are refused with the shapes that work. Orientations are read as
:mod:`kinema.transforms` reads every quaternion (all-zero is the identity).

The scene to messages: its world objects become ``PlanningScene.world.collision_objects`` in ``world``,
identity object pose, each primitive placed in the world (the environment, the cell itself, is drawn and
checked but not listed, as MoveIt lists only objects added to the world). Attached objects become
``robot_state.attached_collision_objects``: each in its link's frame (``header.frame_id`` is the link),
with its touch links, as move_group reports them.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from kinema.errors import ObjectiveError

if TYPE_CHECKING:
    import numpy as np

    from kinema.motion.frames import FrameTree
    from kinema.motion.planning_scene import CollisionObject, PlanningScene

__all__ = [
    "COLLISION_OBJECT_TYPE",
    "PLANNING_SCENE_TYPE",
    "collision_object_dict",
    "collision_object_message",
    "object_pose_of",
    "planning_scene_dict",
    "planning_scene_message",
    "primitive",
    "primitives_of",
    "shape_constants",
]

PLANNING_SCENE_TYPE = "moveit_msgs/msg/PlanningScene"
COLLISION_OBJECT_TYPE = "moveit_msgs/msg/CollisionObject"
SOLID_PRIMITIVE_TYPE = "shape_msgs/msg/SolidPrimitive"
COMPONENTS_TYPE = "moveit_msgs/msg/PlanningSceneComponents"


def _message_class(type_name: str) -> Any:
    from kinema.interfaces import load_interfaces

    return load_interfaces().message_class(type_name)


def shape_constants() -> Any:
    """``shape_msgs/SolidPrimitive``'s class: ``BOX``, ``SPHERE``, ``CYLINDER``, ``CONE`` and the
    dimension indices."""
    return _message_class(SOLID_PRIMITIVE_TYPE)


def collision_object_message() -> Any:
    """``moveit_msgs/CollisionObject``'s class: its operations ``ADD``, ``REMOVE``, ``APPEND``, ``MOVE``."""
    return _message_class(COLLISION_OBJECT_TYPE)


def component_bits() -> Any:
    """``moveit_msgs/PlanningSceneComponents``' class: the bits of a ``/get_planning_scene`` request."""
    return _message_class(COMPONENTS_TYPE)


def everything() -> int:
    """The components this conversion fills: scene settings, robot state and attached objects, world object
    names and geometry."""
    c = component_bits()
    return int(
        c.SCENE_SETTINGS
        | c.ROBOT_STATE
        | c.ROBOT_STATE_ATTACHED_OBJECTS
        | c.WORLD_OBJECT_NAMES
        | c.WORLD_OBJECT_GEOMETRY
    )


def supported_shapes() -> str:
    """The shapes :func:`primitives_of` accepts, for error messages."""
    s = shape_constants()
    return f"BOX ({s.BOX}), SPHERE ({s.SPHERE}), CYLINDER ({s.CYLINDER}) primitives and meshes"


# -- messages to the scene -------------------------------------------------------------------------------


def primitive(shape_type: int, dimensions: list[float], world_T: np.ndarray, what: str) -> CollisionObject:
    """A placed primitive from a ``shape_msgs/SolidPrimitive`` type and dimensions (full sizes).

    Raises:
        ObjectiveError: an unsupported type or the wrong number of dimensions.
    """
    from kinema.motion.planning_scene import CollisionObject

    s = shape_constants()
    needed = {s.BOX: 3, s.SPHERE: 1, s.CYLINDER: 2}
    if shape_type not in needed:
        kind = {s.CONE: f"CONE ({s.CONE})"}.get(shape_type, f"type {shape_type}")
        raise ObjectiveError(
            f"{what} is a {kind}, which Kinema cannot check; supported: {supported_shapes()}"
        )
    if len(dimensions) < needed[shape_type]:
        raise ObjectiveError(
            f"{what} needs {needed[shape_type]} dimensions, got {len(dimensions)}: {list(dimensions)}"
        )
    if shape_type == s.BOX:
        return CollisionObject("", "box", tuple(0.5 * float(d) for d in dimensions[:3]), world_T)
    if shape_type == s.SPHERE:
        return CollisionObject("", "sphere", (float(dimensions[s.SPHERE_RADIUS]),), world_T)
    height, radius = float(dimensions[s.CYLINDER_HEIGHT]), float(dimensions[s.CYLINDER_RADIUS])
    return CollisionObject("", "cylinder", (radius, 0.5 * height), world_T)


def object_pose_of(message: Any, frames: FrameTree | Callable[[str], np.ndarray] | None) -> np.ndarray:
    """The world pose of a ``moveit_msgs/CollisionObject``'s own ``pose`` (given in ``header.frame_id``).

    ``frames`` places ``header.frame_id`` in the world: a frame tree, a function of the frame's name, or
    None for a message in ``world``.

    Raises:
        ObjectiveError: a frame the tree does not know.
    """
    import numpy as np

    from kinema.transforms import pose_from_message

    frame = str(message.header.frame_id)
    if frames is None:
        world_T_frame = np.eye(4)
    elif callable(frames):
        world_T_frame = frames(frame)
    else:
        world_T_frame = frames.world_T(frame)
    return np.asarray(world_T_frame, dtype=float) @ pose_from_message(message.pose)


def primitives_of(
    message: Any, frames: FrameTree | Callable[[str], np.ndarray] | None
) -> list[CollisionObject]:
    """The world-placed primitives of a ``moveit_msgs/CollisionObject`` (``frames`` as in
    :func:`object_pose_of`).

    Raises:
        ObjectiveError: unsupported shapes, mismatched pose lists, or a frame the tree does not know.
    """
    import numpy as np

    from kinema.motion.planning_scene import CollisionObject
    from kinema.transforms import pose_from_message

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
        half = tuple(max(0.5 * float(h - lo), 1e-4) for lo, h in zip(low, high, strict=True))
        shapes.append(CollisionObject("", "box", half, placed))
    if len(message.planes):
        raise ObjectiveError(
            f"collision object {name!r} has planes, which Kinema cannot check; "
            f"supported: {supported_shapes()}"
        )
    return shapes


# -- the scene to messages -------------------------------------------------------------------------------


def _primitive_dict(obj: CollisionObject) -> dict[str, Any]:
    s = shape_constants()
    if obj.shape == "box":
        return {"type": s.BOX, "dimensions": [2 * float(v) for v in obj.size]}
    if obj.shape == "sphere":
        return {"type": s.SPHERE, "dimensions": [float(obj.size[0])]}
    # cylinders, and capsules drawn as the cylinder around them
    extra = float(obj.size[0]) if obj.shape == "capsule" else 0.0
    dimensions = [0.0, 0.0]
    dimensions[s.CYLINDER_HEIGHT] = 2 * float(obj.size[1]) + 2 * extra
    dimensions[s.CYLINDER_RADIUS] = float(obj.size[0])
    return {"type": s.CYLINDER, "dimensions": dimensions}


def collision_object_dict(
    object_id: str, primitives: list[CollisionObject], frame_id: str = "world"
) -> dict[str, Any]:
    """A ``moveit_msgs/CollisionObject`` dict of an object whose primitives are placed in ``frame_id``."""
    import numpy as np

    from kinema.transforms import pose_dict

    return {
        "header": {"frame_id": frame_id},
        "pose": {"orientation": {"w": 1.0}},
        "id": object_id,
        "primitives": [_primitive_dict(p) for p in primitives],
        "primitive_poses": [pose_dict(np.asarray(p.world_T_object, float)) for p in primitives],
        "operation": collision_object_message().ADD,
    }


def planning_scene_message(
    scene: PlanningScene, robot_model_name: str = "", joint_state: Any = None, components: int | None = None
) -> Any:
    """A full ``moveit_msgs/PlanningScene`` (``is_diff`` false) of ``scene``'s world objects (see
    :func:`planning_scene_dict`)."""
    from kinema.transport import from_dict

    return from_dict(
        PLANNING_SCENE_TYPE, planning_scene_dict(scene, robot_model_name, joint_state, components)
    )


def planning_scene_dict(
    scene: PlanningScene, robot_model_name: str = "", joint_state: Any = None, components: int | None = None
) -> dict[str, Any]:
    """A ``moveit_msgs/PlanningScene`` as a dict.

    ``components`` (``moveit_msgs/PlanningSceneComponents`` bits, all of them when None or 0) selects the
    parts, as move_group's ``/get_planning_scene`` does: names only without ``WORLD_OBJECT_GEOMETRY``, no
    robot state without ``ROBOT_STATE``.
    """
    bits = component_bits()
    wanted = int(components or everything())
    data: dict[str, Any] = {"is_diff": False}
    if wanted & bits.SCENE_SETTINGS:
        data["name"] = "kinema"
        data["robot_model_name"] = robot_model_name
    objects = sorted(scene.world_objects().items())
    if wanted & bits.WORLD_OBJECT_GEOMETRY:
        data["world"] = {"collision_objects": [collision_object_dict(oid, prims) for oid, prims in objects]}
    elif wanted & bits.WORLD_OBJECT_NAMES:
        add = collision_object_message().ADD
        data["world"] = {
            "collision_objects": [
                {"header": {"frame_id": "world"}, "id": oid, "operation": add} for oid, _ in objects
            ]
        }
    if wanted & (bits.ROBOT_STATE | bits.ROBOT_STATE_ATTACHED_OBJECTS):
        robot_state: dict[str, Any] = {}
        if joint_state is not None and wanted & bits.ROBOT_STATE:
            robot_state["joint_state"] = {
                "name": [str(n) for n in joint_state.name],
                "position": [float(p) for p in joint_state.position],
            }
        attached = sorted(scene.attached_objects().items())
        if attached:
            robot_state["attached_collision_objects"] = [
                {
                    "link_name": item.link,
                    "object": collision_object_dict(oid, list(item.primitives), item.link),
                    "touch_links": sorted({item.link, *item.touch_links}),
                }
                for oid, item in attached
            ]
        if robot_state:
            data["robot_state"] = robot_state
    return data
