"""MuJoCo geoms as meshcat objects: shapes, sizes, colors and textures, read from a compiled ``MjModel``.

Each visible geom becomes a :class:`GeomVisual`: its pose in its body's frame plus one or more
:class:`ShapePart` s (a capsule is a cylinder and two spheres; everything else is one part). meshcat 0.3.2
draws cylinders along +Y (three.js), MuJoCo along +Z, so cylinder parts carry a +90° turn about X.

Which geoms show follows MuJoCo's own viewer: groups 0-2 (3-5 are hidden by default there), alpha > 0.
The color is the geom's rgba, or its material's when the geom keeps MuJoCo's default rgba (MuJoCo's rule:
an explicit geom rgba overrides the material).
"""

from __future__ import annotations

import io
import logging
from dataclasses import dataclass, field
from typing import Any

import meshcat.geometry as g
import numpy as np

from kinema.transforms import pose_matrix, quaternion_from_wxyz

log = logging.getLogger("kinema.viz")

# MuJoCo's compiled default geom rgba: a geom with this color and a material shows the material's color.
DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)
# Geom groups MuJoCo's viewer shows by default.
VISIBLE_GROUPS = (0, 1, 2)
# An infinite MuJoCo plane (size 0) is drawn this many model extents wide.
INFINITE_PLANE_EXTENTS = 5.0
# Thickness of the box drawn for a plane (m); its top face is the plane.
PLANE_THICKNESS = 0.002
# three.js texture wrap mode RepeatWrapping.
_REPEAT_WRAPPING = 1000

# mjtGeom values (stable across MuJoCo 2.x-4.x).
PLANE, HFIELD, SPHERE, CAPSULE, ELLIPSOID, CYLINDER, BOX, MESH, SDF = range(9)
KIND_NAMES = {
    PLANE: "plane",
    HFIELD: "hfield",
    SPHERE: "sphere",
    CAPSULE: "capsule",
    ELLIPSOID: "ellipsoid",
    CYLINDER: "cylinder",
    BOX: "box",
    MESH: "mesh",
    SDF: "sdf",
}

_Y_TO_Z = np.array([[1.0, 0, 0, 0], [0, 0, -1.0, 0], [0, 1.0, 0, 0], [0, 0, 0, 1.0]])


@dataclass(frozen=True)
class ShapePart:
    """One meshcat object of a geom: ``geometry`` placed at ``transform`` (4x4) in the geom's frame."""

    name: str
    geometry: Any
    transform: np.ndarray = field(default_factory=lambda: np.eye(4))


@dataclass(frozen=True)
class GeomVisual:
    """A visible geom: where it sits on its body, what it looks like.

    Attributes:
        geom_id: index in the model.
        name: the geom's name (``geom<id>`` when unnamed), safe as a meshcat path element.
        kind: MuJoCo's geom type in lower case (``box``, ``capsule``, ...).
        body_id: the body it is attached to.
        transform: the geom's pose in the body frame, 4x4.
        rgba: the color drawn, 0-1.
        parts: the meshcat geometries that draw it.
        texture_png: a PNG of the material's 2D texture, if it has one.
        texture_repeat: how often the texture repeats across a face.
    """

    geom_id: int
    name: str
    kind: str
    body_id: int
    transform: np.ndarray
    rgba: tuple[float, float, float, float]
    parts: tuple[ShapePart, ...]
    texture_png: bytes | None = None
    texture_repeat: tuple[float, float] = (1.0, 1.0)

    def material(self) -> Any:
        """The meshcat material (Phong, with transparency for alpha < 1 and the texture if any)."""
        r, g_, b, a = self.rgba
        options: dict[str, Any] = {}
        if self.texture_png is not None:
            options["map"] = g.ImageTexture(
                g.PngImage(self.texture_png),
                wrap=[_REPEAT_WRAPPING, _REPEAT_WRAPPING],
                repeat=[float(v) for v in self.texture_repeat],
            )
        return g.MeshPhongMaterial(
            color=rgb_to_int(r, g_, b),
            opacity=float(a),
            transparent=bool(a < 1.0),
            **options,
        )


def rgb_to_int(r: float, g_: float, b: float) -> int:
    """0xRRGGBB from 0-1 channels (clipped)."""
    channels = [round(min(max(float(c), 0.0), 1.0) * 255) for c in (r, g_, b)]
    return (channels[0] << 16) | (channels[1] << 8) | channels[2]


def safe_name(name: str, fallback: str) -> str:
    """A meshcat path element: no ``/`` (meshcat splits paths on it), never empty."""
    cleaned = name.replace("/", "_").strip()
    return cleaned or fallback


def geom_rgba(model: Any, geom_id: int) -> tuple[float, float, float, float]:
    """The color MuJoCo draws geom ``geom_id`` with (see the module docstring)."""
    rgba = np.asarray(model.geom_rgba[geom_id], dtype=float)
    material = int(model.geom_matid[geom_id])
    if material >= 0 and np.allclose(rgba, DEFAULT_RGBA, atol=1e-6):
        rgba = np.asarray(model.mat_rgba[material], dtype=float)
    r, g_, b, a = (float(v) for v in rgba)
    return (r, g_, b, a)


def geom_visuals(model: Any, *, groups: tuple[int, ...] = VISIBLE_GROUPS) -> list[GeomVisual]:
    """Every geom of ``model`` MuJoCo's viewer would draw, as meshcat shapes (see the module docstring)."""
    visuals = []
    for geom_id in range(model.ngeom):
        if int(model.geom_group[geom_id]) not in groups:
            continue
        rgba = geom_rgba(model, geom_id)
        if rgba[3] <= 0.0:
            continue
        visual = geom_visual(model, geom_id, rgba)
        if visual is not None:
            visuals.append(visual)
    return visuals


def geom_visual(
    model: Any, geom_id: int, rgba: tuple[float, float, float, float] | None = None
) -> GeomVisual | None:
    """Geom ``geom_id`` as a :class:`GeomVisual` (None for types meshcat cannot draw: SDF)."""
    kind = int(model.geom_type[geom_id])
    size = np.asarray(model.geom_size[geom_id], dtype=float)
    parts = _parts(model, geom_id, kind, size)
    if parts is None:
        log.warning(
            "geom %d (%s) is not drawn: meshcat cannot draw MuJoCo %s geoms",
            geom_id,
            model.geom(geom_id).name,
            KIND_NAMES.get(kind, str(kind)),
        )
        return None
    png, repeat = _texture(model, geom_id) if kind in (PLANE, BOX) else (None, (1.0, 1.0))
    if png is not None and bool(model.mat_texuniform[int(model.geom_matid[geom_id])]):
        # A uniform texture repeats per metre (MuJoCo's texuniform), not per face.
        width, depth = (2 * float(v) for v in size[:2])
        repeat = (
            repeat[0] * width if width > 0 else repeat[0],
            repeat[1] * depth if depth > 0 else repeat[1],
        )
    name = safe_name(model.geom(geom_id).name, f"geom{geom_id}")
    return GeomVisual(
        geom_id=geom_id,
        name=name,
        kind=KIND_NAMES[kind],
        body_id=int(model.geom_bodyid[geom_id]),
        transform=pose_matrix(model.geom_pos[geom_id], quaternion_from_wxyz(model.geom_quat[geom_id])),
        rgba=rgba if rgba is not None else geom_rgba(model, geom_id),
        parts=tuple(parts),
        texture_png=png,
        texture_repeat=repeat,
    )


def _translation(x: float, y: float, z: float) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, 3] = (x, y, z)
    return matrix


def _parts(model: Any, geom_id: int, kind: int, size: np.ndarray) -> list[ShapePart] | None:
    if kind == SPHERE:
        return [ShapePart("sphere", g.Sphere(float(size[0])))]
    if kind == ELLIPSOID:
        return [ShapePart("ellipsoid", g.Ellipsoid([float(v) for v in size[:3]]))]
    if kind == BOX:
        return [ShapePart("box", g.Box([2 * float(v) for v in size[:3]]))]
    if kind == CYLINDER:
        return [ShapePart("cylinder", g.Cylinder(2 * float(size[1]), float(size[0])), _Y_TO_Z)]
    if kind == CAPSULE:
        radius, half = float(size[0]), float(size[1])
        return [
            ShapePart("cylinder", g.Cylinder(2 * half, radius), _Y_TO_Z),
            ShapePart("cap_top", g.Sphere(radius), _translation(0, 0, half)),
            ShapePart("cap_bottom", g.Sphere(radius), _translation(0, 0, -half)),
        ]
    if kind == PLANE:
        extent = INFINITE_PLANE_EXTENTS * float(model.stat.extent)
        width = 2 * float(size[0]) if size[0] > 0 else extent
        depth = 2 * float(size[1]) if size[1] > 0 else extent
        return [
            ShapePart(
                "plane", g.Box([width, depth, PLANE_THICKNESS]), _translation(0, 0, -PLANE_THICKNESS / 2)
            )
        ]
    if kind == MESH:
        mesh = int(model.geom_dataid[geom_id])
        return [ShapePart("mesh", mesh_geometry(model, mesh))]
    if kind == HFIELD:
        field_id = int(model.geom_dataid[geom_id])
        return [ShapePart("hfield", hfield_geometry(model, field_id))]
    return None


class FlatMeshGeometry(g.Geometry):
    """Triangles with per-corner normals (three.js BufferGeometry); meshcat's own mesh has no normals."""

    def __init__(self, positions: np.ndarray, normals: np.ndarray) -> None:
        super().__init__()
        self.positions = np.ascontiguousarray(positions, dtype=np.float32)
        self.normals = np.ascontiguousarray(normals, dtype=np.float32)

    def lower(self, object_data: Any) -> dict[str, Any]:
        return {
            "uuid": self.uuid,
            "type": "BufferGeometry",
            "data": {
                "attributes": {
                    "position": g.pack_numpy_array(self.positions.T),
                    "normal": g.pack_numpy_array(self.normals.T),
                }
            },
        }


def _face_normals(corners: np.ndarray) -> np.ndarray:
    """Unit normal of each triangle (F, 3, 3 corners), repeated for its three corners."""
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    normal = normal / np.where(length > 0, length, 1.0)
    return np.repeat(normal, 3, axis=0)


def mesh_geometry(model: Any, mesh_id: int) -> FlatMeshGeometry:
    """Mesh ``mesh_id`` as triangles in the geom frame, with MuJoCo's own vertex normals when it has them.

    MuJoCo stores mesh vertices already moved into the mesh frame the geom pose refers to, so the
    vertices need no further transform.
    """
    vert_start, vert_count = int(model.mesh_vertadr[mesh_id]), int(model.mesh_vertnum[mesh_id])
    face_start, face_count = int(model.mesh_faceadr[mesh_id]), int(model.mesh_facenum[mesh_id])
    vertices = np.asarray(model.mesh_vert[vert_start : vert_start + vert_count], dtype=float)
    faces = np.asarray(model.mesh_face[face_start : face_start + face_count], dtype=int)
    corners = vertices[faces]  # (F, 3, 3)
    normals = None
    if hasattr(model, "mesh_normal") and int(model.mesh_normalnum[mesh_id]) > 0:
        normal_start = int(model.mesh_normaladr[mesh_id])
        table = np.asarray(
            model.mesh_normal[normal_start : normal_start + int(model.mesh_normalnum[mesh_id])]
        )
        indices = np.asarray(model.mesh_facenormal[face_start : face_start + face_count], dtype=int)
        if indices.size and indices.max() < len(table):
            normals = table[indices].reshape(-1, 3)
    if normals is None:
        normals = _face_normals(corners)
    return FlatMeshGeometry(corners.reshape(-1, 3), normals)


def hfield_geometry(model: Any, field_id: int) -> FlatMeshGeometry:
    """Height field ``field_id``'s top surface as triangles in the geom frame."""
    rows, cols = int(model.hfield_nrow[field_id]), int(model.hfield_ncol[field_id])
    radius_x, radius_y, elevation, _base = (float(v) for v in model.hfield_size[field_id])
    start = int(model.hfield_adr[field_id])
    heights = np.asarray(model.hfield_data[start : start + rows * cols], dtype=float).reshape(rows, cols)
    xs = np.linspace(-radius_x, radius_x, cols)
    ys = np.linspace(-radius_y, radius_y, rows)
    grid = np.stack(np.meshgrid(xs, ys), axis=-1)  # (rows, cols, 2)
    points = np.concatenate([grid, (heights * elevation)[..., None]], axis=-1).reshape(-1, 3)
    r, c = np.meshgrid(np.arange(rows - 1), np.arange(cols - 1), indexing="ij")
    a = (r * cols + c).ravel()
    b, d, e = a + 1, a + cols, a + cols + 1
    faces = np.concatenate([np.stack([a, b, e], 1), np.stack([a, e, d], 1)])
    corners = points[faces]
    return FlatMeshGeometry(corners.reshape(-1, 3), _face_normals(corners))


def _texture(model: Any, geom_id: int) -> tuple[bytes | None, tuple[float, float]]:
    """The PNG of the geom material's 2D color texture, and its repeat counts."""
    material = int(model.geom_matid[geom_id])
    if material < 0:
        return None, (1.0, 1.0)
    texids = np.atleast_1d(model.mat_texid[material])
    # mjTEXROLE_RGB is role 1 since MuJoCo 3.1 (a single id before).
    texture = int(texids[1] if texids.size > 1 else texids[0])
    if texture < 0 or int(model.tex_type[texture]) != 0:  # only 2D textures map onto faces
        return None, (1.0, 1.0)
    width, height = int(model.tex_width[texture]), int(model.tex_height[texture])
    channels = int(model.tex_nchannel[texture])
    start = int(model.tex_adr[texture])
    pixels = np.asarray(model.tex_data[start : start + width * height * channels], dtype=np.uint8)
    repeat = tuple(float(v) for v in model.mat_texrepeat[material][:2])
    return encode_png(pixels.reshape(height, width, channels)), (repeat[0], repeat[1])


def encode_png(pixels: np.ndarray) -> bytes:
    """A PNG of an (H, W, 1|3|4) uint8 image."""
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(pixels[..., 0] if pixels.shape[2] == 1 else pixels).save(buffer, format="PNG")
    return buffer.getvalue()
