"""PublishMarkers and VisualizeMesh: draw shapes and meshes in ``kinema view`` (RViz marker topics)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.config.robot_files import is_lfs_pointer

from ..files.locations import file_to_read, split_package_uri
from ..messages.conversions import duration, pose_matrix
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    port_error,
    read_input,
    read_message,
    read_vector,
)
from .visualize_pose import MARKER_ARRAY_TYPE, marker_publisher

MARKER_TYPES = {"arrow": 0, "cube": 1, "sphere": 2, "cylinder": 3}
_COLOR = {"r": 0.2, "g": 0.6, "b": 1.0, "a": 0.8}


def publish_markers(behavior: Any, markers: list[dict[str, Any]]) -> None:
    """Publish ``markers`` (Marker dicts) as one MarkerArray on the view's marker topic."""
    from kinema.transport import from_dict

    marker_publisher(behavior).publish(from_dict(MARKER_ARRAY_TYPE, {"markers": markers}))


def pose_dict(frame_and_matrix: tuple[str, np.ndarray]) -> tuple[str, dict[str, Any]]:
    """``(frame_id, Pose dict)`` of a ``(frame_id, 4x4 transform)``."""
    from kinema import transforms

    frame, matrix = frame_and_matrix
    return frame, transforms.pose_dict(matrix)


def _scales(behavior: Any, value: Any, count: int) -> list[list[float]]:
    items = value if isinstance(value, list | tuple) else [value]
    if len(items) == 3 and all(isinstance(v, int | float) for v in items):
        return [[float(v) for v in items]] * count
    scales = []
    for item in items:
        if hasattr(item, "x"):
            scales.append([float(item.x), float(item.y), float(item.z)])
        elif isinstance(item, list | tuple) and len(item) == 3:
            scales.append([float(v) for v in item])
        else:
            raise port_error(
                behavior, "marker_scale_xyz", f"holds {item!r}", "expected x;y;z or one per pose"
            )
    if len(scales) == 1:
        return scales * count
    if len(scales) != count:
        raise port_error(
            behavior,
            "marker_scale_xyz",
            f"has {len(scales)} scales for {count} poses",
            "give one, or one per pose",
        )
    return scales


class PublishMarkers(SyncBehavior):
    """Draws a marker (arrow, cube, sphere or cylinder) at each of ``marker_poses`` in ``kinema view``."""

    subcategory = "User Interface"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("marker_type", str, "sphere", f"Shape: {', '.join(MARKER_TYPES)}."),
            input_port(
                "marker_namespace", str, "markers", "Namespace; a marker replaces the one of same index."
            ),
            input_port("marker_scale_xyz", None, "0.05;0.05;0.05", "Size x;y;z (m), or one per pose."),
            input_port("marker_poses", None, "{marker_poses}", "Poses (geometry_msgs/PoseStamped vector)."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        kind = str(read_input(self, "marker_type")).strip().lower()
        if kind not in MARKER_TYPES:
            raise port_error(self, "marker_type", f"= {kind!r}", f"valid: {', '.join(MARKER_TYPES)}")
        poses = read_vector(self, "marker_poses")
        scale_value = read_input(self, "marker_scale_xyz")
        if isinstance(scale_value, str):
            from kinema.bt.conversions import convert_from_string

            scale_value = convert_from_string(list[float], scale_value)
        scales = _scales(self, scale_value, len(poses))
        namespace = str(read_input(self, "marker_namespace"))
        markers: list[dict[str, Any]] = []
        for index, (pose, scale) in enumerate(zip(poses, scales, strict=True)):
            try:
                frame, pose_fields = pose_dict(pose_matrix(pose, f"marker_poses[{index}]"))
            except Exception as error:
                raise port_error(self, "marker_poses", f"element {index}: {error}", "") from None
            markers.append(
                {
                    "header": {"frame_id": frame},
                    "ns": namespace,
                    "id": index,
                    "type": MARKER_TYPES[kind],
                    "action": 0,
                    "pose": pose_fields,
                    "scale": dict(zip("xyz", scale, strict=True)),
                    "color": _COLOR,
                }
            )
        publish_markers(self, markers)
        return NodeStatus.SUCCESS


class VisualizeMesh(SyncBehavior):
    """Draws the mesh file ``mesh_path`` (STL, OBJ or DAE) at ``mesh_pose`` in ``kinema view``.

    Relative paths are in the objectives folder; ``package://<pkg>/<path>`` names a file of a package. A
    Git LFS pointer file (a clone without ``git lfs pull``) draws nothing, with a warning, and succeeds.
    """

    subcategory = "User Interface"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("mesh_path", str, "", "The mesh file."),
            message_input("mesh_pose", "geometry_msgs/msg/PoseStamped", "{mesh_pose}", "Where to draw it."),
            input_port("mesh_name", str, "mesh", "Name (a new mesh of the same name replaces it)."),
            input_port("marker_lifetime", float, 0.0, "Seconds the mesh stays (0 = until replaced)."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        package, text = split_package_uri(str(read_input(self, "mesh_path")))
        path = file_to_read(self, "mesh_path", text, package, lfs_pointer_ok=True)
        if path.suffix.lower() not in (".stl", ".obj", ".dae"):
            raise port_error(self, "mesh_path", f"= {str(path)!r}", "give an .stl, .obj or .dae file")
        if is_lfs_pointer(path):
            # Only a picture: the objective goes on (MoveIt Pro's lab_sim ships its meshes through LFS).
            self.logger.publish_warn(
                f"VisualizeMesh: {path} is a Git LFS pointer file, not the mesh: nothing drawn (run `git lfs "
                "pull` in its repository)"
            )
            return NodeStatus.SUCCESS
        frame, pose_fields = pose_dict(pose_matrix(read_message(self, "mesh_pose"), "mesh_pose"))
        marker = {
            "header": {"frame_id": frame},
            "ns": str(read_input(self, "mesh_name")),
            "id": 0,
            "type": 10,  # MESH_RESOURCE
            "action": 0,
            "pose": pose_fields,
            "scale": {"x": 1.0, "y": 1.0, "z": 1.0},
            "color": {"r": 0.8, "g": 0.8, "b": 0.8, "a": 1.0},
            "lifetime": duration(max(float(read_input(self, "marker_lifetime")), 0.0)),
            "mesh_resource": Path(path).resolve().as_uri(),
        }
        publish_markers(self, [marker])
        return NodeStatus.SUCCESS
