"""``visualization_msgs`` markers (what VisualizePose and other behaviors publish) drawn with meshcat.

A marker is keyed by ``(ns, id)`` as in RViz: a new one with the same key replaces the old one,
``DELETE`` removes it, ``DELETEALL`` removes all. A marker with a lifetime > 0 disappears that many
seconds after it arrived (wall time of the viewer); lifetime 0 keeps it until replaced or deleted.

Shapes: ARROW (by two points, or by pose and scale), CUBE, SPHERE, CYLINDER, LINE_STRIP, LINE_LIST,
CUBE_LIST / SPHERE_LIST / POINTS (as points), TRIANGLE_LIST, and MESH_RESOURCE for ``file://`` URIs and
absolute paths of STL, OBJ and DAE files (what VisualizeMesh sends; the file must be on the viewer's
machine). TEXT_VIEW_FACING and ``package://`` mesh resources are not drawn (meshcat 0.3.2 has no text
sprites; the viewer does not resolve packages).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import meshcat.geometry as g
import numpy as np

from kinema.transforms import TransformError, pose_from_message
from kinema.viz import scene_commands as sc
from kinema.viz.geom_shapes import rgb_to_int, safe_name
from kinema.viz.meshcat_server import Command

log = logging.getLogger("kinema.viz")

ARROW, CUBE, SPHERE, CYLINDER, LINE_STRIP, LINE_LIST, CUBE_LIST, SPHERE_LIST, POINTS = range(9)
TEXT_VIEW_FACING, MESH_RESOURCE, TRIANGLE_LIST = 9, 10, 11
ADD, DELETE, DELETEALL = 0, 2, 3
# An arrow's head takes this share of its length when the marker does not give one.
HEAD_SHARE = 0.23


@dataclass(frozen=True)
class MarkerShape:
    """One meshcat object of a marker: ``obj`` placed at the 4x4 ``transform`` in the world."""

    name: str
    obj: Any
    transform: np.ndarray


def _seconds(duration: Any) -> float:
    return float(duration.sec) + float(duration.nanosec) * 1e-9


def _point(p: Any) -> np.ndarray:
    return np.array([float(p.x), float(p.y), float(p.z)])


def _material(color: Any) -> Any:
    alpha = float(color.a) if float(color.a) > 0 else 1.0  # RViz warns on alpha 0; draw it opaque
    return g.MeshPhongMaterial(
        color=rgb_to_int(color.r, color.g, color.b), opacity=alpha, transparent=bool(alpha < 1.0)
    )


def _along(start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """A frame at ``start`` whose +Y (meshcat's cylinder axis) points to ``end``."""
    axis = end - start
    length = float(np.linalg.norm(axis))
    y = axis / length if length > 0 else np.array([0.0, 1.0, 0.0])
    helper = np.array([1.0, 0.0, 0.0]) if abs(y[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    x = np.cross(y, helper)
    x /= np.linalg.norm(x)
    z = np.cross(x, y)
    matrix = np.eye(4)
    matrix[:3, 0], matrix[:3, 1], matrix[:3, 2] = x, y, z
    matrix[:3, 3] = start
    return matrix


def arrow_shapes(
    start: np.ndarray,
    end: np.ndarray,
    shaft_diameter: float,
    head_diameter: float,
    head_length: float,
    color: Any,
) -> list[MarkerShape]:
    """A shaft (cylinder) and a head (cone) from ``start`` to ``end``."""
    length = float(np.linalg.norm(end - start))
    if length <= 0:
        return []
    head = min(head_length if head_length > 0 else HEAD_SHARE * length, length)
    shaft = length - head
    frame = _along(start, end)
    material = _material(color)
    shapes = []
    if shaft > 0:
        offset = np.eye(4)
        offset[1, 3] = shaft / 2
        shapes.append(
            MarkerShape("shaft", g.Mesh(g.Cylinder(shaft, shaft_diameter / 2), material), frame @ offset)
        )
    offset = np.eye(4)
    offset[1, 3] = shaft + head / 2
    cone = g.Cylinder(head, radiusTop=0.0, radiusBottom=head_diameter / 2)
    shapes.append(MarkerShape("head", g.Mesh(cone, material), frame @ offset))
    return shapes


def marker_shapes(marker: Any, frame: np.ndarray) -> list[MarkerShape]:
    """The meshcat objects drawing ``marker`` (``visualization_msgs/Marker``); its frame is at ``frame``."""
    kind = int(marker.type)
    pose = frame @ pose_from_message(marker.pose)
    scale = marker.scale
    sx, sy, sz = float(scale.x), float(scale.y), float(scale.z)
    color = marker.color
    points = [_point(p) for p in marker.points]
    if kind == ARROW:
        if len(points) >= 2:
            start = (pose @ np.append(points[0], 1.0))[:3]
            end = (pose @ np.append(points[1], 1.0))[:3]
            return arrow_shapes(start, end, sx, sy, sz, color)
        start = pose[:3, 3]
        end = start + pose[:3, 0] * sx
        return arrow_shapes(start, end, sy, sz, HEAD_SHARE * sx, color)
    if kind == CUBE:
        return [MarkerShape("cube", g.Mesh(g.Box([sx, sy, sz]), _material(color)), pose)]
    if kind == SPHERE:
        return [MarkerShape("sphere", g.Mesh(g.Ellipsoid([sx / 2, sy / 2, sz / 2]), _material(color)), pose)]
    if kind == CYLINDER:
        turn = np.array([[1.0, 0, 0, 0], [0, 0, -1.0, 0], [0, 1.0, 0, 0], [0, 0, 0, 1.0]])
        stretch = np.diag([sx / sy if sy else 1.0, 1.0, 1.0, 1.0])
        cylinder = g.Mesh(g.Cylinder(sz, sy / 2), _material(color))
        return [MarkerShape("cylinder", cylinder, pose @ turn @ stretch)]
    if kind == MESH_RESOURCE:
        return _mesh_shapes(marker, pose, sx, sy, sz)
    if kind in (LINE_STRIP, LINE_LIST, CUBE_LIST, SPHERE_LIST, POINTS, TRIANGLE_LIST):
        if not points:
            return []
        positions = np.asarray(points, dtype=np.float32)
        colors = _point_colors(marker, len(points))
        if kind == TRIANGLE_LIST:
            count = len(points) // 3 * 3
            if count == 0:
                return []
            faces = np.arange(count).reshape(-1, 3)
            geometry = g.TriangularMeshGeometry(positions[:count], faces)
            return [MarkerShape("triangles", g.Mesh(geometry, _material(color)), pose)]
        geometry = g.PointsGeometry(positions.T, color=colors.T)
        if kind in (LINE_STRIP, LINE_LIST):
            material = g.LineBasicMaterial(vertexColors=True, linewidth=max(sx, 0.001))
            line = g.Line(geometry, material) if kind == LINE_STRIP else g.LineSegments(geometry, material)
            return [MarkerShape("line", line, pose)]
        size = max(sx, 0.001)
        return [MarkerShape("points", g.Points(geometry, g.PointsMaterial(size=size)), pose)]
    return []


_MESH_LOADERS = {".stl": "StlMeshGeometry", ".obj": "ObjMeshGeometry", ".dae": "DaeMeshGeometry"}


def mesh_resource_geometry(uri: str) -> Any | None:
    """The meshcat geometry of a ``file://`` (or absolute path) STL/OBJ/DAE mesh, or None."""
    from pathlib import Path
    from urllib.parse import unquote, urlparse

    parsed = urlparse(uri)
    if parsed.scheme not in ("", "file"):
        return None
    path = Path(unquote(parsed.path))
    loader = _MESH_LOADERS.get(path.suffix.lower())
    if loader is None or not path.is_file():
        return None
    try:
        return getattr(g, loader).from_file(str(path))
    except (OSError, ValueError) as error:
        log.info("mesh %s cannot be drawn: %s", path, error)
        return None


def _mesh_shapes(marker: Any, pose: np.ndarray, sx: float, sy: float, sz: float) -> list[MarkerShape]:
    geometry = mesh_resource_geometry(str(marker.mesh_resource))
    if geometry is None:
        return []
    scale = np.diag([sx or 1.0, sy or 1.0, sz or 1.0, 1.0])
    return [MarkerShape("mesh", g.Mesh(geometry, _material(marker.color)), pose @ scale)]


def _point_colors(marker: Any, count: int) -> np.ndarray:
    if len(marker.colors) == count:
        return np.array([[float(c.r), float(c.g), float(c.b)] for c in marker.colors], dtype=np.float32)
    c = marker.color
    return np.tile(np.array([float(c.r), float(c.g), float(c.b)], dtype=np.float32), (count, 1))


class MarkerBoard:
    """The markers on screen, their meshcat paths and their expiry times (thread-safe).

    Args:
        root: the meshcat path markers are drawn under.
        clock: monotonic seconds (tests pass a fake).
    """

    def __init__(self, root: str = "/kinema/markers", clock: Callable[[], float] = time.monotonic) -> None:
        self.root = root
        self._now = clock
        self._expiry: dict[tuple[str, int], float | None] = {}
        self._lock = threading.Lock()
        self._unsupported_warned: set[int] = set()

    def path(self, ns: str, marker_id: int) -> str:
        """The meshcat path of marker ``(ns, id)``."""
        return f"{self.root}/{safe_name(ns, 'default')}/{marker_id}"

    @property
    def keys(self) -> list[tuple[str, int]]:
        """The ``(ns, id)`` of every marker shown."""
        with self._lock:
            return sorted(self._expiry)

    def update(self, marker: Any, frame: np.ndarray) -> list[Command]:
        """Commands applying ``marker`` (add, replace, delete, delete all); ``frame``: its frame's pose."""
        action = int(marker.action)
        ns, marker_id = str(marker.ns), int(marker.id)
        if action == DELETEALL:
            return self.clear()
        with self._lock:
            known = self._expiry.pop((ns, marker_id), "absent") != "absent"
        commands = [sc.delete(self.path(ns, marker_id))] if known else []
        if action == DELETE:
            return commands
        try:
            shapes = marker_shapes(marker, frame)
        except TransformError as error:
            log.warning("marker %s/%d is not drawn: its pose: %s", ns, marker_id, error)
            return commands
        if not shapes:
            kind = int(marker.type)
            if kind not in self._unsupported_warned and kind in (TEXT_VIEW_FACING, MESH_RESOURCE):
                self._unsupported_warned.add(kind)
                log.info(
                    "marker type %d (%s) is not drawn by the meshcat view",
                    kind,
                    "text" if kind == TEXT_VIEW_FACING else "mesh resource",
                )
            return commands
        lifetime = _seconds(marker.lifetime)
        with self._lock:
            self._expiry[(ns, marker_id)] = self._now() + lifetime if lifetime > 0 else None
        base = self.path(ns, marker_id)
        for shape in shapes:
            commands.append(sc.set_object(f"{base}/{shape.name}", shape.obj))
            commands.append(sc.set_transform(f"{base}/{shape.name}", shape.transform))
        return commands

    def expire(self) -> list[Command]:
        """Commands removing the markers whose lifetime is over."""
        now = self._now()
        with self._lock:
            gone = [key for key, until in self._expiry.items() if until is not None and until <= now]
            for key in gone:
                del self._expiry[key]
        return [sc.delete(self.path(*key)) for key in gone]

    def clear(self) -> list[Command]:
        """Commands removing every marker."""
        with self._lock:
            self._expiry.clear()
        return [sc.delete(self.root)]
