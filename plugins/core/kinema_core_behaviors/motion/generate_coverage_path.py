"""GenerateCoveragePath: a raster of poses that sweeps a rectangle (painting, spraying, inspecting)."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import KinemaError

from ..messages.conversions import POSE_STAMPED_TYPE, pose_matrix, pose_stamped_message
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_vector_output,
    port_error,
    read_input,
    read_message,
)


class GenerateCoveragePath(SyncBehavior):
    """Writes to ``vector_of_poses`` a back-and-forth raster over a ``width`` x ``height`` rectangle whose
    bottom-right corner is ``bottom_right_corner``.

    The rectangle lies in the corner pose's x-y plane: seen from the corner's +z side with x to the right
    and y up, it spans ``width`` to the left (-x) and ``height`` up (+y). Passes run along the width, one
    every ``stride_distance`` (the last on the top edge), alternating direction; the poses are each pass's
    two ends, in the corner's frame, with the corner's orientation (a tool whose z is the corner's z faces
    the surface all along). PlanCartesianPath joins them with straight lines. Nothing checks that the
    robot can reach them. (MoveIt Pro's axes and defaults are not public; these are Kinema's.) Fails on a
    width or stride that is not > 0, a negative height, or more than 10000 passes.
    """

    subcategory = "Motion - Planning"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "bottom_right_corner",
                POSE_STAMPED_TYPE,
                "{bottom_right_corner}",
                "The rectangle's bottom-right corner; its x-y plane is the rectangle's.",
            ),
            input_port("width", float, 1.0, "Length of each pass (m), along the corner's -x."),
            input_port("height", float, 1.0, "Extent the passes cover (m), along the corner's +y."),
            input_port("stride_distance", float, 0.1, "Distance between passes (m)."),
            message_vector_output(
                "vector_of_poses", POSE_STAMPED_TYPE, "{vector_of_poses}", "The passes' ends, in order."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.motion.coverage import raster_poses

        try:
            frame, corner = pose_matrix(read_message(self, "bottom_right_corner"), "bottom_right_corner")
        except KinemaError as error:
            raise port_error(self, "bottom_right_corner", str(error)) from None
        width, height, stride = (float(read_input(self, p)) for p in ("width", "height", "stride_distance"))
        try:
            poses = raster_poses(corner, width, height, stride)
        except KinemaError as error:
            self.logger.publish_failure(f"GenerateCoveragePath: {error}")
            return NodeStatus.FAILURE
        self.set_output("vector_of_poses", [pose_stamped_message(frame, pose) for pose in poses])
        return NodeStatus.SUCCESS
