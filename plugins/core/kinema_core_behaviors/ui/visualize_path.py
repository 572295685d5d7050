"""VisualizePath: draw a path of poses (a coverage raster, a contour, a Cartesian plan's waypoints)."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import KinemaError

from ..messages.conversions import duration, pose_matrix
from ..messages.ports import fails_on_bad_input, port_error, read_input, read_vector
from .markers import publish_markers
from .visualize_pose import triad_markers

_LINE_COLOR = {"r": 1.0, "g": 0.55, "b": 0.0, "a": 1.0}
# The most markers a path of this name drew (line + three arrows a pose), per context: a shorter path
# deletes the rest.
_DRAWN = "visualize_path_drawn"


def world_poses(behavior: Any, poses: list[Any], port: str) -> tuple[str, list[Any]]:
    """``(frame, 4x4 poses)`` of a path: in the poses' frame when they share one the view can draw in
    (``world`` or empty), else all brought into the world through the cell's frames now.

    Raises:
        PortValueError: an element is not a PoseStamped, or its frame is unknown to the cell.
    """
    from ..poses.frame_tree import current_frame_tree

    placed = []
    for index, pose in enumerate(poses):
        try:
            placed.append(pose_matrix(pose, f"{port}[{index}]"))
        except KinemaError as error:
            raise port_error(
                behavior, port, f"element {index}: {error}", "give PoseStamped messages"
            ) from None
    if all(frame in ("", "world") for frame, _ in placed):
        return "world", [matrix for _, matrix in placed]
    try:
        tree = current_frame_tree(behavior)
        return "world", [tree.transform(matrix, frame, "world") for frame, matrix in placed]
    except KinemaError as error:
        raise port_error(behavior, port, f"cannot be placed in the world: {error}", "") from None


class VisualizePath(SyncBehavior):
    """Draws ``path`` (PoseStamped waypoints) in ``kinema view`` as a line through the poses, and with
    ``show_poses`` a coordinate triad of ``pose_marker_size`` at each pose.

    The markers go to ``/visualization_marker_array`` under the namespace ``marker_name``: a new path of
    the same name replaces the old one (a shorter one removes the rest); ``marker_lifetime`` 0 keeps it.
    Poses in robot links or other frames of the cell are placed where those frames are now. Fails on an
    empty path or an element that is not a PoseStamped.
    """

    subcategory = "User Interface"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("path", None, "{path}", "The poses (a vector of geometry_msgs/PoseStamped)."),
            input_port("marker_name", str, "path", "Namespace of the markers (a new path replaces the old)."),
            input_port("marker_lifetime", float, 0.0, "Seconds the path stays (0: until replaced)."),
            input_port(
                "show_poses",
                bool,
                True,
                "Also draw each pose's axes (MoveIt Pro's default is not public; Kinema's: true).",
            ),
            input_port(
                "pose_marker_size",
                float,
                0.05,
                "Length (m) of each pose's axes (MoveIt Pro's default is not public; Kinema's: 0.05).",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        poses = read_vector(self, "path")
        if not poses:
            raise port_error(self, "path", "is an empty vector", "give one or more poses")
        name = str(read_input(self, "marker_name"))
        lifetime = max(float(read_input(self, "marker_lifetime")), 0.0)
        size = float(read_input(self, "pose_marker_size"))
        show = bool(read_input(self, "show_poses"))
        if show and not size > 0:
            raise port_error(self, "pose_marker_size", f"= {size:g}", "give a size > 0 m, e.g. 0.05")
        frame, matrices = world_poses(self, poses, "path")
        markers: list[dict[str, Any]] = [
            {
                "header": {"frame_id": frame},
                "ns": name,
                "id": 0,
                "type": 4,  # LINE_STRIP
                "action": 0,
                "pose": {"orientation": {"w": 1.0}},
                "scale": {"x": 0.005},
                "color": _LINE_COLOR,
                "lifetime": duration(lifetime),
                "points": [{"x": float(m[0, 3]), "y": float(m[1, 3]), "z": float(m[2, 3])} for m in matrices],
            }
        ]
        if show:
            for index, matrix in enumerate(matrices):
                for k, arrow in enumerate(triad_markers(frame, matrix, name, size, lifetime)["markers"]):
                    arrow["id"] = 1 + 3 * index + k
                    markers.append(arrow)
        drawn = self.context.shared(_DRAWN, dict)
        count, before = len(markers), drawn.get(name, 0)
        markers += [
            {"header": {"frame_id": frame}, "ns": name, "id": i, "action": 2}  # DELETE
            for i in range(count, before)
        ]
        drawn[name] = count
        publish_markers(self, markers)
        return NodeStatus.SUCCESS
