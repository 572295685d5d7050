"""CreateCollisionSpheresAtClosestPoints: a cloud's points nearest a pose as a few collision spheres."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from ..messages.conversions import POSE_STAMPED_TYPE, pose_stamped_message
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_output,
    port_error,
    read_input,
    write_output,
)
from .clouds import POINT_CLOUD, frame_of, pose_in_frame, read_cloud

COLLISION_OBJECT = "moveit_msgs/msg/CollisionObject"


class CreateCollisionSpheresAtClosestPoints(SyncBehavior):
    """Spheres of ``sphere_radius`` at the ``closest_point_count`` points of ``point_cloud`` nearest to
    ``reference_pose``, among those inside a cylinder around the pose's z axis (``filter_cylinder_radius``,
    ``filter_cylinder_height`` centred on the pose). A cheap stand-in for a dense cloud near a tool.

    Writes one ``moveit_msgs/CollisionObject`` (id ``point_cloud_spheres``, in the cloud's frame); with
    ``debug_output_markers`` also the sphere poses and the marker scale, for PublishMarkers.
    """

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud."),
            message_input("reference_pose", POSE_STAMPED_TYPE, "{reference_pose}", "Where to look from."),
            input_port("closest_point_count", int, 100, "How many spheres at most."),
            input_port("sphere_radius", float, 0.01, "Radius of each sphere (m)."),
            input_port("filter_cylinder_radius", float, 1.0, "Radius of the cylinder points must be in (m)."),
            input_port(
                "filter_cylinder_height", float, 1.0, "Height of that cylinder along the pose's z (m)."
            ),
            input_port("debug_output_markers", bool, False, "Also write marker_poses and marker_scale_xyz."),
            message_output("collision_object", COLLISION_OBJECT, "{collision_object}", "The spheres."),
            output_port("marker_poses", None, "{marker_poses}", "Sphere centres (std::vector<PoseStamped>)."),
            output_port("marker_scale_xyz", None, "{marker_scale_xyz}", "Sphere diameter x;y;z for markers."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        from kinema.transport import from_dict

        cloud = read_cloud(self, "point_cloud").finite()
        frame = frame_of(cloud)
        reference = pose_in_frame(self, "reference_pose", frame)
        count = int(read_input(self, "closest_point_count"))
        radius = float(read_input(self, "sphere_radius"))
        cylinder_radius = float(read_input(self, "filter_cylinder_radius"))
        height = float(read_input(self, "filter_cylinder_height"))
        for port, value in (
            ("closest_point_count", count),
            ("sphere_radius", radius),
            ("filter_cylinder_radius", cylinder_radius),
            ("filter_cylinder_height", height),
        ):
            if not value > 0:
                raise port_error(self, port, f"= {value}", "give a value > 0")
        local = (cloud.points.astype(float) - reference[:3, 3]) @ reference[:3, :3]
        inside = (np.hypot(local[:, 0], local[:, 1]) <= cylinder_radius) & (np.abs(local[:, 2]) <= height / 2)
        candidates = cloud.points[inside].astype(float)
        distances = np.linalg.norm(candidates - reference[:3, 3], axis=1)
        closest = candidates[np.argsort(distances)[:count]]
        poses = [{"position": {"x": x, "y": y, "z": z}, "orientation": {"w": 1.0}} for x, y, z in closest]
        sphere = {"type": 2, "dimensions": [radius]}
        write_output(
            self,
            "collision_object",
            from_dict(
                COLLISION_OBJECT,
                {
                    "header": {"frame_id": frame},
                    "id": "point_cloud_spheres",
                    "primitives": [sphere] * len(poses),
                    "primitive_poses": poses,
                    "operation": 0,
                },
            ),
        )
        if bool(read_input(self, "debug_output_markers")):
            markers = []
            for point in closest:
                pose = np.eye(4)
                pose[:3, 3] = point
                markers.append(pose_stamped_message(frame, pose))
            write_output(self, "marker_poses", markers)
            write_output(self, "marker_scale_xyz", [2 * radius] * 3)
        return NodeStatus.SUCCESS
