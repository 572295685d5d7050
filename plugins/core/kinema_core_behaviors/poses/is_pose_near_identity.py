"""IsPoseNearIdentity: is a pose (an error or offset between two poses) close to no motion at all?"""

from __future__ import annotations

import math

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from ..messages.conversions import POSE_STAMPED_TYPE
from ..messages.ports import fails_on_bad_input, message_input, port_error, read_input, read_message


class IsPoseNearIdentity(SyncBehavior):
    """Succeeds when ``pose`` is within ``position_tolerance`` and ``rotation_tolerance`` of the identity.

    The distance is the norm of the pose's translation (m) and the angle of its rotation (rad, in [0, pi],
    whichever sign the quaternion has); both limits are inclusive and the frame is not looked at. Use it
    on an error pose, e.g. a tracked target relative to the tool, to wait until they line up. Otherwise it
    fails, saying which tolerance was exceeded and by how much, as an info message: the usual use is a
    condition polled in a RetryUntilSuccessful loop, where not being there yet is no error. An all-zero
    orientation reads as the identity (kinema.transforms' rule for an unset quaternion); a negative
    tolerance or a NaN in the pose fails with a failure message.
    """

    subcategory = "Math - Poses"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("pose", POSE_STAMPED_TYPE, "{pose}", "The pose to compare with the identity."),
            input_port(
                "position_tolerance", float, 0.01, "Largest translation norm (m) that counts as near."
            ),
            input_port(
                "rotation_tolerance", float, 0.01, "Largest rotation angle (rad) that counts as near."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema import transforms

        pose = read_message(self, "pose").pose
        limits = {}
        for port in ("position_tolerance", "rotation_tolerance"):
            limits[port] = float(read_input(self, port))
            if not limits[port] >= 0:
                raise port_error(self, port, f"= {limits[port]:g}", "a tolerance must be >= 0")
        p, q = pose.position, pose.orientation
        distance = math.sqrt(p.x * p.x + p.y * p.y + p.z * p.z)
        try:
            angle = transforms.angle_between((0.0, 0.0, 0.0, 1.0), (q.x, q.y, q.z, q.w))
        except transforms.TransformError as error:
            raise port_error(self, "pose", f"has an unusable orientation: {error}") from None
        if not math.isfinite(distance):
            raise port_error(self, "pose", f"has a position with a NaN or infinity: {p.x}, {p.y}, {p.z}")
        exceeded = []
        if distance > limits["position_tolerance"]:
            exceeded.append(
                f"translation {distance:.4g} m exceeds position_tolerance {limits['position_tolerance']:g} m"
            )
        if angle > limits["rotation_tolerance"]:
            exceeded.append(
                f"rotation {angle:.4g} rad exceeds rotation_tolerance {limits['rotation_tolerance']:g} rad"
            )
        if not exceeded:
            return NodeStatus.SUCCESS
        self.logger.publish_info(f"IsPoseNearIdentity: pose is not near identity: {'; '.join(exceeded)}")
        return NodeStatus.FAILURE
