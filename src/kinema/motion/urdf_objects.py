"""A URDF as one rigid collision object of the planning scene (``AddURDF``: a tool, a part, a fixture).

The URDF's links are placed in its root link's frame through its joints, every movable joint at 0 (its
zero position), and each link's ``<collision>`` shapes become primitives of the object: boxes, cylinders
and spheres as they are, a mesh as its bounding box in the mesh's own frame (as a mesh in a
``moveit_msgs/CollisionObject`` is checked). The object is rigid: like MoveIt Pro's
``URDFPlanningSceneCapability``, Kinema does not follow a tool's own joints, and a ``<ros2_control>``
block is not started (the result names both, so the behavior can say so).

Mesh and include URIs (``package://``, ``file://``, relative paths) resolve as the robot's own do
(:func:`kinema.config.robot_files.resolve_uri`); a xacro file is expanded first.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from lxml import etree

from kinema.errors import MotionError
from kinema.motion.planning_scene import CollisionObject
from kinema.transforms import rotation_from_euler

if TYPE_CHECKING:
    from kinema.config.robot_files import PackageIndex

__all__ = ["UrdfObject", "load_urdf_object", "urdf_object_from_text"]


@dataclass(frozen=True, eq=False)  # holds numpy arrays
class UrdfObject:
    """The collision geometry of a URDF, in its root link's frame.

    Attributes:
        name: the ``<robot name>``.
        root_link: the link the shapes are placed relative to (the object's own frame).
        shapes: its collision primitives; each ``world_T_object`` is ``root_T_shape``.
        held_joints: the URDF's movable joints, held at their zero position.
        ros2_control: the URDF carries a ``<ros2_control>`` block (not started).
    """

    name: str
    root_link: str
    shapes: tuple[CollisionObject, ...]
    held_joints: tuple[str, ...] = ()
    ros2_control: bool = False

    def placed(self, world_T_root: np.ndarray) -> list[CollisionObject]:
        """Its shapes placed in the world with the root link at ``world_T_root``."""
        world_T_root = np.asarray(world_T_root, dtype=float)
        return [
            CollisionObject(s.name, s.shape, s.size, world_T_root @ s.world_T_object) for s in self.shapes
        ]


def _numbers(text: str | None, count: int, default: float, what: str) -> list[float]:
    if text is None:
        return [default] * count
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        raise MotionError(f"{what} = {text!r} is not {count} numbers") from None
    if len(values) != count or not all(np.isfinite(values)):
        raise MotionError(f"{what} = {text!r} is not {count} finite numbers")
    return values


def _origin(element: etree._Element | None, what: str) -> np.ndarray:
    """The ``<origin xyz rpy>`` under ``element`` as a 4x4 transform (identity when absent)."""
    origin = element.find("origin") if element is not None else None
    pose = np.eye(4)
    if origin is not None:
        pose[:3, 3] = _numbers(origin.get("xyz"), 3, 0.0, f"{what} origin xyz")
        pose[:3, :3] = rotation_from_euler(_numbers(origin.get("rpy"), 3, 0.0, f"{what} origin rpy"))
    return pose


def _mesh_box(
    mesh: etree._Element, base_dir: Path, index: PackageIndex, what: str
) -> tuple[tuple[float, float, float], np.ndarray]:
    """Half extents and centre (in the mesh's frame) of a ``<mesh>``'s bounding box, scale applied."""
    import trimesh

    from kinema.config.robot_files import check_mesh, resolve_uri
    from kinema.errors import ConfigError

    filename = mesh.get("filename", "")
    if not filename:
        raise MotionError(f"{what}: a <mesh> without a filename")
    try:
        path = check_mesh(resolve_uri(filename, base_dir=base_dir, index=index))
    except ConfigError as error:
        raise MotionError(f"{what}: {error}") from None
    try:
        loaded = trimesh.load(str(path), force="mesh")
    except Exception as error:  # trimesh raises many kinds for an unreadable file
        raise MotionError(f"{what}: cannot read mesh {path}: {error}") from None
    bounds = np.asarray(getattr(loaded, "bounds", None) if loaded is not None else None, dtype=float)
    if bounds.shape != (2, 3) or not np.all(np.isfinite(bounds)):
        raise MotionError(f"{what}: mesh {path} has no vertices")
    scale = np.asarray(_numbers(mesh.get("scale"), 3, 1.0, f"{what} mesh scale"))
    corners = bounds * scale  # a negative scale mirrors: the box is the same, its corners swap
    low, high = corners.min(axis=0), corners.max(axis=0)
    centre = np.eye(4)
    centre[:3, 3] = 0.5 * (low + high)
    half = tuple(max(0.5 * float(h - lo), 1e-4) for lo, h in zip(low, high, strict=True))
    return (half[0], half[1], half[2]), centre


def _shape(
    collision: etree._Element, link_pose: np.ndarray, base_dir: Path, index: PackageIndex, what: str
) -> CollisionObject:
    geometry = collision.find("geometry")
    element = next(iter(geometry), None) if geometry is not None else None
    while element is not None and not isinstance(element.tag, str):
        element = element.getnext()  # skip comments
    if element is None:
        raise MotionError(f"{what}: <collision> without a <geometry>")
    placed = link_pose @ _origin(collision, what)
    tag = element.tag
    if tag == "box":
        size = _numbers(element.get("size"), 3, 0.0, f"{what} box size")
        return CollisionObject("", "box", tuple(0.5 * v for v in size), placed)
    if tag == "cylinder":
        radius = _numbers(element.get("radius"), 1, 0.0, f"{what} cylinder radius")[0]
        length = _numbers(element.get("length"), 1, 0.0, f"{what} cylinder length")[0]
        return CollisionObject("", "cylinder", (radius, 0.5 * length), placed)
    if tag == "sphere":
        radius = _numbers(element.get("radius"), 1, 0.0, f"{what} sphere radius")[0]
        return CollisionObject("", "sphere", (radius,), placed)
    if tag == "capsule":  # not URDF 1.0, but some descriptions use it (as MuJoCo reads it)
        radius = _numbers(element.get("radius"), 1, 0.0, f"{what} capsule radius")[0]
        length = _numbers(element.get("length"), 1, 0.0, f"{what} capsule length")[0]
        return CollisionObject("", "capsule", (radius, 0.5 * length), placed)
    if tag == "mesh":
        half, centre = _mesh_box(element, base_dir, index, what)
        return CollisionObject("", "box", half, placed @ centre)
    raise MotionError(f"{what}: unknown geometry <{tag}>; valid: box, cylinder, sphere, mesh")


def urdf_object_from_text(
    text: str, *, base_dir: str | Path, index: PackageIndex | None = None, source: str = "the URDF"
) -> UrdfObject:
    """The collision object a URDF text describes (see the module docstring).

    Args:
        text: the URDF (xacro already expanded).
        base_dir: the folder relative mesh paths are in (the URDF's).
        index: where ``package://`` URIs are looked up.
        source: how to name the URDF in errors (its file).

    Raises:
        MotionError: not URDF XML, no single root link, a joint naming an unknown link, a bad number, a
            mesh that cannot be found or read, or no ``<collision>`` shape at all.
    """
    from kinema.config.robot_files import PackageIndex

    index = index if index is not None else PackageIndex()
    try:
        root = etree.fromstring(text.encode("utf-8"))
    except etree.XMLSyntaxError as error:
        raise MotionError(f"{source} is not valid XML: {error}") from None
    if root.tag != "robot":
        raise MotionError(f"{source} is not a URDF: its root element is <{root.tag}>, not <robot>")
    links = {link.get("name", ""): link for link in root.findall("link")}
    joints = root.findall("joint")
    children = {j.find("child").get("link", "") for j in joints if j.find("child") is not None}
    roots = [name for name in links if name not in children]
    if len(roots) != 1:
        raise MotionError(
            f"{source} must have one root link (a link that is no joint's child); it has "
            f"{len(roots)}: {', '.join(roots) or 'none'}"
        )
    by_parent: dict[str, list[etree._Element]] = {}
    for joint in joints:
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            raise MotionError(f"{source}: joint {joint.get('name', '')!r} needs a <parent> and a <child>")
        for end in (parent.get("link", ""), child.get("link", "")):
            if end not in links:
                raise MotionError(
                    f"{source}: joint {joint.get('name', '')!r} names link {end!r}, which the URDF lacks"
                )
        by_parent.setdefault(parent.get("link", ""), []).append(joint)
    poses = {roots[0]: np.eye(4)}
    queue = [roots[0]]
    held: list[str] = []
    while queue:
        parent = queue.pop(0)
        for joint in by_parent.get(parent, []):
            child = joint.find("child").get("link", "")  # type: ignore[union-attr]
            if child in poses:
                continue
            name = joint.get("name", "")
            poses[child] = poses[parent] @ _origin(joint, f"{source} joint {name!r}")
            if joint.get("type", "fixed") != "fixed":
                held.append(name)
            queue.append(child)
    shapes: list[CollisionObject] = []
    base = Path(base_dir)
    for name, link in links.items():
        if name not in poses:
            continue
        for k, collision in enumerate(link.findall("collision")):
            shapes.append(
                _shape(collision, poses[name], base, index, f"{source} link {name!r} collision {k}")
            )
    if not shapes:
        raise MotionError(
            f"{source} has no <collision> geometry, so there is nothing for the planner to check; give its "
            "links <collision> elements"
        )
    return UrdfObject(
        root.get("name", ""),
        roots[0],
        tuple(shapes),
        tuple(held),
        root.find("ros2_control") is not None,
    )


def load_urdf_object(path: str | Path, index: PackageIndex | None = None) -> UrdfObject:
    """The collision object of the URDF (or xacro) file ``path``.

    Raises:
        MotionError: as :func:`urdf_object_from_text`, or the file cannot be read or expanded.
    """
    from kinema.config.robot_files import process_xacro
    from kinema.errors import ConfigError

    path = Path(path)
    try:
        text = process_xacro(path, index=index)
    except ConfigError as error:
        raise MotionError(str(error)) from None
    return urdf_object_from_text(text, base_dir=path.parent, index=index, source=str(path))
