"""GetMasks3DFromMasks2D and GetPointCloudFromMask3D: image masks (from a segmentation model) become the
cloud points of each object.

A Mask2D marks an object's pixels; the Mask3D made of it lists the indices of the cloud's points that
fall on those pixels. An organised cloud of the camera's size maps pixel (u, v) to point ``v * width + u``;
any other cloud is projected into the image with the camera's intrinsics (it must be in the camera's
optical frame).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from ..files.image_file import image_pixels
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_output,
    port_error,
    read_message,
    read_vector,
    write_output,
)
from .clouds import CAMERA_INFO, POINT_CLOUD, read_cloud, write_cloud

MASK2D = "moveit_studio_vision_msgs/msg/Mask2D"
MASK3D = "moveit_studio_vision_msgs/msg/Mask3D"


def mask_layer(node: Any, port: str, index: int, mask: Any) -> np.ndarray:
    """The boolean image (its own height x width) of Mask2D ``mask``: True on the object's pixels.

    Raises:
        PortValueError: the element is not a Mask2D, or its image is malformed.
    """
    if getattr(mask, "__msgtype__", None) != MASK2D:
        raise port_error(
            node, port, f"element {index} is not a {MASK2D}", "give masks from a GetMasks2D behavior"
        )
    layer, _ = image_pixels(node, port, mask.mask)
    return layer > 0 if layer.ndim == 2 else layer.max(axis=2) > 0


def mask_image(node: Any, port: str, index: int, mask: Any, width: int, height: int) -> np.ndarray:
    """The HxW boolean image of Mask2D ``mask`` placed at its (x, y) offset in a ``width`` x ``height``
    image."""
    import numpy as np

    full = np.zeros((height, width), dtype=bool)
    x0, y0 = int(mask.x), int(mask.y)
    rows, cols = np.nonzero(mask_layer(node, port, index, mask))
    rows, cols = rows + y0, cols + x0
    inside = (rows >= 0) & (rows < height) & (cols >= 0) & (cols < width)
    full[rows[inside], cols[inside]] = True
    return full


def mask3d_indices(node: Any, port: str, mask3d: Any, cloud_size: int) -> np.ndarray:
    """The point indices of Mask3D ``mask3d`` (int64), checked against a cloud of ``cloud_size`` points.

    Raises:
        PortValueError: the mask lists a point the cloud does not have (it was made from another cloud).
    """
    import numpy as np

    indices = np.asarray(mask3d.point_indices, dtype=np.int64)
    if len(indices) and int(indices.max()) >= cloud_size:
        raise port_error(
            node,
            port,
            f"lists point {int(indices.max())}, the cloud has {cloud_size} points",
            "use the cloud the mask was made from (GetMasks3DFromMasks2D's point_cloud)",
        )
    return indices


class GetMasks3DFromMasks2D(SyncBehavior):
    """For each 2D mask of ``masks2d`` (on the image of the camera ``camera_info`` describes), the points of
    ``point_cloud`` on its pixels, as a Mask3D of point indices. Points the camera did not see (NaN) are
    left out. Fails when the cloud is organised at another size than the camera's image."""

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud the camera took."),
            message_input("camera_info", CAMERA_INFO, "{camera_info}", "The camera's intrinsics."),
            input_port("masks2d", None, "{masks2d}", "The image masks (std::vector<Mask2D>)."),
            output_port("masks3d", None, "{masks3d}", "A Mask3D per image mask (std::vector<Mask3D>)."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        from kinema.perception.ros_messages import intrinsics_of
        from kinema.transport import from_dict

        cloud = read_cloud(self, "point_cloud")
        camera = intrinsics_of(read_message(self, "camera_info", CAMERA_INFO))
        width, height = camera.width, camera.height
        finite = np.isfinite(cloud.points).all(axis=1)
        if cloud.shape is not None:
            if cloud.shape != (height, width):
                raise port_error(
                    self,
                    "point_cloud",
                    f"is organised {cloud.shape[1]}x{cloud.shape[0]}, the camera's image is {width}x{height}",
                    "give the cloud and camera_info of the same camera",
                )
            pixel_of = None
        else:
            in_front = finite & (cloud.points[:, 2] > 0)
            uv = np.full((len(cloud), 2), -1, dtype=np.int64)
            uv[in_front] = np.round(camera.project(cloud.points[in_front])).astype(np.int64)
            pixel_of = uv
        header = read_message(self, "point_cloud", POINT_CLOUD).header
        masks3d = []
        for index, mask in enumerate(read_vector(self, "masks2d")):
            image = mask_image(self, "masks2d", index, mask, width, height)
            if pixel_of is None:
                chosen = np.flatnonzero(image.reshape(-1) & finite)
            else:
                u, v = pixel_of[:, 0], pixel_of[:, 1]
                visible = (u >= 0) & (u < width) & (v >= 0) & (v < height)
                hits = np.zeros(len(cloud), dtype=bool)
                hits[visible] = image[v[visible], u[visible]]
                chosen = np.flatnonzero(hits & finite)
            masks3d.append(
                from_dict(
                    MASK3D,
                    {
                        "header": header,
                        "point_indices": chosen.astype(np.uint32),
                    },
                )
            )
        write_output(self, "masks3d", masks3d)
        return NodeStatus.SUCCESS


class GetPointCloudFromMask3D(SyncBehavior):
    """The points of ``point_cloud`` that ``mask3d`` lists (a fragment: one object's points). Fails naming
    the largest index when the mask was made from a bigger cloud."""

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud the mask was made from."),
            message_input("mask3d", MASK3D, "{mask3d}", "The object's point indices."),
            message_output(
                "point_cloud_fragment", POINT_CLOUD, "{point_cloud_fragment}", "The object's points."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        cloud = read_cloud(self, "point_cloud")
        indices = mask3d_indices(self, "mask3d", read_message(self, "mask3d", MASK3D), len(cloud))
        keep = np.zeros(len(cloud), dtype=bool)
        keep[indices] = True
        write_cloud(self, "point_cloud_fragment", cloud.select(keep).finite())
        return NodeStatus.SUCCESS
