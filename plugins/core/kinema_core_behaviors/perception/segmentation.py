"""GetMasks2DFromExemplar, GetMasks2DFromPointQuery, GetMasks2DAutomask and GetMasks2DAction: MoveIt Pro's
segmentation-model behaviors, known here so that the objectives using them load and validate, and failing
when they run.

MoveIt Pro runs SAM3 (exemplar and text prompts) and SAM2 (point prompts, and a grid of them for automask)
as ONNX models from its ``moveit_pro_sam3`` / ``moveit_pro_sam2`` packages (or an example package holding
the files), on a GPU, and asks a ``GetMasks2D`` action server (Mask R-CNN in the example workspace) for
GetMasks2DAction. Kinema runs no segmentation model: these behaviors declare MoveIt Pro's ports and, when
ticked, fail with one message saying so (:meth:`_SegmentationModel.tick`). They never write
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

    def model_source(self) -> str:
        """Where MoveIt Pro's model comes from, for the failure message: ``SAM3 from moveit_pro_sam3``."""
        package = self.get_input_or("model_package", "")
        return self.model + (f" from {package}" if package else "")

    def tick(self) -> NodeStatus:
        self.logger.publish_failure(
            f"{self.registration_id}: Kinema does not run segmentation models ({self.model_source()}"
            " in MoveIt Pro), so it has no masks to write; give masks2d from a behavior of your own "
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


class GetMasks2DAutomask(_SegmentationModel):
    """Segments everything in ``image`` with MoveIt Pro's SAM2 model, prompted by a grid of points.

    Kinema does not run the model: the behavior fails when it runs and writes no masks (see the module).
    """

    model = "SAM2 automask"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            *_model_ports(
                "moveit_pro_sam2", "models/sam2.1_hiera_l_image_encoder.onnx", "models/sam2.1_decoder.onnx"
            ),
            input_port(
                "prompt_encoder_model_path",
                str,
                "models/sam2.1_prompt_encoder.onnx",
                "Point-prompt encoder model, relative to model_package.",
            ),
            message_input("image", IMAGE, "{image}", "The image to segment."),
            input_port("grid_size", int, 11, "Prompt points per image side (grid_size² prompts)."),
            input_port("score_threshold", float, 0.8, "Lowest score (0..1) a mask is kept with."),
            input_port(
                "nms_threshold", float, 0.3, "Overlap (IoU, 0..1) above which the weaker mask is dropped."
            ),
            input_port("min_component_area", int, 2000, "Smallest mask (pixels) kept."),
            output_port("masks2d", None, "{masks2d}", "The masks found (std::vector<Mask2D>)."),
            output_port("mask_count", int, "{mask_count}", "How many masks were found."),
        ]


class GetMasks2DAction(_SegmentationModel):
    """Segments ``image`` by asking the ``GetMasks2D`` action server ``action_name`` (in MoveIt Pro's example
    workspace, a Mask R-CNN model) for masks of ``valid_classes``.

    Kinema runs no such server or model: the behavior fails when it runs and writes no masks (see the
    module).
    """

    model = "the GetMasks2D action server's model"

    def model_source(self) -> str:
        return f"the {self.get_input_or('action_name', '')} action server's model"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("image", IMAGE, "{image}", "The image to segment."),
            input_port(
                "action_name", str, "get_masks_2d_maskrcnn", "The GetMasks2D action server (MoveIt Pro)."
            ),
            input_port(
                "valid_classes",
                list[str],
                "",
                "Class names the masks may have, ';'-separated (a name may hold spaces: 'pull handle'); "
                "'': any class.",
            ),
            input_port("min_confidence", float, 0.8, "Lowest score (0..1) a mask is kept with."),
            input_port(
                "max_nms_iou", float, 0.8, "Overlap (IoU, 0..1) above which the weaker mask is dropped."
            ),
            input_port("min_relative_area", float, 0.0, "Smallest mask kept, as a fraction of the image."),
            input_port("max_relative_area", float, 1.0, "Largest mask kept, as a fraction of the image."),
            input_port("timeout_sec", float, 10.0, "How long (s) to wait for the server's answer."),
            output_port("masks2d", None, "{masks2d}", "The masks found (std::vector<Mask2D>)."),
        ]
