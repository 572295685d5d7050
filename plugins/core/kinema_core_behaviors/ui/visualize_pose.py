"""VisualizePose: draw a pose as a coordinate triad in the viewer (a marker message on a topic)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import ObjectiveError
from kinema.ui_topics import MARKER_ARRAY_TOPIC, MARKER_ARRAY_TYPE

from ..messages.conversions import duration, pose_matrix

_AXES = ((1.0, 0.0, 0.0, 1.0), (0.0, 1.0, 0.0, 1.0), (0.0, 0.0, 1.0, 1.0))


def triad_markers(
    frame_id: str, matrix: np.ndarray, name: str, size: float, lifetime: float, text: str = ""
) -> dict[str, Any]:
    """A ``MarkerArray`` dict: three arrows (x red, y green, z blue) of length ``size``, plus a label."""
    origin = matrix[:3, 3]
    markers: list[dict[str, Any]] = []
    for axis, color in enumerate(_AXES):
        tip = origin + matrix[:3, axis] * size
        markers.append(
            {
                "header": {"frame_id": frame_id},
                "ns": name,
                "id": axis,
                "type": 0,  # ARROW, given by its two points
                "action": 0,
                "pose": {"orientation": {"w": 1.0}},
                "scale": {"x": size * 0.08, "y": size * 0.15, "z": size * 0.2},
                "color": dict(zip("rgba", color, strict=True)),
                "lifetime": duration(lifetime),
                "points": [
                    {"x": float(origin[0]), "y": float(origin[1]), "z": float(origin[2])},
                    {"x": float(tip[0]), "y": float(tip[1]), "z": float(tip[2])},
                ],
            }
        )
    if text:
        markers.append(
            {
                "header": {"frame_id": frame_id},
                "ns": name,
                "id": 3,
                "type": 9,  # TEXT_VIEW_FACING
                "action": 0,
                "pose": {
                    "position": {"x": float(origin[0]), "y": float(origin[1]), "z": float(origin[2] + size)},
                    "orientation": {"w": 1.0},
                },
                "scale": {"z": size * 0.3},
                "color": {"r": 1.0, "g": 1.0, "b": 1.0, "a": 1.0},
                "lifetime": duration(lifetime),
                "text": text,
            }
        )
    return {"markers": markers}


def publish_pose_marker(
    behavior: Any, pose: Any, name: str, size: float, lifetime: float, text: str = ""
) -> None:
    """Publish the triad of ``pose`` on the marker array topic through ``behavior``'s context."""
    from kinema.transport import from_dict

    frame_id, matrix = pose_matrix(pose, "pose")
    if size <= 0:
        raise ObjectiveError(f"marker_size must be > 0, got {size}")
    marker_publisher(behavior).publish(
        from_dict(MARKER_ARRAY_TYPE, triad_markers(frame_id, matrix, name, size, lifetime, text))
    )


def marker_publisher(behavior: Any, node: Any = None) -> Any:
    """The context's publisher of marker arrays (:mod:`kinema.ui_topics`), keeping all of them.

    A drawing the objective asked for (or a DELETE of one) must not be dropped when the link is busy,
    as a large snapshot cloud would be under load with ROS's default keep-last profile.
    """
    from kinema.transport import KEEP_ALL_QOS

    if node is None:
        node = behavior.context.require_node(behavior.registration_id)
    return behavior.context.publisher(node, MARKER_ARRAY_TYPE, MARKER_ARRAY_TOPIC, qos=KEEP_ALL_QOS)


class VisualizePose(SyncBehavior):
    """Publishes ``pose`` as a coordinate triad named ``marker_name`` for the viewer to draw.

    The markers go to ``/visualization_marker_array`` (``visualization_msgs/MarkerArray``, one arrow per
    axis); a marker with the same name replaces the previous one; ``marker_lifetime`` 0 keeps it.
    """

    subcategory = "User Interface"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("pose", None, "{pose}", "The pose to draw (geometry_msgs/PoseStamped)."),
            input_port("marker_name", str, "pose", "Name of the marker (a new pose replaces the old one)."),
            input_port("marker_lifetime", float, 0.0, "Seconds the marker stays (0: until replaced)."),
            input_port("marker_size", float, 0.1, "Length of the triad's arrows (m)."),
            input_port("marker_text", str, "", "Label drawn next to the pose."),
        ]

    def tick(self) -> NodeStatus:
        try:
            publish_pose_marker(
                self,
                self.get_input("pose"),
                str(self.get_input("marker_name")),
                float(self.get_input("marker_size")),
                float(self.get_input("marker_lifetime")),
                str(self.get_input_or("marker_text", "")),
            )
        except ObjectiveError as error:
            self.logger.publish_failure(f"VisualizePose: {error}")
            return NodeStatus.FAILURE
        return NodeStatus.SUCCESS
