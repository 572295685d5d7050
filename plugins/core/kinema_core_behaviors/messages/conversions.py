"""Between the ROS messages behaviors exchange on the blackboard and Kinema's motion types.

Blackboard values are ROS messages, as in MoveIt Pro (``sensor_msgs/JointState``,
``trajectory_msgs/JointTrajectory``, ``geometry_msgs/PoseStamped``), so objectives and the blackboard
viewer see the same shapes there; planning works on numpy arrays.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from kinema.errors import ObjectiveError

if TYPE_CHECKING:
    import numpy as np

    from kinema.motion import JointTrajectory

JOINT_STATE_TYPE = "sensor_msgs/msg/JointState"
ROBOT_STATE_TYPE = "moveit_studio_agent_msgs/msg/RobotJointState"
TRAJECTORY_TYPE = "trajectory_msgs/msg/JointTrajectory"
POINT_TYPE = "trajectory_msgs/msg/JointTrajectoryPoint"
DURATION_TYPE = "builtin_interfaces/msg/Duration"
POSE_STAMPED_TYPE = "geometry_msgs/msg/PoseStamped"


def duration(seconds: float) -> dict[str, int]:
    """A ``builtin_interfaces/Duration`` dict (non-negative nanoseconds part, as ROS requires)."""
    total = round(seconds * 1e9)
    return {"sec": total // 1_000_000_000, "nanosec": total % 1_000_000_000}


def seconds(stamp: Any) -> float:
    """Seconds of a ``Duration``/``Time`` message or dict."""
    if isinstance(stamp, Mapping):
        return int(stamp["sec"]) + int(stamp["nanosec"]) * 1e-9
    return int(stamp.sec) + int(stamp.nanosec) * 1e-9


def joint_state_message(names: Sequence[str], positions: Sequence[float]) -> Any:
    """A ``sensor_msgs/JointState`` with positions only."""
    from kinema.transport import from_dict

    return from_dict(JOINT_STATE_TYPE, {"name": list(names), "position": [float(p) for p in positions]})


def robot_state_message(names: Sequence[str], positions: Sequence[float]) -> Any:
    """A ``RobotJointState`` (joint state plus empty multi-DOF state), MoveIt Pro's robot state shape.

    MoveIt Pro's "Move to Joint State" takes this type, and its ``robot_joint_state.yaml`` holds exactly
    these two parts.
    """
    from kinema.transport import from_dict

    return from_dict(
        ROBOT_STATE_TYPE,
        {"joint_state": {"name": list(names), "position": [float(p) for p in positions]}},
    )


def joint_positions(value: Any, what: str) -> dict[str, float]:
    """Joint positions by name from a JointState, a RobotJointState, a waypoint or a ``{name: value}`` dict.

    A dict may also be a JointState or RobotJointState written out (``{name: [...], position: [...]}``,
    ``{joint_state: {name: [...], position: [...]}}``), as a ``-p`` override or YAML file spells one.

    Raises:
        ObjectiveError: the value is none of these, or names and positions disagree in length.
    """
    if isinstance(value, Mapping) and isinstance(value.get("joint_state"), Mapping):
        value = value["joint_state"]
    if isinstance(value, Mapping) and not _written_joint_state(value):
        try:
            return {str(name): float(position) for name, position in value.items()}
        except (TypeError, ValueError) as error:
            raise ObjectiveError(
                f"{what} must map joint names to numbers ({{joint1: 0.0, joint2: 1.57}}) or be a "
                f"sensor_msgs/JointState ({{name: [joint1, joint2], position: [0.0, 1.57]}}): {error}"
            ) from None
    if isinstance(value, Mapping):
        names, positions = value["name"], value["position"]
        if not isinstance(names, list | tuple) or not isinstance(positions, list | tuple):
            raise ObjectiveError(
                f"{what}: a JointState's name and position are lists "
                f"({{name: [joint1, joint2], position: [0.0, 1.57]}}), got {str(dict(value))[:80]!r}"
            )
    else:
        state = getattr(value, "joint_state", value)
        names = getattr(state, "name", None)
        positions = getattr(state, "position", None)
    if names is None or positions is None:
        raise ObjectiveError(
            f"{what} must be a sensor_msgs/JointState (e.g. from RetrieveWaypoint or GetJointState), "
            f"got {type(value).__name__}: {str(value)[:80]!r}"
        )
    if len(names) != len(positions):
        raise ObjectiveError(f"{what} names {len(names)} joints but gives {len(positions)} positions")
    try:
        return {str(name): float(position) for name, position in zip(names, positions, strict=True)}
    except (TypeError, ValueError) as error:
        raise ObjectiveError(f"{what}: a joint position is not a number: {error}") from None


def _written_joint_state(value: Mapping[Any, Any]) -> bool:
    """A dict holding a JointState's fields (``name`` and ``position``) rather than joint names."""
    return "name" in value and "position" in value


def trajectory_message(trajectory: JointTrajectory, frame_id: str = "") -> Any:
    """A ``trajectory_msgs/JointTrajectory`` of a timed trajectory (positions, velocities, accelerations)."""
    import numpy as np

    from kinema.interfaces import load_interfaces
    from kinema.transport import from_dict

    # The points are built as messages directly, their rows of float64 kept as arrays: converting a few
    # hundred points from lists, field by field, took longer than planning them.
    types = load_interfaces().typestore.types
    point, stamp = types[POINT_TYPE], types[DURATION_TYPE]
    positions, velocities, accelerations = (
        np.asarray(values, dtype=np.float64)
        for values in (trajectory.positions, trajectory.velocities, trajectory.accelerations)
    )
    points = [
        point(
            positions=positions[i].copy(),
            velocities=velocities[i].copy(),
            accelerations=accelerations[i].copy(),
            effort=np.zeros(0, dtype=np.float64),
            time_from_start=stamp(**duration(float(time))),
        )
        for i, time in enumerate(trajectory.times)
    ]
    return from_dict(
        TRAJECTORY_TYPE,
        {"header": {"frame_id": frame_id}, "joint_names": list(trajectory.joint_names), "points": points},
    )


def trajectory_from_message(message: Any, what: str) -> JointTrajectory:
    """The timed trajectory a ``trajectory_msgs/JointTrajectory`` describes.

    Raises:
        ObjectiveError: not a trajectory message, no points, or inconsistent points.
    """
    from kinema.errors import MotionError
    from kinema.motion import JointTrajectory

    names = getattr(message, "joint_names", None)
    points = getattr(message, "points", None)
    if names is None or points is None:
        raise ObjectiveError(
            f"{what} must be a trajectory_msgs/JointTrajectory (e.g. from PlanToJointGoal), "
            f"got {type(message).__name__}"
        )
    if len(points) == 0:
        raise ObjectiveError(f"{what} has no points")
    velocities = [list(p.velocities) for p in points]
    accelerations = [list(p.accelerations) for p in points]
    try:
        return JointTrajectory.from_points(
            [str(n) for n in names],
            [seconds(p.time_from_start) for p in points],
            [list(p.positions) for p in points],
            velocities if all(len(v) for v in velocities) else None,
            accelerations if all(len(a) for a in accelerations) else None,
        )
    except MotionError as error:
        raise ObjectiveError(f"{what}: {error}") from None


def pose_stamped_message(frame_id: str, matrix: np.ndarray) -> Any:
    """A ``geometry_msgs/PoseStamped`` of a 4x4 homogeneous transform."""
    from kinema import transforms
    from kinema.transport import from_dict

    return from_dict(
        POSE_STAMPED_TYPE, {"header": {"frame_id": frame_id}, "pose": transforms.pose_dict(matrix)}
    )


def pose_matrix(pose_stamped: Any, what: str) -> tuple[str, np.ndarray]:
    """``(frame_id, 4x4 transform)`` of a ``geometry_msgs/PoseStamped``.

    The orientation is read as :mod:`kinema.transforms` reads every quaternion: normalised, all-zero (an
    unset orientation) the identity.

    Raises:
        ObjectiveError: not a PoseStamped, or an orientation with a NaN or infinite component.
    """
    from kinema import transforms

    pose = getattr(pose_stamped, "pose", None)
    header = getattr(pose_stamped, "header", None)
    if pose is None or header is None:
        raise ObjectiveError(
            f"{what} must be a geometry_msgs/PoseStamped (e.g. from CreatePoseStamped), "
            f"got {type(pose_stamped).__name__}"
        )
    try:
        return str(header.frame_id), transforms.pose_from_message(pose)
    except transforms.TransformError as error:
        raise ObjectiveError(f"{what}: {error}") from None


_POINT_FIELD_DTYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 8: "f8"}


def point_cloud_xyz(cloud: Any) -> np.ndarray:
    """The finite ``x, y, z`` of a ``sensor_msgs/PointCloud2`` as an ``(N, 3)`` float array (m).

    Raises:
        ObjectiveError: not a point cloud, or without x, y and z fields.
    """
    import numpy as np

    fields = {str(f.name): f for f in getattr(cloud, "fields", [])}
    if not all(axis in fields for axis in "xyz"):
        raise ObjectiveError(
            f"the point cloud has fields {sorted(fields)}; x, y and z are needed (a sensor_msgs/PointCloud2)"
        )
    order = ">" if cloud.is_bigendian else "<"
    dtype = np.dtype(
        {
            "names": list("xyz"),
            "formats": [order + _POINT_FIELD_DTYPES[int(fields[a].datatype)] for a in "xyz"],
            "offsets": [int(fields[a].offset) for a in "xyz"],
            "itemsize": int(cloud.point_step),
        }
    )
    count = int(cloud.width) * int(cloud.height)
    data = np.asarray(cloud.data, dtype=np.uint8)[: count * int(cloud.point_step)]
    records = np.frombuffer(data.tobytes(), dtype=dtype, count=count)
    xyz = np.stack([records[a].astype(float) for a in "xyz"], axis=1)
    return xyz[np.isfinite(xyz).all(axis=1)]


def point_cloud_message(xyz: np.ndarray, frame_id: str) -> Any:
    """A dense ``sensor_msgs/PointCloud2`` of ``(N, 3)`` points (float32 x, y, z)."""
    import numpy as np

    from kinema.transport import from_dict

    points = np.ascontiguousarray(xyz, dtype="<f4")
    fields = [{"name": a, "offset": 4 * i, "datatype": 7, "count": 1} for i, a in enumerate("xyz")]
    return from_dict(
        "sensor_msgs/msg/PointCloud2",
        {
            "header": {"frame_id": frame_id},
            "height": 1,
            "width": len(points),
            "fields": fields,
            "is_bigendian": False,
            "point_step": 12,
            "row_step": 12 * len(points),
            "data": np.frombuffer(points.tobytes(), dtype=np.uint8),
            "is_dense": True,
        },
    )
