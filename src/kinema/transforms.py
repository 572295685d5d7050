"""Rigid transforms: poses, quaternions, rotation matrices and twists, in one place.

Every conversion between a pose and a 4x4 matrix in Kinema goes through this module (as mink keeps its
SE(3) in one module), built on scipy's :class:`~scipy.spatial.transform.Rotation`, so no quaternion formula
is written twice and degenerate input has one answer everywhere.

Conventions:

- a pose is a ``(4, 4)`` float array, a homogeneous transform named by its frames (``world_T_tool`` maps
  points in ``tool`` to ``world``); positions are metres;
- a quaternion is ``(x, y, z, w)``, the order of ``geometry_msgs/Quaternion`` and scipy; MuJoCo's
  ``(w, x, y, z)`` is converted at the edge with :func:`quaternion_from_wxyz`;
- a twist (and a wrench) is a ``(6,)`` array, linear part first, then angular.

Degenerate input, one answer: a quaternion is normalised before use; an all-zero quaternion (norm below
:data:`ZERO_NORM`) is an unset orientation and means the identity, as MoveIt's planning scene and RViz read
a message whose orientation was never filled; a quaternion with a NaN or an infinite component, or one that
is not four numbers, raises :class:`TransformError`. A behavior that wants to refuse an all-zero quaternion
a user typed checks :func:`is_zero_quaternion` before converting.

scipy is imported when a rotation is first built, so importing this module costs only numpy.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from kinema.errors import KinemaError

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation

__all__ = [
    "ZERO_NORM",
    "TransformError",
    "angle_between",
    "average_pose",
    "euler_from_rotation",
    "invert",
    "is_zero_quaternion",
    "pose_dict",
    "pose_from_message",
    "pose_matrix",
    "pose_parts",
    "quaternion_from_matrix",
    "quaternion_from_wxyz",
    "rotate_twist",
    "rotation_angle",
    "rotation_from_euler",
    "rotation_from_rotvec",
    "rotation_matrix",
    "slerp",
    "unit_quaternion",
]

# Below this norm a quaternion carries no direction: an unset orientation (see the module docstring).
ZERO_NORM = 1e-9


class TransformError(KinemaError, ValueError):
    """A value that is no rotation or pose: wrong number of components, NaN or infinity."""


def _rotation(quaternion_xyzw: Any) -> Rotation:
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(unit_quaternion(quaternion_xyzw))


def is_zero_quaternion(quaternion_xyzw: Any) -> bool:
    """True for an all-zero quaternion (norm below :data:`ZERO_NORM`): an unset orientation."""
    return float(np.linalg.norm(np.asarray(quaternion_xyzw, dtype=float))) < ZERO_NORM


def unit_quaternion(quaternion_xyzw: Any) -> np.ndarray:
    """The quaternion ``(x, y, z, w)`` normalised, ``(4,)``; all-zero is the identity ``(0, 0, 0, 1)``.

    Raises:
        TransformError: not four finite numbers.
    """
    try:
        q = np.asarray(quaternion_xyzw, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise TransformError(f"a quaternion must be 4 numbers x, y, z, w, got {quaternion_xyzw!r}") from None
    if q.shape != (4,):
        raise TransformError(f"a quaternion must be 4 numbers x, y, z, w, got {q.size}: {q.tolist()}")
    if not np.all(np.isfinite(q)):
        raise TransformError(f"quaternion {q.tolist()} has a NaN or infinite component")
    norm = float(np.linalg.norm(q))
    if norm < ZERO_NORM:
        return np.array([0.0, 0.0, 0.0, 1.0])
    return q / norm


def quaternion_from_wxyz(quaternion_wxyz: Any) -> np.ndarray:
    """A MuJoCo ``(w, x, y, z)`` quaternion in this module's order ``(x, y, z, w)``, normalised."""
    w, x, y, z = np.asarray(quaternion_wxyz, dtype=float).reshape(4)
    return unit_quaternion([x, y, z, w])


def rotation_matrix(quaternion_xyzw: Any) -> np.ndarray:
    """The ``(3, 3)`` rotation matrix of a quaternion ``(x, y, z, w)`` (see the degenerate-input rule)."""
    return _rotation(quaternion_xyzw).as_matrix()


def quaternion_from_matrix(rotation: np.ndarray) -> np.ndarray:
    """The unit quaternion ``(x, y, z, w)`` of a rotation matrix (the upper-left ``(3, 3)`` of a pose)."""
    from scipy.spatial.transform import Rotation

    matrix = np.asarray(rotation, dtype=float)
    return Rotation.from_matrix(matrix[:3, :3]).as_quat()


def rotation_from_rotvec(rotation_vector: Any) -> np.ndarray:
    """The ``(3, 3)`` rotation about ``rotation_vector``'s axis by its length (rad); ``(N, 3)`` vectors give
    ``(N, 3, 3)`` rotations."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_rotvec(np.asarray(rotation_vector, dtype=float)).as_matrix()


def rotation_from_euler(roll_pitch_yaw: Any) -> np.ndarray:
    """The ``(3, 3)`` rotation of roll, pitch, yaw (rad) about the fixed x, y, z axes in turn (URDF's rpy)."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_euler("xyz", np.asarray(roll_pitch_yaw, dtype=float)).as_matrix()


def euler_from_rotation(rotation: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (rad) of a rotation (the upper-left ``(3, 3)`` of a pose): the inverse of
    :func:`rotation_from_euler`, URDF's ``rpy``."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(np.asarray(rotation, dtype=float)[:3, :3]).as_euler("xyz")


def pose_matrix(position: Any, quaternion_xyzw: Any) -> np.ndarray:
    """The ``(4, 4)`` pose of a position ``(x, y, z)`` (m) and a quaternion ``(x, y, z, w)``."""
    matrix = np.eye(4)
    matrix[:3, :3] = rotation_matrix(quaternion_xyzw)
    matrix[:3, 3] = np.asarray(position, dtype=float).reshape(3)
    return matrix


def pose_parts(pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(position (3,), quaternion (x, y, z, w) (4,))`` of a ``(4, 4)`` pose."""
    matrix = np.asarray(pose, dtype=float)
    return matrix[:3, 3].copy(), quaternion_from_matrix(matrix)


def _xyz(value: Any, names: str) -> list[float]:
    if isinstance(value, Mapping):
        return [float(value.get(name, 0.0)) for name in names]
    return [float(getattr(value, name)) for name in names]


def pose_from_message(pose: Any) -> np.ndarray:
    """The ``(4, 4)`` pose of a ``geometry_msgs/Pose`` (a message or its dict form, missing fields 0)."""
    if isinstance(pose, Mapping):
        position, orientation = pose.get("position", {}), pose.get("orientation", {})
    else:
        position, orientation = pose.position, pose.orientation
    return pose_matrix(_xyz(position, "xyz"), _xyz(orientation, "xyzw"))


def pose_dict(pose: np.ndarray) -> dict[str, dict[str, float]]:
    """The ``geometry_msgs/Pose`` (dict form, for ``kinema.transport.from_dict``) of a ``(4, 4)`` pose."""
    (px, py, pz), (x, y, z, w) = pose_parts(pose)
    return {
        "position": {"x": float(px), "y": float(py), "z": float(pz)},
        "orientation": {"x": float(x), "y": float(y), "z": float(z), "w": float(w)},
    }


def invert(pose: np.ndarray) -> np.ndarray:
    """``b_T_a`` of a rigid ``a_T_b`` ``(4, 4)``: the transposed rotation, no general matrix inverse."""
    matrix = np.asarray(pose, dtype=float)
    inverse = np.eye(4)
    inverse[:3, :3] = matrix[:3, :3].T
    inverse[:3, 3] = -matrix[:3, :3].T @ matrix[:3, 3]
    return inverse


def slerp(start_xyzw: Any, end_xyzw: Any, t: float) -> np.ndarray:
    """The unit quaternion at fraction ``t`` in [0, 1] from ``start`` to ``end``, the shorter way round."""
    from scipy.spatial.transform import Rotation, Slerp

    keys = Rotation.from_quat(np.stack([unit_quaternion(start_xyzw), unit_quaternion(end_xyzw)]))
    return Slerp([0.0, 1.0], keys)(float(np.clip(t, 0.0, 1.0))).as_quat()


def angle_between(start_xyzw: Any, end_xyzw: Any) -> float:
    """The angle (rad, in [0, pi]) of the rotation that takes orientation ``start`` to ``end``."""
    return float((_rotation(end_xyzw) * _rotation(start_xyzw).inv()).magnitude())


def rotation_angle(a: np.ndarray, b: np.ndarray) -> float:
    """The angle (rad, in [0, pi]) of the rotation that takes ``(3, 3)`` rotation matrix ``a`` to ``b``."""
    cosine = (float(np.trace(np.asarray(a).T @ np.asarray(b))) - 1.0) / 2.0
    return float(np.arccos(np.clip(cosine, -1.0, 1.0)))


def average_pose(poses: Sequence[np.ndarray], weights: Sequence[float] | None = None) -> np.ndarray:
    """The mean of ``(4, 4)`` poses: the (weighted) mean position and the rotation closest to the mean of
    the rotations (the chordal L2 mean, scipy's ``Rotation.mean``: for rotations a few degrees apart it is
    their average, and it does not depend on a quaternion's sign).

    Raises:
        TransformError: no poses, or weights that do not match them or do not add up to more than 0.
    """
    from scipy.spatial.transform import Rotation

    matrices = np.asarray([np.asarray(p, dtype=float) for p in poses])
    if matrices.ndim != 3 or matrices.shape[1:] != (4, 4) or not len(matrices):
        raise TransformError(
            f"average_pose needs one or more 4x4 poses, got an array of shape {matrices.shape}"
        )
    w = np.ones(len(matrices)) if weights is None else np.asarray(weights, dtype=float)
    if w.shape != (len(matrices),) or not np.all(w >= 0) or not w.sum() > 0:
        raise TransformError(f"average_pose needs one weight >= 0 a pose, not all 0; got {list(w)}")
    mean = np.eye(4)
    mean[:3, 3] = np.average(matrices[:, :3, 3], axis=0, weights=w)
    mean[:3, :3] = Rotation.from_matrix(matrices[:, :3, :3]).mean(weights=w).as_matrix()
    return mean


def rotate_twist(rotation: np.ndarray, twist: Sequence[float] | np.ndarray) -> np.ndarray:
    """A twist or wrench ``(6,)`` (linear, angular) re-expressed by ``rotation`` ``(3, 3)``: ``a_R_b`` takes
    one in ``b``'s axes to ``a``'s (same reference point; use ``rotation.T`` for the way back)."""
    r = np.asarray(rotation, dtype=float)[:3, :3]
    vector = np.asarray(twist, dtype=float).reshape(6)
    return np.concatenate((r @ vector[:3], r @ vector[3:]))
