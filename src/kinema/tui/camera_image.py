"""Camera images made showable: any ``sensor_msgs/Image`` the cameras send, as RGB pixels (no textual).

Colour images keep their colours; ``mono8``/``mono16`` become grey; depth (``32FC1``, ``16UC1`` in mm)
is shaded grey between its nearest and farthest valid value (near is light, nothing seen is black).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from kinema.errors import PerceptionError
from kinema.tui.connection import CameraImage

IMAGE_TYPE = "sensor_msgs/msg/Image"
ENCODINGS = ("rgb8", "bgr8", "rgba8", "bgra8", "mono8", "mono16", "32FC1", "16UC1")


def shade_depth(depth: np.ndarray) -> np.ndarray:
    """HxWx3 uint8 grey of a depth image: nearest valid depth white, farthest dark, invalid black."""
    depth = np.asarray(depth, dtype=np.float32)
    valid = np.isfinite(depth) & (depth > 0)
    grey = np.zeros(depth.shape, dtype=np.uint8)
    if valid.any():
        near, far = float(depth[valid].min()), float(depth[valid].max())
        span = far - near if far > near else 1.0
        grey[valid] = (255 - 200 * (depth[valid] - near) / span).astype(np.uint8)
    return np.repeat(grey[:, :, None], 3, axis=2)


def rgb_pixels(message: Any) -> np.ndarray:
    """HxWx3 uint8 RGB of a ``sensor_msgs/Image``.

    Raises:
        PerceptionError: an encoding it cannot show (naming those it can) or a data size that does not
            match width, height and step.
    """
    height, width, step = int(message.height), int(message.width), int(message.step)
    encoding = str(message.encoding)
    data = np.asarray(message.data, dtype=np.uint8)
    if data.size < height * step:
        raise PerceptionError(f"image of {width}x{height}, step {step}, has only {data.size} bytes")
    rows = data[: height * step].reshape(height, step)
    if encoding in ("rgb8", "bgr8", "rgba8", "bgra8"):
        channels = 4 if encoding.endswith("a8") else 3
        pixels = rows[:, : width * channels].reshape(height, width, channels)[:, :, :3]
        return np.ascontiguousarray(pixels[:, :, ::-1] if encoding.startswith("bgr") else pixels)
    if encoding == "mono8":
        return np.repeat(rows[:, :width, None], 3, axis=2)
    big_endian = bool(message.is_bigendian)
    if encoding in ("mono16", "16UC1"):
        values = rows[:, : width * 2].copy().view(">u2" if big_endian else "<u2")
        if encoding == "16UC1":  # depth in millimetres
            return shade_depth(np.where(values > 0, values / 1000.0, np.nan))
        return np.repeat((values >> 8).astype(np.uint8)[:, :, None], 3, axis=2)
    if encoding == "32FC1":
        return shade_depth(rows[:, : width * 4].copy().view(">f4" if big_endian else "<f4"))
    raise PerceptionError(f"cannot show image encoding {encoding!r}; valid: {', '.join(ENCODINGS)}")


def camera_image(topic: str, message: Any) -> CameraImage:
    """The :class:`CameraImage` of an image message received on ``topic``."""
    stamp = message.header.stamp
    return CameraImage(
        topic,
        rgb_pixels(message),
        str(message.encoding),
        str(message.header.frame_id),
        int(stamp.sec) + int(stamp.nanosec) * 1e-9,
    )
