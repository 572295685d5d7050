"""GetMask2DProperties and FilterMasks2DByArea: how big an image mask is, in pixels, and keeping the masks
of the size the objects sought are.

A mask's area is the number of its object's pixels (non-zero in its image); its width and height are those
of the tightest box around them. "Calibrate SAM3 Mask Areas" logs them to choose the filter's bounds.
"""

from __future__ import annotations

from typing import Any

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    port_error,
    read_input,
    read_message,
    read_vector,
    write_output,
)
from .masks import MASK2D, mask_layer

SUBCATEGORY = "Perception - 2D Image"


class GetMask2DProperties(SyncBehavior):
    """Writes the ``area`` (pixels of the object) of Mask2D ``mask`` and the ``width`` and ``height``
    (pixels) of the tightest box around those pixels; all 0 for an empty mask."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("mask", MASK2D, "{mask}", "The mask (one element of a GetMasks2D* masks2d)."),
            output_port("width", int, "{width}", "Width (pixels) of the box around the object's pixels."),
            output_port("height", int, "{height}", "Height (pixels) of the box around the object's pixels."),
            output_port("area", int, "{area}", "How many pixels the object covers."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        layer = mask_layer(self, "mask", 0, read_message(self, "mask", MASK2D))
        rows, cols = np.nonzero(layer)
        width = int(np.ptp(cols)) + 1 if len(cols) else 0
        height = int(np.ptp(rows)) + 1 if len(rows) else 0
        write_output(self, "width", width)
        write_output(self, "height", height)
        write_output(self, "area", int(layer.sum()))
        return NodeStatus.SUCCESS


class FilterMasks2DByArea(SyncBehavior):
    """Keeps the masks of ``masks`` whose area (pixels of the object) is at least ``min_area`` and at most
    ``max_area``, in their order, as ``filtered_masks`` (which may be ``masks`` itself). ``max_area`` 0
    sets no upper bound. Keeping none succeeds with an empty vector (GetSizeOfVector then gives 0)."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("masks", None, "{masks2d}", "The masks (std::vector<Mask2D>)."),
            input_port("min_area", int, 0, "Smallest area (pixels) kept."),
            input_port("max_area", int, 0, "Largest area (pixels) kept; 0: no upper bound."),
            output_port(
                "filtered_masks", None, "{masks2d}", "The masks kept (std::vector<Mask2D>), in order."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        least, most = int(read_input(self, "min_area")), int(read_input(self, "max_area"))
        if least < 0 or most < 0:
            port = "min_area" if least < 0 else "max_area"
            value = least if least < 0 else most
            raise port_error(self, port, f"= {value}", "give a pixel count of 0 or more")
        if most and least > most:
            raise port_error(
                self, "max_area", f"= {most} is below min_area {least}", "give max_area >= min_area, or 0"
            )
        kept: list[Any] = []
        for index, mask in enumerate(read_vector(self, "masks")):
            area = int(mask_layer(self, "masks", index, mask).sum())
            if area >= least and (not most or area <= most):
                kept.append(mask)
        write_output(self, "filtered_masks", kept)
        return NodeStatus.SUCCESS
