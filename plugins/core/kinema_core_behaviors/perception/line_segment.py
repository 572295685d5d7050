"""FitLineSegmentToMask3D: the line segment an object's points lie along (a hinge, a lever handle), as the
two poses at its ends."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from ..messages.conversions import POSE_STAMPED_TYPE, pose_stamped_message
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_vector_output,
    port_error,
    read_input,
    read_message,
    write_output,
)
from .clouds import POINT_CLOUD, frame_of, read_cloud, target_T_source
from .masks import MASK3D, mask3d_indices


class FitLineSegmentToMask3D(SyncBehavior):
    """Fits a line segment to the points of ``point_cloud`` that ``mask3d`` lists and writes the poses at
    its two ends, in ``base_frame``, as ``line_segment_poses`` (start, end).

    The line is the one most of the points lie within ``max_distance_from_line_for_inlier`` of (RANSAC,
    seeded: the same points give the same segment); the segment spans its outermost inliers. It runs so its
    largest component is positive: a vertical hinge from bottom to top, a handle along world y towards +y.
    Each pose's x axis points along the segment, from start to end; z is the direction from the camera
    (the origin of the cloud's frame) to the segment, made square to it: into the surface the part is
    mounted on, the way a tool approaches it; y completes the frame. Both ends share that orientation.

    Fails when the mask has fewer than 2 distinct points, lists points the cloud does not have, or the
    distance is negative.
    """

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud the mask was made from."),
            message_input("mask3d", MASK3D, "{mask3d}", "The object's point indices."),
            input_port("base_frame", str, "world", "The frame the poses are expressed in."),
            input_port(
                "max_distance_from_line_for_inlier",
                float,
                0.02,
                "How far (m) from the line a point may lie and still be on the segment.",
            ),
            message_vector_output(
                "line_segment_poses",
                POSE_STAMPED_TYPE,
                "{line_segment_poses}",
                "The poses at the segment's start and end (x along it, z away from the camera).",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        from kinema.errors import PerceptionError
        from kinema.perception import fit_line_segment

        cloud = read_cloud(self, "point_cloud")
        base = str(read_input(self, "base_frame"))
        inlier = float(read_input(self, "max_distance_from_line_for_inlier"))
        indices = mask3d_indices(self, "mask3d", read_message(self, "mask3d", MASK3D), len(cloud))
        base_T_cloud = target_T_source(self, frame_of(cloud), base, "base_frame")
        points = cloud.transformed(base_T_cloud, base).points[indices].astype(float)
        try:
            segment = fit_line_segment(points, inlier)
        except PerceptionError as error:
            port = "max_distance_from_line_for_inlier" if "inlier distance" in str(error) else "mask3d"
            raise port_error(self, port, str(error), "") from None
        x = segment.direction
        sight = (segment.start + segment.end) / 2 - base_T_cloud[:3, 3]
        z = sight - x * float(sight @ x)
        if np.linalg.norm(z) < 1e-9:
            # Seen end-on: any direction square to the segment; the one nearest the frame's z.
            hint = np.array([0.0, 0.0, 1.0]) if abs(x[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
            z = hint - x * float(hint @ x)
        z /= np.linalg.norm(z)
        poses = []
        for end in (segment.start, segment.end):
            pose = np.eye(4)
            pose[:3, :3] = np.column_stack([x, np.cross(z, x), z])
            pose[:3, 3] = end
            poses.append(pose_stamped_message(base, pose))
        write_output(self, "line_segment_poses", poses)
        return NodeStatus.SUCCESS
