"""Where a camera is, from three AprilTags on a calibration tool the robot holds (or that is fixed in the
cell at a known place).

The tool carries three tags, left, right and bottom. Its frame is defined by their centres: the origin is
their centroid, x points from the left tag to the right one, y points from the bottom tag toward the
middle of the other two (made perpendicular to x), and z = x cross y. The tool's frame in the robot's
description (``calibration_tool_frame``) must be placed that way. The camera sees the three tags; their
positions in the camera's frame give ``camera_T_tool``; the tool's pose in the base frame is known from
the robot; so ``base_T_camera = base_T_tool · inverse(camera_T_tool)``. Only the tags' positions are used
(a tag's orientation is the least accurate thing a detector measures).
"""

from __future__ import annotations

import numpy as np

from kinema.errors import PerceptionError

__all__ = ["camera_in_base", "tool_frame_from_tags"]

# Tags closer than this (m), or a bottom tag this close to the left-right line, define no frame.
_DEGENERATE = 1e-3


def tool_frame_from_tags(left: np.ndarray, right: np.ndarray, bottom: np.ndarray) -> np.ndarray:
    """``frame_T_tool`` from the three tag centres given in ``frame`` (each shape ``(3,)``, metres).

    Raises:
        PerceptionError: two tags (nearly) coincide, or the three are (nearly) on one line.
    """
    left, right, bottom = (np.asarray(v, dtype=float).reshape(3) for v in (left, right, bottom))
    across = right - left
    if np.linalg.norm(across) < _DEGENERATE:
        raise PerceptionError("the left and right tags are at the same place; check which tag is which")
    x = across / np.linalg.norm(across)
    up = (left + right) / 2.0 - bottom
    up = up - x * float(up @ x)
    if np.linalg.norm(up) < _DEGENERATE:
        raise PerceptionError("the bottom tag is on the line through the left and right tags; no frame")
    y = up / np.linalg.norm(up)
    pose = np.eye(4)
    pose[:3, :3] = np.column_stack([x, y, np.cross(x, y)])
    pose[:3, 3] = (left + right + bottom) / 3.0
    return pose


def camera_in_base(
    base_T_tool: np.ndarray, left: np.ndarray, right: np.ndarray, bottom: np.ndarray
) -> np.ndarray:
    """``base_T_camera`` from the tool's pose in the base and the tag centres seen in the camera's frame.

    Raises:
        PerceptionError: as :func:`tool_frame_from_tags`.
    """
    from kinema.transforms import invert

    camera_T_tool = tool_frame_from_tags(left, right, bottom)
    return np.asarray(base_T_tool, dtype=float) @ invert(camera_T_tool)
