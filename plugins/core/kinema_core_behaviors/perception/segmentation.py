"""GetMasks2DFromExemplar and GetMasks2DFromPointQuery: MoveIt Pro's segmentation-model behaviors, known
here so that the objectives using them load and validate, and failing when they run.

MoveIt Pro runs SAM3 (exemplar and text prompts) and SAM2 (point prompts) as ONNX models from its
``moveit_pro_sam3`` / ``moveit_pro_sam2`` packages, on a GPU. Kinema runs no segmentation model: these
behaviors declare MoveIt Pro's ports and, when ticked, fail with a message saying so. They never write
masks, so nothing downstream (GetMasks3DFromMasks2D, FindMaskedObjects, a grasp) acts on made-up
objects. Masks from elsewhere (a behavior of your own that runs a model) feed the same downstream
behaviors through ``masks2d``.
"""

from __future__ import annotations

from typing import ClassVar

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from ..messages.ports import message_input
from .clouds import IMAGE

SUBCATEGORY = "Perception - ML"


class _SegmentationModel(SyncBehavior):
    """A segmentation behavior whose model Kinema does not run (see the module's notes)."""

    subcategory = SUBCATEGORY
    # The model MoveIt Pro runs for this behavior, for the failure message.
    model: ClassVar[str] = ""

    def tick(self) -> NodeStatus:
        package = self.get_input_or("model_package", "")
        self.logger.publish_failure(
            f"{self.registration_id}: Kinema does not run segmentation models ({self.model}"
            + (f" from {package}" if package else "")
            + " in MoveIt Pro), so it has no masks to write; give masks2d from a behavior of your own "
            "that runs a model, or run this objective on MoveIt Pro"
        )
        return NodeStatus.FAILURE


def _model_ports(package: str, encoder: str, decoder: str) -> list[PortInfo]:
    return [
        input_port("model_package", str, package, "Package holding the model files (MoveIt Pro)."),
        input_port("encoder_model_path", str, encoder, "Image encoder model, relative to model_package."),
        input_port("decoder_model_path", str, decoder, "Mask decoder model, relative to model_package."),
    ]


class GetMasks2DFromExemplar(_SegmentationModel):
    """Segments ``target_image`` with MoveIt Pro's SAM3 model, prompted by text and exemplars.

    Kinema does not run the model: the behavior fails when it runs and writes no masks (see the module).
    """

    model = "SAM3"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            *_model_ports("moveit_pro_sam3", "models/sam3_vision_encoder.onnx", "models/sam3_decoder.onnx"),
            input_port(
                "geometry_encoder_model_path",
                str,
                "models/sam3_geometry_encoder.onnx",
                "Box-prompt encoder model, relative to model_package.",
            ),
            input_port(
                "text_encoder_model_path",
                str,
                "models/sam3_text_encoder.onnx",
                "Text-prompt encoder model, relative to model_package.",
            ),
            message_input("target_image", IMAGE, "{image}", "The image to segment."),
            input_port("text_prompt", str, "", "What to find, in words ('bottles'); '': no text prompt."),
            input_port(
                "exemplar_image", None, "", "An image showing the object (sensor_msgs/Image); optional."
            ),
            input_port("exemplar_bboxes", None, "", "Boxes around the object in exemplar_image; optional."),
            input_port(
                "target_bboxes", None, "", "Boxes around examples of the object in target_image; optional."
            ),
            input_port("confidence_threshold", float, 0.5, "Lowest score (0..1) a mask is kept with."),
            output_port("masks2d", None, "{masks2d}", "The masks found (std::vector<Mask2D>)."),
            output_port("mask_count", int, "{mask_count}", "How many masks were found."),
            output_port("confidence_scores", list[float], "{confidence_scores}", "One score per mask."),
            output_port(
                "confidence_scores_str", str, "{confidence_scores_str}", "The scores as text, for labels."
            ),
        ]


class GetMasks2DFromPointQuery(_SegmentationModel):
    """Segments ``image`` with MoveIt Pro's SAM2 model, prompted by pixels on the object.

    Kinema does not run the model: the behavior fails when it runs and writes no masks (see the module).
    """

    model = "SAM2"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            *_model_ports(
                "moveit_pro_sam2", "models/sam2_hiera_large_encoder.onnx", "models/sam2_decoder.onnx"
            ),
            message_input("image", IMAGE, "{image}", "The image to segment."),
            input_port(
                "pixel_coords", None, "{pixel_coords}", "Pixels on the object (from GetPointsFromUser)."
            ),
            output_port("masks2d", None, "{masks2d}", "The masks found (std::vector<Mask2D>)."),
        ]
