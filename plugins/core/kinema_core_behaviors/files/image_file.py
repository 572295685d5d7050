"""LoadImageFromFile and SaveImageToFile: ``sensor_msgs/Image`` to and from PNG/JPEG files (Pillow)."""

from __future__ import annotations

import io
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import AsyncBehavior, PortInfo, input_port
from kinema.config.atomic_write import atomic_write_bytes
from kinema.errors import KinemaError

from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_output,
    port_error,
    read_input,
    read_message,
    read_text,
)
from .locations import RELATIVE_READ, RELATIVE_WRITE, file_to_read, file_to_write

IMAGE = "sensor_msgs/msg/Image"
# encoding -> (Pillow mode, channels)
ENCODINGS = {
    "rgb8": ("RGB", 3),
    "rgba8": ("RGBA", 4),
    "mono8": ("L", 1),
    "bgr8": ("RGB", 3),
    "bgra8": ("RGBA", 4),
}


def image_message(pixels: np.ndarray, encoding: str, frame_id: str = "") -> Any:
    """A ``sensor_msgs/Image`` of an ``(h, w[, c])`` uint8 array."""
    import numpy as np

    from kinema.transport import from_dict

    height, width = pixels.shape[:2]
    channels = 1 if pixels.ndim == 2 else pixels.shape[2]
    return from_dict(
        IMAGE,
        {
            "header": {"frame_id": frame_id},
            "height": height,
            "width": width,
            "encoding": encoding,
            "is_bigendian": 0,
            "step": width * channels,
            "data": np.ascontiguousarray(pixels, dtype=np.uint8).reshape(-1),
        },
    )


def image_pixels(node: Any, port: str, image: Any) -> tuple[np.ndarray, str]:
    """``(pixels, Pillow mode)`` of an 8-bit ``sensor_msgs/Image`` (BGR turned into RGB)."""
    import numpy as np

    encoding = str(image.encoding)
    if encoding not in ENCODINGS:
        raise port_error(node, port, f"has encoding {encoding!r}", f"valid: {', '.join(ENCODINGS)}")
    mode, channels = ENCODINGS[encoding]
    data = np.asarray(image.data, dtype=np.uint8)
    expected = int(image.height) * int(image.step)
    if data.size != expected or int(image.step) != int(image.width) * channels:
        raise port_error(node, port, f"has {data.size} bytes for {image.width}x{image.height} {encoding}", "")
    pixels = data.reshape(int(image.height), int(image.width), channels)
    if encoding.startswith("bgr"):
        pixels = pixels[:, :, [2, 1, 0, *([3] if channels == 4 else [])]]
    return (pixels[:, :, 0] if channels == 1 else pixels), mode


class LoadImageFromFile(AsyncBehavior):
    """Reads a PNG or JPEG file into a ``sensor_msgs/Image`` (rgb8, rgba8 or mono8) in frame ``frame_id``."""

    subcategory = "File Management"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "file_path",
                str,
                "",
                f"The image file; relative to package_name's folder when given, else {RELATIVE_READ}.",
            ),
            input_port("package_name", str, "", "Package the relative file_path is in (empty: objectives)."),
            input_port(
                "frame_id",
                str,
                "",
                "The image's header.frame_id: the camera frame it is taken to be seen from (later "
                "behaviors that place its pixels in 3D read it), e.g. 'camera'.",
            ),
            message_output("image", IMAGE, "{image}", "The image."),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        import numpy as np
        from PIL import Image, UnidentifiedImageError

        package = read_text(self, "package_name")
        path = file_to_read(self, "file_path", str(read_input(self, "file_path")), package)
        try:
            with Image.open(path) as opened:
                picture = opened.convert(
                    "RGBA"
                    if opened.mode in ("RGBA", "LA", "P")
                    else "L"
                    if opened.mode in ("L", "1", "I;16", "I")
                    else "RGB"
                )
        except (OSError, UnidentifiedImageError) as error:
            raise port_error(
                self, "file_path", f"file {path} is not an image Pillow reads: {error}", ""
            ) from None
        encoding = {"RGB": "rgb8", "RGBA": "rgba8", "L": "mono8"}[picture.mode]
        frame_id = read_text(self, "frame_id")
        self.set_output("image", image_message(np.asarray(picture), encoding, frame_id))
        return True


class SaveImageToFile(AsyncBehavior):
    """Writes a ``sensor_msgs/Image`` to a file, atomically; the extension picks the format (PNG default)."""

    subcategory = "File Management"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("image", IMAGE, "{image}", "The image to save (8-bit encodings)."),
            input_port("file_path", str, "", f"File to write; {RELATIVE_WRITE}."),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        from PIL import Image

        image = read_message(self, "image")
        text = str(read_input(self, "file_path"))
        suffix = "" if text.lower().endswith((".png", ".jpg", ".jpeg", ".bmp")) else ".png"
        path = file_to_write(self, "file_path", text, suffix)
        pixels, mode = image_pixels(self, "image", image)
        buffer = io.BytesIO()
        picture = Image.fromarray(pixels, mode=mode)
        if path.suffix.lower() in (".jpg", ".jpeg") and mode == "RGBA":
            picture = picture.convert("RGB")
        picture.save(
            buffer, format={".jpg": "JPEG", ".jpeg": "JPEG", ".bmp": "BMP"}.get(path.suffix.lower(), "PNG")
        )
        try:
            atomic_write_bytes(path, buffer.getvalue())
        except KinemaError as error:
            raise port_error(self, "file_path", f"= {text!r}: {error}", "") from None
        return True
