"""Point clouds in ``kinema view``: SendPointCloudToUI, PublishPointCloud and ClearSnapshot.

The view draws markers, so a cloud is drawn as a POINTS marker (at most ``MAX_DRAWN_POINTS``, evenly
sub-sampled, each point in the cloud's colour or, without colours, coloured by height) in the
``snapshot`` namespace; the cloud itself is also published on its topic for other subscribers.
ClearSnapshot deletes the drawn snapshots and, as MoveIt Pro's clears its octomap, the obstacles
UpdatePlanningSceneService made of a cloud.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import BehaviorContext, NodeStatus, PortInfo, SyncBehavior, input_port

from ..messages.ports import fails_on_bad_input, message_input, port_error, read_input, read_message
from .markers import publish_markers

# UpdatePlanningSceneService's world object (named here to keep ui free of the perception family).
OCTOMAP_ID = "octomap"

POINT_CLOUD = "sensor_msgs/msg/PointCloud2"
SNAPSHOT_NAMESPACE = "snapshot"
MAX_DRAWN_POINTS = 20000


class _Snapshots:
    """The highest snapshot marker id drawn in a cell (-1: none), kept in its behavior context."""

    def __init__(self) -> None:
        self.last_id = -1


def _snapshots(context: BehaviorContext) -> _Snapshots:
    return context.shared("ui.point_cloud_snapshots", _Snapshots)


def height_colors(xyz: np.ndarray) -> np.ndarray:
    """Nx3 colours (0..1) for a cloud without its own: blue at its lowest point to yellow at its highest."""
    import numpy as np

    z = xyz[:, 2] if len(xyz) else np.zeros(0)
    span = float(z.max() - z.min()) if len(z) else 0.0
    t = (z - z.min()) / span if span > 0 else np.zeros_like(z)
    low, high = np.array([0.15, 0.35, 0.95]), np.array([1.0, 0.85, 0.1])
    return low + np.outer(t, high - low)


def cloud_marker(
    xyz: np.ndarray, frame_id: str, marker_id: int, colors: np.ndarray | None = None
) -> dict[str, Any]:
    """A POINTS marker of the cloud, sub-sampled evenly to at most MAX_DRAWN_POINTS so the view stays
    smooth, each point in its own colour (``colors``: Nx3 uint8 RGB; by height when None)."""
    import numpy as np

    if len(xyz) > MAX_DRAWN_POINTS:
        keep = np.linspace(0, len(xyz) - 1, MAX_DRAWN_POINTS).astype(int)
        xyz = xyz[keep]
        colors = None if colors is None else colors[keep]
    shades = height_colors(xyz) if colors is None else np.asarray(colors, dtype=float) / 255.0
    from kinema.interfaces import load_interfaces

    types = load_interfaces().typestore.types
    point, color = types["geometry_msgs/msg/Point"], types["std_msgs/msg/ColorRGBA"]
    return {
        "header": {"frame_id": frame_id},
        "ns": SNAPSHOT_NAMESPACE,
        "id": marker_id,
        "type": 8,  # POINTS
        "action": 0,
        "pose": {"orientation": {"w": 1.0}},
        "scale": {"x": 0.005, "y": 0.005},
        "color": {"r": 0.9, "g": 0.9, "b": 0.9, "a": 1.0},
        # Message objects rather than dicts: converting 20,000 point dicts took 1.5 s, these 0.1 s.
        "points": [point(x=x, y=y, z=z) for x, y, z in np.asarray(xyz, dtype=float).tolist()],
        "colors": [color(r=r, g=g, b=b, a=1.0) for r, g, b in shades.tolist()],
    }


def _publish_cloud(behavior: Any, cloud: Any, topic: str) -> None:
    """Publish ``cloud`` keeping all: a snapshot of several MB dropped under load would never arrive."""
    from kinema.transport import KEEP_ALL_QOS

    node = behavior.context.require_node(behavior.registration_id)
    behavior.context.publisher(node, POINT_CLOUD, topic, qos=KEEP_ALL_QOS).publish(cloud)


def _draw(behavior: Any, cloud: Any, *, keep_previous: bool) -> None:
    from kinema.perception.ros_messages import from_point_cloud2

    try:
        points = from_point_cloud2(cloud).finite()
    except Exception as error:
        raise port_error(behavior, "point_cloud", str(error), "") from None
    snapshots = _snapshots(behavior.context)
    marker_id = snapshots.last_id + 1 if keep_previous else 0
    snapshots.last_id = marker_id
    marker = cloud_marker(points.points, str(cloud.header.frame_id) or "world", marker_id, points.colors)
    publish_markers(behavior, [marker])


class SendPointCloudToUI(SyncBehavior):
    """Shows a point cloud as a snapshot in ``kinema view`` (kept until ClearSnapshot) and publishes it."""

    subcategory = "User Interface"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud to show."),
            input_port("pcd_topic", str, "/pcd_pointcloud_captures", "Topic the cloud is published on."),
            input_port(
                "use_latest_transform",
                bool,
                False,
                "MoveIt Pro transforms with the latest TF instead of the cloud's stamp; Kinema's frames "
                "are always current, so it changes nothing.",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        cloud = read_message(self, "point_cloud")
        _draw(self, cloud, keep_previous=True)
        _publish_cloud(self, cloud, str(read_input(self, "pcd_topic")))
        return NodeStatus.SUCCESS


class PublishPointCloud(SyncBehavior):
    """Publishes a point cloud on ``point_cloud_topic``; draws it in ``kinema view``, replacing the last."""

    subcategory = "User Interface"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud to publish."),
            input_port("point_cloud_topic", str, "/point_cloud", "Topic to publish on."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        cloud = read_message(self, "point_cloud")
        _draw(self, cloud, keep_previous=False)
        _publish_cloud(self, cloud, str(read_input(self, "point_cloud_topic")))
        return NodeStatus.SUCCESS


class ClearSnapshot(SyncBehavior):
    """Removes the point cloud snapshots SendPointCloudToUI drew in ``kinema view``, and the obstacles
    UpdatePlanningSceneService added from a cloud (the ``octomap`` world object)."""

    subcategory = "User Interface"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return []

    def tick(self) -> NodeStatus:
        snapshots = _snapshots(self.context)
        count, snapshots.last_id = snapshots.last_id + 1, -1
        markers = [{"ns": SNAPSHOT_NAMESPACE, "id": i, "action": 2} for i in range(max(count, 1))]
        publish_markers(self, markers)
        scene = self.context.loaded_planning_scene
        if scene is not None and OCTOMAP_ID in scene.world:
            scene.remove_world_object(OCTOMAP_ID)
        return NodeStatus.SUCCESS
