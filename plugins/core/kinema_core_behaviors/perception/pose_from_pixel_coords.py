"""GetPoseFromPixelCoords: a pose on the surface a camera's cloud shows at each clicked pixel."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import PerceptionError

from ..messages.conversions import POSE_STAMPED_TYPE, pose_stamped_message
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_vector_output,
    port_error,
    read_input,
    read_vector,
    write_output,
)
from .clouds import POINT_CLOUD, read_cloud

POINT_STAMPED = "geometry_msgs/msg/PointStamped"


class GetPoseFromPixelCoords(SyncBehavior):
    """For each pixel of ``pixel_coords`` (as GetPointsFromUser writes them), the pose on the surface that
    ``point_cloud`` shows there, in the cloud's frame, in the order of the pixels.

    The cloud must be organised (one point per pixel, as a depth camera's cloud from GetPointCloud is):
    pixel (u, v), rounded to the nearest whole pixel, is its point ``v * width + u``. The pose is at that
    point; its z axis is the surface normal pointing out of the surface, towards the cloud frame's origin
    (the camera, for the camera's own cloud); its x axis is the cloud frame's x (image right) laid into the
    surface, its y completes the frame (image up, for a surface facing the camera). So TransformPose's
    ``translation_xyz`` 0;0;d gives a pose d in front of the surface on the camera's side (push_button.xml's
    approach, 0.1 m out), and its ``quaternion_xyzw`` 0.7071;0.7071;0;0 (half a turn about the x+y
    diagonal) points the approach's z into the surface and swaps x and y: a tool frame sent there faces the
    surface from 0.1 m out, the convention the objective implies. The normal is fitted (PCA) to
    the points within ``neighbor_radius`` of the pixel's point, taken from ``downsample_fraction``
    of the cloud's points spread evenly over it.

    Fails naming the pixel when it lies outside the image, the camera saw nothing there (NaN), or too few
    points around it fit a surface; fails when the cloud is not organised or no pixel is given.
    """

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "point_cloud",
                POINT_CLOUD,
                "{point_cloud}",
                "The camera's organised cloud, in its own frame (the normals face this frame's origin).",
            ),
            input_port(
                "pixel_coords",
                None,
                "{pixel_coords}",
                "The pixels, from GetPointsFromUser (std::vector<geometry_msgs/PointStamped>: x the column, "
                "y the row, rounded to the nearest pixel; a header's frame_id names the point in messages).",
            ),
            input_port(
                "downsample_fraction",
                float,
                0.1,
                "Fraction (0, 1] of the cloud's points, spread evenly over it, searched for a pixel's "
                "neighbours: smaller is faster, larger fits small surfaces better.",
            ),
            input_port(
                "neighbor_radius",
                float,
                0.1,
                "Distance (m) from a pixel's point within which the kept points fit its surface normal.",
            ),
            message_vector_output(
                "output_poses",
                POSE_STAMPED_TYPE,
                "{output_poses}",
                "A pose a pixel, in order, in the cloud's frame: at the pixel's point, z out of the surface.",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        from kinema.perception import pose_on_surface, surface_normal

        cloud = read_cloud(self, "point_cloud")
        if cloud.shape is None:
            raise port_error(
                self,
                "point_cloud",
                f"is unorganised ({len(cloud)} points in one row), so it has no pixels",
                "give the camera's organised cloud from GetPointCloud, before any crop or filter",
            )
        height, width = cloud.shape
        fraction = float(read_input(self, "downsample_fraction"))
        if not 0.0 < fraction <= 1.0:
            raise port_error(
                self, "downsample_fraction", f"= {fraction:g}", "give a fraction of the points in (0, 1]"
            )
        radius = float(read_input(self, "neighbor_radius"))
        if not radius > 0.0:
            raise port_error(self, "neighbor_radius", f"= {radius:g}", "give a distance in metres above 0")
        pixels = read_vector(self, "pixel_coords")
        if not pixels:
            raise port_error(self, "pixel_coords", "is empty", "give at least one pixel (GetPointsFromUser)")
        finite = cloud.points[np.isfinite(cloud.points).all(axis=1)].astype(float)
        # evenly spread, so the kept points cover the whole image as the full cloud does
        count = round(fraction * len(finite))
        kept = finite[np.unique(np.linspace(0, len(finite) - 1, count).round().astype(np.int64))]
        poses = []
        for index, pixel in enumerate(pixels):
            u, v, name = self._pixel(index, pixel)
            where = f"pixel {index}{f' ({name})' if name else ''} at column {u}, row {v}"
            if not (0 <= u < width and 0 <= v < height):
                raise port_error(
                    self,
                    "pixel_coords",
                    f"{where} is outside the cloud's {width}x{height} image",
                    f"give columns 0..{width - 1} and rows 0..{height - 1} of the cloud's camera",
                )
            point = cloud.points[v * width + u].astype(float)
            if not np.isfinite(point).all():
                raise port_error(
                    self,
                    "pixel_coords",
                    f"{where}: the camera saw nothing there (NaN)",
                    "click on a surface the camera sees",
                )
            near = kept[np.linalg.norm(kept - point, axis=1) <= radius]
            try:
                normal = surface_normal(np.vstack([point, near]), np.zeros(3))
            except PerceptionError as error:
                raise port_error(
                    self,
                    "pixel_coords",
                    f"{where}: within neighbor_radius {radius:g} m of its point, {error}",
                    "raise neighbor_radius or downsample_fraction",
                ) from None
            poses.append(pose_stamped_message(cloud.frame_id, pose_on_surface(point, normal)))
        write_output(self, "output_poses", poses)
        return NodeStatus.SUCCESS

    def _pixel(self, index: int, pixel: Any) -> tuple[int, int, str]:
        """``(column, row, name)`` of element ``index``, a PointStamped (its point's x, y; its frame_id)."""
        import math

        if getattr(pixel, "__msgtype__", None) != POINT_STAMPED:
            raise port_error(
                self,
                "pixel_coords",
                f"element {index} is not a {POINT_STAMPED}",
                "give the pixel_coords GetPointsFromUser writes",
            )
        x, y = float(pixel.point.x), float(pixel.point.y)
        if not (math.isfinite(x) and math.isfinite(y)):
            raise port_error(self, "pixel_coords", f"element {index} is at ({x}, {y})", "give finite pixels")
        return math.floor(x + 0.5), math.floor(y + 0.5), str(pixel.header.frame_id)
