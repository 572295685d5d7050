"""The edge between perception's arrays and ``sensor_msgs``: PointCloud2, Image and CameraInfo.

Messages are the transport's rosbags dataclasses; pass the type table (``session.registry.typestore.types``)
to build them. Clouds go out as PCL does it: float32 x, y, z and, with colours, an ``rgb`` float32 whose
bytes are B, G, R, 0 (little endian), 16 bytes a point; an organised cloud keeps its height x width and
marks missing points with NaN (``is_dense`` false).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from kinema.errors import PerceptionError
from kinema.perception.intrinsics import CameraIntrinsics
from kinema.perception.point_cloud import PointCloud

FLOAT32 = 7  # sensor_msgs/PointField datatype
_DATATYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 8: "f8"}


def stamp_of(seconds: float, types: Mapping[str, Any]) -> Any:
    """A ``builtin_interfaces/Time`` for ``seconds``."""
    nanoseconds = round(seconds * 1e9)
    return types["builtin_interfaces/msg/Time"](
        sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000
    )


def _header(frame_id: str, seconds: float, types: Mapping[str, Any]) -> Any:
    return types["std_msgs/msg/Header"](stamp=stamp_of(seconds, types), frame_id=frame_id)


def to_point_cloud2(cloud: PointCloud, types: Mapping[str, Any]) -> Any:
    """``sensor_msgs/PointCloud2`` of ``cloud`` (organised if it is)."""
    count = len(cloud)
    height, width = cloud.shape if cloud.shape is not None else (1, count)
    has_rgb = cloud.colors is not None
    point_step = 16 if has_rgb else 12
    packed = np.empty((count, point_step // 4), dtype="<f4")
    packed[:, :3] = cloud.points
    if has_rgb:
        assert cloud.colors is not None
        c = cloud.colors.astype(np.uint32)
        packed.view("<u4")[:, 3] = (c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]
    field_type = types["sensor_msgs/msg/PointField"]
    names = ["x", "y", "z", "rgb"] if has_rgb else ["x", "y", "z"]
    fields = [field_type(name=n, offset=4 * i, datatype=FLOAT32, count=1) for i, n in enumerate(names)]
    return types["sensor_msgs/msg/PointCloud2"](
        header=_header(cloud.frame_id, cloud.stamp, types),
        height=height,
        width=width,
        fields=fields,
        is_bigendian=False,
        point_step=point_step,
        row_step=point_step * width,
        data=packed.reshape(-1).view(np.uint8),
        is_dense=bool(np.isfinite(cloud.points).all()),
    )


def from_point_cloud2(message: Any) -> PointCloud:
    """The cloud in a ``sensor_msgs/PointCloud2`` (x, y, z and, if present, PCL-packed rgb).

    Raises:
        PerceptionError: the message has no float x/y/z fields or its data is short.
    """
    offsets = {str(f.name): (int(f.offset), int(f.datatype)) for f in message.fields}
    missing = [n for n in ("x", "y", "z") if n not in offsets]
    if missing:
        raise PerceptionError(
            f"PointCloud2 in frame {message.header.frame_id!r} has no {', '.join(missing)} field "
            f"(fields: {', '.join(offsets) or 'none'})"
        )
    count = int(message.height) * int(message.width)
    step = int(message.point_step)
    data = np.asarray(message.data, dtype=np.uint8)
    if len(data) < count * step:
        raise PerceptionError(f"PointCloud2 data holds {len(data)} bytes, {count} points need {count * step}")
    rows = data[: count * step].reshape(count, step)
    endian = ">" if message.is_bigendian else "<"

    def column(name: str) -> np.ndarray:
        offset, datatype = offsets[name]
        dtype = np.dtype(endian + _DATATYPES.get(datatype, "f4"))
        return rows[:, offset : offset + dtype.itemsize].copy().view(dtype).reshape(count)

    points = np.stack([column("x"), column("y"), column("z")], axis=1).astype(np.float32)
    colors = None
    for name in ("rgb", "rgba"):
        if name in offsets:
            offset, _ = offsets[name]
            packed = rows[:, offset : offset + 4].copy().view(endian + "u4").reshape(count)
            colors = np.stack([(packed >> 16) & 255, (packed >> 8) & 255, packed & 255], axis=1)
            break
    stamp = message.header.stamp
    organised = int(message.height) > 1
    return PointCloud(
        points,
        None if colors is None else colors.astype(np.uint8),
        frame_id=str(message.header.frame_id),
        stamp=int(stamp.sec) + int(stamp.nanosec) * 1e-9,
        shape=(int(message.height), int(message.width)) if organised else None,
    )


def image_message(
    pixels: np.ndarray, encoding: str, frame_id: str, seconds: float, types: Mapping[str, Any]
) -> Any:
    """``sensor_msgs/Image`` of an HxWx3 ``rgb8`` or an HxW ``32FC1`` array."""
    pixels = np.ascontiguousarray(pixels)
    dtype: np.dtype[Any]
    if encoding == "rgb8":
        channels, dtype = 3, np.dtype(np.uint8)
    elif encoding == "32FC1":
        channels, dtype = 1, np.dtype("<f4")
    else:
        raise PerceptionError(f"image encoding {encoding!r} is not supported (rgb8, 32FC1)")
    height, width = pixels.shape[:2]
    data = pixels.astype(dtype, copy=False).reshape(-1).view(np.uint8)
    return types["sensor_msgs/msg/Image"](
        header=_header(frame_id, seconds, types),
        height=height,
        width=width,
        encoding=encoding,
        is_bigendian=0,
        step=width * channels * dtype.itemsize,
        data=data,
    )


def image_array(message: Any) -> np.ndarray:
    """The pixels of a ``sensor_msgs/Image``: HxWx3 uint8 for rgb8/bgr8 (as RGB), HxW float32 (32FC1)."""
    height, width, encoding = int(message.height), int(message.width), str(message.encoding)
    data = np.asarray(message.data, dtype=np.uint8)
    step = int(message.step)
    if encoding in ("rgb8", "bgr8"):
        rows = data.reshape(height, step)[:, : width * 3].reshape(height, width, 3)
        return rows[..., ::-1].copy() if encoding == "bgr8" else rows.copy()
    if encoding == "32FC1":
        dtype = ">f4" if message.is_bigendian else "<f4"
        return data.reshape(height, step)[:, : width * 4].copy().view(dtype).reshape(height, width)
    raise PerceptionError(f"image encoding {encoding!r} is not supported (rgb8, bgr8, 32FC1)")


def camera_info_message(
    intrinsics: CameraIntrinsics, frame_id: str, seconds: float, types: Mapping[str, Any]
) -> Any:
    """``sensor_msgs/CameraInfo`` of an undistorted pinhole camera."""
    k = intrinsics.k
    p = np.zeros((3, 4))
    p[:, :3] = k
    return types["sensor_msgs/msg/CameraInfo"](
        header=_header(frame_id, seconds, types),
        height=intrinsics.height,
        width=intrinsics.width,
        distortion_model="plumb_bob",
        d=np.zeros(5),
        k=k.reshape(-1),
        r=np.eye(3).reshape(-1),
        p=p.reshape(-1),
        binning_x=0,
        binning_y=0,
        roi=types["sensor_msgs/msg/RegionOfInterest"](
            x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
        ),
    )


def intrinsics_of(message: Any) -> CameraIntrinsics:
    """The pinhole intrinsics in a ``sensor_msgs/CameraInfo``."""
    k = np.asarray(message.k, dtype=float).reshape(3, 3)
    return CameraIntrinsics(int(message.width), int(message.height), k[0, 0], k[1, 1], k[0, 2], k[1, 2])
