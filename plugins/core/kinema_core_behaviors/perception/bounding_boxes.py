"""CreateBoundingBoxFromOffset: the box around an exemplar image's object, for segmentation by exemplar."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from ..messages.ports import fails_on_bad_input, message_input, port_error, read_input, read_message

IMAGE = "sensor_msgs/msg/Image"
BOX = "vision_msgs/msg/BoundingBox2D"


class CreateBoundingBoxFromOffset(SyncBehavior):
    """Writes one box to ``bounding_boxes``: the whole of ``exemplar_image`` less ``padding_percent`` of its
    width and height on each side (an exemplar image is cropped around the object, with a margin).

    MoveIt Pro feeds the box to GetMasks2DFromExemplar with the exemplar image; its exact rule is not
    public, so this is Kinema's: centre at the image's centre, size ``(1 - 2 * padding_percent)`` times the
    image's. Fails when ``padding_percent`` is not in [0, 0.5).
    """

    subcategory = "Perception - ML"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("exemplar_image", IMAGE, "{exemplar_image}", "The exemplar image."),
            input_port(
                "padding_percent",
                float,
                0.05,
                "Margin left on each side, as a fraction of the image's width and height, [0, 0.5).",
            ),
            output_port(
                "bounding_boxes",
                None,
                "{bounding_boxes}",
                "One box in the image's pixels (std::vector<vision_msgs/BoundingBox2D>).",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.transport import from_dict

        image = read_message(self, "exemplar_image")
        padding = float(read_input(self, "padding_percent"))
        if not 0.0 <= padding < 0.5:
            raise port_error(self, "padding_percent", f"= {padding:g} is not in [0, 0.5)", "e.g. 0.07")
        width, height = float(image.width), float(image.height)
        if width <= 0 or height <= 0:
            raise port_error(self, "exemplar_image", f"is {width:g} x {height:g} pixels", "give a real image")
        box = from_dict(
            BOX,
            {
                "center": {"position": {"x": width / 2.0, "y": height / 2.0}, "theta": 0.0},
                "size_x": width * (1.0 - 2.0 * padding),
                "size_y": height * (1.0 - 2.0 * padding),
            },
        )
        self.set_output("bounding_boxes", [box])
        return NodeStatus.SUCCESS
