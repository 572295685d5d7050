"""Points spread over a mesh's surface (an STL, say), area-weighted, as MoveIt Pro's LoadPointCloudFromFile
does for CAD parts. trimesh reads the mesh and samples it."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kinema.errors import PerceptionError
from kinema.perception.point_cloud import PointCloud


def sample_mesh_surface(
    path: str | os.PathLike[str],
    count: int,
    *,
    scale: float = 1.0,
    seed: int | None = None,
    frame_id: str = "",
    color: tuple[int, int, int] | None = None,
) -> PointCloud:
    """``count`` points on the surface of mesh file ``path`` (STL, OBJ, PLY, ...), coordinates x ``scale``.

    Args:
        path: the mesh file.
        count: how many points.
        scale: factor on the mesh's coordinates (STLs are often in millimetres: 0.001).
        seed: seed for reproducible sampling (None: random).
        frame_id: the frame of the mesh's coordinates.
        color: RGB given to every point, or None for no colours.

    Raises:
        PerceptionError: the file is missing or is not a mesh with area, or count < 1.
    """
    import trimesh

    file = Path(path)
    if count < 1:
        raise PerceptionError(f"number of points to sample must be at least 1, got {count}")
    if not file.is_file():
        raise PerceptionError(f"{file}: no such mesh file")
    try:
        mesh = trimesh.load_mesh(file, force="mesh")
    except Exception as error:
        raise PerceptionError(f"{file}: not a readable mesh: {error}") from error
    if not isinstance(mesh, trimesh.Trimesh) or mesh.area <= 0:
        raise PerceptionError(f"{file}: the mesh has no surface to sample")
    points, _faces = trimesh.sample.sample_surface(mesh, count, seed=seed)
    colors = None if color is None else np.tile(np.asarray(color, dtype=np.uint8), (count, 1))
    return PointCloud((np.asarray(points) * scale).astype(np.float32), colors, frame_id=frame_id)
