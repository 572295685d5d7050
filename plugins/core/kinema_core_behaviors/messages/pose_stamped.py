"""CreatePoseStamped: a stamped pose from a frame, a position and a quaternion."""

from __future__ import annotations

import numpy as np

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from .conversions import pose_stamped_message


def pose_from_ports(position: list[float], orientation: list[float], what: str) -> np.ndarray | str:
    """A 4x4 transform from ``x;y;z`` and ``x;y;z;w``, or the reason it cannot be built."""
    from scipy.spatial.transform import Rotation

    if len(position) != 3:
        return f"{what} position must have 3 values (x;y;z), got {len(position)}"
    if len(orientation) != 4:
        return f"{what} orientation must have 4 values (x;y;z;w), got {len(orientation)}"
    quaternion = np.asarray(orientation, dtype=float)
    norm = float(np.linalg.norm(quaternion))
    if norm < 1e-9:
        return f"{what} orientation is a zero quaternion"
    matrix = np.eye(4)
    matrix[:3, :3] = Rotation.from_quat(quaternion / norm).as_matrix()
    matrix[:3, 3] = position
    return matrix


class CreatePoseStamped(SyncBehavior):
    """Writes a ``geometry_msgs/PoseStamped`` in ``reference_frame`` (the quaternion is normalised)."""

    subcategory = "Math - Poses"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("reference_frame", str, "world", "Frame the pose is expressed in."),
            input_port("position_xyz", list[float], "0.0;0.0;0.0", "Position x;y;z (m)."),
            input_port("orientation_xyzw", list[float], "0.0;0.0;0.0;1.0", "Orientation quaternion x;y;z;w."),
            output_port("pose_stamped", None, "{pose_stamped}", "The pose (geometry_msgs/PoseStamped)."),
        ]

    def tick(self) -> NodeStatus:
        matrix = pose_from_ports(
            list(self.get_input("position_xyz")),
            list(self.get_input("orientation_xyzw")),
            "CreatePoseStamped:",
        )
        if isinstance(matrix, str):
            self.logger.publish_failure(matrix)
            return NodeStatus.FAILURE
        self.set_output("pose_stamped", pose_stamped_message(str(self.get_input("reference_frame")), matrix))
        return NodeStatus.SUCCESS
