"""PublishMask2D and PublishBoundingBoxes2D: 2D detections drawn onto the image, published as an image.

``kinema view`` is a 3D view and shows no camera images, so these behaviors publish the annotated
``sensor_msgs/Image`` on a topic for image viewers (``rqt_image_view``, ``ros2 topic``); that is as far
as Kinema's UIs go today.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

from ..files.image_file import image_message, image_pixels
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    port_error,
    read_input,
    read_message,
    read_vector,
)

IMAGE = "sensor_msgs/msg/Image"
# RGB per detection, in turn (plain tuples: loading the plugin must not import numpy)
_PALETTE = ((230, 25, 75), (60, 180, 75), (255, 225, 25), (0, 130, 200), (245, 130, 48), (145, 30, 180))


def _rgb(behavior: Any) -> np.ndarray:
    import numpy as np

    pixels, mode = image_pixels(behavior, "image", read_message(behavior, "image"))
    if mode == "L":
        pixels = np.repeat(pixels[:, :, None], 3, axis=2)
    return np.array(pixels[:, :, :3], dtype=np.uint8)


def _publish(behavior: Any, topic: str, pixels: np.ndarray, frame_id: str) -> None:
    node = behavior.context.require_node(behavior.registration_id)
    behavior.context.publisher(node, IMAGE, topic).publish(image_message(pixels, "rgb8", frame_id))


def _box(mask_or_box: Any) -> tuple[int, int, int, int] | None:
    """``(x0, y0, x1, y1)`` of a 2D box message (center/size or x/y/width/height fields)."""
    center = getattr(mask_or_box, "center", None)
    if center is not None and hasattr(mask_or_box, "size_x"):
        cx, cy = float(center.position.x), float(center.position.y)
        hx, hy = float(mask_or_box.size_x) / 2, float(mask_or_box.size_y) / 2
        return int(cx - hx), int(cy - hy), int(cx + hx), int(cy + hy)
    if all(hasattr(mask_or_box, a) for a in ("x", "y", "width", "height")):
        x, y = int(mask_or_box.x), int(mask_or_box.y)
        return x, y, x + int(mask_or_box.width), y + int(mask_or_box.height)
    return None


def _outline(pixels: np.ndarray, box: tuple[int, int, int, int], color: tuple[int, int, int]) -> None:
    h, w = pixels.shape[:2]
    x0, y0, x1, y1 = max(box[0], 0), max(box[1], 0), min(box[2], w - 1), min(box[3], h - 1)
    if x0 > x1 or y0 > y1:
        return
    pixels[y0 : y1 + 1, [x0, x1]] = color
    pixels[[y0, y1], x0 : x1 + 1] = color


class PublishBoundingBoxes2D(SyncBehavior):
    """Draws 2D bounding boxes onto ``image`` and publishes it on ``visualization_topic``."""

    subcategory = "User Interface"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("image", IMAGE, "{image}", "The image the boxes belong to."),
            input_port(
                "bounding_boxes",
                None,
                "{bounding_boxes}",
                "The boxes (vision_msgs/BoundingBox2D or x/y/w/h).",
            ),
            input_port(
                "visualization_topic", str, "/bounding_boxes_visualization", "Topic of the drawn image."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        pixels = _rgb(self)
        for index, item in enumerate(read_vector(self, "bounding_boxes")):
            box = _box(item)
            if box is None:
                raise port_error(self, "bounding_boxes", f"element {index} is not a 2D box", "")
            _outline(pixels, box, _PALETTE[index % len(_PALETTE)])
        frame = str(read_message(self, "image").header.frame_id)
        _publish(self, str(read_input(self, "visualization_topic")), pixels, frame)
        return NodeStatus.SUCCESS


class PublishMask2D(SyncBehavior):
    """Blends 2D masks onto ``image`` (``opacity``) and publishes it on ``masks_visualization_topic``."""

    subcategory = "User Interface"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("image", IMAGE, "{image}", "The image the masks belong to."),
            input_port(
                "masks", None, "{masks2d}", "The masks (each with a mono8 'mask' image and an x/y offset)."
            ),
            input_port("masks_visualization_topic", str, "/masks_visualization", "Topic of the drawn image."),
            input_port("opacity", float, 0.5, "How strongly masks cover the image (0..1)."),
            input_port("bounding_box_labels", None, "", "Optional label per mask (shown in the log)."),
            input_port("bounding_box_detection_class", str, "", "Optional class name of the detections."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        pixels = _rgb(self).astype(float)
        opacity = float(read_input(self, "opacity"))
        if not 0.0 <= opacity <= 1.0:
            raise port_error(self, "opacity", f"= {opacity}", "give a value from 0 to 1")
        h, w = pixels.shape[:2]
        for index, item in enumerate(read_vector(self, "masks")):
            mask = getattr(item, "mask", item)
            try:
                layer, _ = image_pixels(self, "masks", mask)
            except Exception:
                raise port_error(self, "masks", f"element {index} has no mono8 mask image", "") from None
            x0, y0 = int(getattr(item, "x", 0)), int(getattr(item, "y", 0))
            region = np.zeros((h, w), dtype=bool)
            lh, lw = min(layer.shape[0], h - y0), min(layer.shape[1], w - x0)
            if lh > 0 and lw > 0:
                region[y0 : y0 + lh, x0 : x0 + lw] = layer[:lh, :lw] > 0
            color = np.array(_PALETTE[index % len(_PALETTE)])
            pixels[region] = pixels[region] * (1 - opacity) + color * opacity
        frame = str(read_message(self, "image").header.frame_id)
        _publish(self, str(read_input(self, "masks_visualization_topic")), pixels.astype(np.uint8), frame)
        return NodeStatus.SUCCESS
