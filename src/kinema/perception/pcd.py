"""PCL's ``.pcd`` files (ascii, binary and binary_compressed), read and written with pypcd4.

x, y, z are required; an ``rgb`` (or ``rgba``) field, packed PCL-style, becomes the cloud's colours.
Saving is atomic: a partly written file never replaces a good one.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from kinema.errors import PerceptionError
from kinema.perception.point_cloud import PointCloud


def load_pcd(path: str | os.PathLike[str], frame_id: str = "") -> PointCloud:
    """The cloud in PCD file ``path``, labelled ``frame_id``.

    Raises:
        PerceptionError: the file is missing, not a PCD file, or has no x, y, z fields.
    """
    import pypcd4

    file = Path(path)
    if not file.is_file():
        raise PerceptionError(f"{file}: no such point cloud file")
    try:
        pcd = pypcd4.PointCloud.from_path(file)
    except Exception as error:
        raise PerceptionError(f"{file}: not a readable PCD file: {error}") from error
    fields = list(pcd.fields)
    missing = [f for f in ("x", "y", "z") if f not in fields]
    if missing:
        raise PerceptionError(
            f"{file}: PCD file has no {', '.join(missing)} field (fields: {', '.join(fields)})"
        )
    data = pcd.pc_data
    points = np.stack([data["x"], data["y"], data["z"]], axis=1).astype(np.float32)
    colors = None
    for name in ("rgb", "rgba"):
        if name in fields:
            packed = np.ascontiguousarray(data[name]).view(np.uint32)
            colors = np.stack([(packed >> 16) & 255, (packed >> 8) & 255, packed & 255], axis=1).astype(
                np.uint8
            )
            break
    width, height = int(pcd.metadata.width), int(pcd.metadata.height)
    shape = (height, width) if height > 1 and width * height == len(points) else None
    return PointCloud(points, colors, frame_id=frame_id, shape=shape)


def save_pcd(cloud: PointCloud, path: str | os.PathLike[str], *, compressed: bool = True) -> Path:
    """Write ``cloud`` to ``path`` (binary_compressed, or binary with ``compressed=False``); returns the path.

    Raises:
        PerceptionError: the folder does not exist or cannot be written.
    """
    import pypcd4

    file = Path(path)
    if not file.parent.is_dir():
        raise PerceptionError(f"{file}: folder {file.parent} does not exist")
    points = cloud.points.astype(np.float32)
    if cloud.colors is not None:
        c = cloud.colors.astype(np.uint32)
        rgb = ((c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]).view(np.float32)
        pcd = pypcd4.PointCloud.from_xyzrgb_points(np.column_stack([points, rgb]))
    else:
        pcd = pypcd4.PointCloud.from_xyz_points(points)
    if cloud.shape is not None:
        pcd.metadata.height, pcd.metadata.width = cloud.shape
    encoding = pypcd4.Encoding.BINARY_COMPRESSED if compressed else pypcd4.Encoding.BINARY
    handle, temporary = tempfile.mkstemp(prefix=f".{file.name}.", suffix=".tmp", dir=file.parent)
    os.close(handle)
    try:
        pcd.save(temporary, encoding=encoding)
        os.replace(temporary, file)
    except OSError as error:
        raise PerceptionError(f"{file}: cannot write the point cloud: {error}") from error
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)
    return file
