"""ReversePoseStampedVector: the poses of a vector in the opposite order."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior

from ..messages.conversions import POSE_STAMPED_TYPE
from ..messages.ports import (
    fails_on_bad_input,
    message_vector_input,
    message_vector_output,
    read_vector,
    write_output,
)


class ReversePoseStampedVector(SyncBehavior):
    """Writes the poses of ``input_vector`` to ``output_vector`` last first.

    ``output_vector`` may be the same blackboard entry as ``input_vector`` (MoveIt Pro's surface-raster
    objectives reverse a contour in place so passes alternate direction). An empty vector gives an empty
    vector. Fails, naming the port, when the vector holds something else than poses.
    """

    subcategory = "Vector Handling"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_vector_input(
                "input_vector", POSE_STAMPED_TYPE, "{input_vector}", "The poses to reverse."
            ),
            message_vector_output(
                "output_vector",
                POSE_STAMPED_TYPE,
                "{output_vector}",
                "The same poses in reverse order (may be the input's entry).",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        poses = read_vector(self, "input_vector")
        write_output(self, "output_vector", poses[::-1])
        return NodeStatus.SUCCESS
