"""The perception family's one edge between the blackboard and :mod:`kinema.perception`.

Ports hold ``sensor_msgs/PointCloud2`` messages, as MoveIt Pro's do (so PushBackVector, SendPointCloudToUI
and the blackboard view see what they expect); a behavior reads a port into a numpy
:class:`~kinema.perception.PointCloud`, works on arrays and writes a message back. Moving a cloud between
frames asks the frame tree of the cell as it is now.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.errors import KinemaError

from ..messages.conversions import POSE_STAMPED_TYPE, pose_matrix
from ..messages.ports import port_error, read_message, write_output

POINT_CLOUD = "sensor_msgs/msg/PointCloud2"
IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
CLOUD_PRODUCERS = "from GetPointCloud, LoadPointCloudFromFile or another point cloud behavior"


def message_types() -> Any:
    """The message classes by type name (the transport's type table)."""
    from kinema.interfaces import load_interfaces

    return load_interfaces().typestore.types


def read_cloud(node: Any, port: str) -> Any:
    """The cloud on input port ``port`` as a :class:`kinema.perception.PointCloud`.

    Raises:
        PortValueError: no value, not a PointCloud2, or a PointCloud2 without x, y, z.
    """
    from kinema.perception.ros_messages import from_point_cloud2

    message = read_message(node, port, POINT_CLOUD)
    try:
        return from_point_cloud2(message)
    except KinemaError as error:
        raise port_error(node, port, str(error), CLOUD_PRODUCERS) from None


def cloud_message(cloud: Any) -> Any:
    """The ``sensor_msgs/PointCloud2`` of a :class:`kinema.perception.PointCloud`."""
    from kinema.perception.ros_messages import to_point_cloud2

    return to_point_cloud2(cloud, message_types())


def write_cloud(node: Any, port: str, cloud: Any) -> None:
    """Write ``cloud`` (a :class:`kinema.perception.PointCloud`) to output port ``port`` as a PointCloud2."""
    write_output(node, port, cloud_message(cloud))


def frame_of(cloud: Any) -> str:
    """The cloud's frame; an unlabelled cloud is in ``world``."""
    return cloud.frame_id or "world"


def target_T_source(node: Any, source: str, target: str, port: str, at: float = 0.0) -> np.ndarray:
    """The 4x4 transform taking points in ``source`` to ``target``, from the cell's frames now (or at
    stamp ``at``, a cloud's: a wrist camera's frame goes where the camera was when it was taken).

    Raises:
        PortValueError: either frame is unknown (the frame tree's message lists the known ones).
    """
    import numpy as np

    if source == target or {source, target} <= {"", "world"}:
        return np.eye(4)
    from ..poses.frame_tree import current_frame_tree

    try:
        return current_frame_tree(node, at=at).transform(np.eye(4), source, target)
    except KinemaError as error:
        raise port_error(node, port, f"cannot relate frame {source!r} to {target!r}: {error}", "") from None


def pose_in_frame(node: Any, port: str, frame: str) -> np.ndarray:
    """The PoseStamped on input port ``port`` as a 4x4 pose in ``frame``."""
    pose_frame, matrix = pose_matrix(read_message(node, port, POSE_STAMPED_TYPE), port)
    return target_T_source(node, pose_frame or "world", frame, port) @ matrix


def parse_color(node: Any, port: str, text: Any) -> tuple[int, int, int]:
    """``"r;g;b"`` (0-255 each) as a tuple.

    Raises:
        PortValueError: not three integers from 0 to 255.
    """
    from kinema.bt.conversions import split_string

    parts = text if isinstance(text, list | tuple) else split_string(str(text))
    try:
        values = tuple(int(float(v)) for v in parts)
    except (TypeError, ValueError):
        values = ()
    if len(values) != 3 or not all(0 <= v <= 255 for v in values):
        raise port_error(node, port, f"= {text!r}", "give three values 0-255 as r;g;b, e.g. 255;0;0")
    return values[0], values[1], values[2]
