"""GetContourFromPointCloudSlice: a path along a surface, from the outline of a slice of its cloud."""

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
from .clouds import POINT_CLOUD, frame_of, read_cloud, target_T_source


class GetContourFromPointCloudSlice(SyncBehavior):
    """Outlines the points of ``input_cloud`` within ``slice_distance_from_plane`` of ``slice_plane``'s x-y
    plane and writes poses along the outline to ``contour_path``.

    The outline is the convex hull of the slice projected onto the plane (``hull_alpha`` <= 0), or a
    concave hull: the boundary of the Delaunay triangles whose circumradius is at most ``hull_alpha`` m
    (PCL's ConcaveHull's alpha). It runs anticlockwise about the plane's z. With
    ``contour_crop_angle_span`` under 2 pi only the part between ``contour_crop_angle_start`` and start +
    span (rad, about the plane's origin from its x axis) is kept, from the start on. Poses are at most
    ``max_pose_spacing`` apart, on the plane, each with z along the outline's inward normal (a tool with
    that z faces the surface: PlanCartesianPath's ``tip_offset`` 0;0;d keeps it d away) and x along the
    travel; they are in ``slice_plane``'s frame. (MoveIt Pro's conventions are not public; these are
    Kinema's.) Fails with fewer than 3 points in the slice, or nothing of the outline in the angles.
    """

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("input_cloud", POINT_CLOUD, "{point_cloud}", "The cloud to slice."),
            message_input(
                "slice_plane",
                POSE_STAMPED_TYPE,
                "{slice_plane}",
                "The plane (its x-y plane), its origin the centre of the crop angles.",
            ),
            input_port(
                "slice_distance_from_plane", float, 0.05, "Points this close (m) to the plane are sliced."
            ),
            input_port(
                "hull_alpha",
                float,
                -1.0,
                "<= 0: convex hull; > 0: concave hull keeping triangles of circumradius up to this (m).",
            ),
            input_port("max_pose_spacing", float, 0.2, "Largest distance (m) between consecutive poses."),
            input_port(
                "contour_crop_angle_start",
                float,
                0.0,
                "Where the kept part begins (rad, about the plane's z from its x axis).",
            ),
            input_port(
                "contour_crop_angle_span",
                float,
                6.283185307179586,
                "How far the kept part reaches, anticlockwise (rad); 2 pi or more: the whole closed outline.",
            ),
            message_vector_output(
                "contour_path", POSE_STAMPED_TYPE, "{contour_path}", "Poses along the outline, in order."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.perception import slice_contour

        cloud = read_cloud(self, "input_cloud")
        try:
            frame, plane = pose_matrix(read_message(self, "slice_plane"), "slice_plane")
        except KinemaError as error:
            raise port_error(self, "slice_plane", str(error)) from None
        frame = frame or "world"
        points = cloud.transformed(target_T_source(self, frame_of(cloud), frame, "input_cloud"), frame).points
        try:
            poses = slice_contour(
                points,
                plane,
                float(read_input(self, "slice_distance_from_plane")),
                alpha=float(read_input(self, "hull_alpha")),
                max_spacing=float(read_input(self, "max_pose_spacing")),
                angle_start=float(read_input(self, "contour_crop_angle_start")),
                angle_span=float(read_input(self, "contour_crop_angle_span")),
            )
        except KinemaError as error:
            self.logger.publish_failure(f"GetContourFromPointCloudSlice: {error}")
            return NodeStatus.FAILURE
        self.set_output("contour_path", [pose_stamped_message(frame, pose) for pose in poses])
        return NodeStatus.SUCCESS
