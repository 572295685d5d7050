"""MoveIt Pro's segmentation-model behaviors: known with MoveIt Pro's ports, failing honestly when run."""

from __future__ import annotations

from typing import Any

import pytest

from kinema.bt import NodeStatus
from kinema.testing import tick_behavior


@pytest.mark.parametrize(
    ("behavior_id", "inputs", "model"),
    [
        ("GetMasks2DFromExemplar", {"text_prompt": "bottles", "model_package": "moveit_pro_sam3"}, "SAM3"),
        ("GetMasks2DFromPointQuery", {"model_package": "moveit_pro_sam2"}, "SAM2"),
    ],
)
def test_a_segmentation_behavior_fails_saying_kinema_runs_no_model_and_writes_no_masks(
    behavior: Any, behavior_id: str, inputs: dict[str, Any], model: str
) -> None:
    run = tick_behavior(behavior(behavior_id), inputs)
    assert run.status is NodeStatus.FAILURE
    (toast,) = run.toasts
    assert toast.startswith(f"{behavior_id}: Kinema does not run segmentation models ({model} from ")
    assert inputs["model_package"] in toast
    assert run.outputs == {}  # no masks, counts or scores made up


def test_the_exemplar_behavior_declares_the_ports_lab_sim_sets(behavior: Any) -> None:
    ports = {port.name: port for port in behavior("GetMasks2DFromExemplar").provided_ports()}
    assert {
        "model_package",
        "encoder_model_path",
        "decoder_model_path",
        "geometry_encoder_model_path",
        "text_encoder_model_path",
        "confidence_threshold",
        "target_image",
        "text_prompt",
        "exemplar_image",
        "exemplar_bboxes",
        "target_bboxes",
        "masks2d",
        "mask_count",
        "confidence_scores",
        "confidence_scores_str",
    } == set(ports)
    outputs = {name for name, port in ports.items() if port.direction.name == "OUTPUT"}
    assert outputs == {"masks2d", "mask_count", "confidence_scores", "confidence_scores_str"}


def _calling(subtree_file: str, call: str) -> str:
    """Kinema's core subtree file with a main tree that makes ``call``."""
    from pathlib import Path

    from lxml import etree

    core = Path(__file__).resolve().parents[3] / "objectives" / subtree_file
    root = etree.fromstring(core.read_bytes())
    root.set("main_tree_to_execute", "Caller")
    root.insert(0, etree.fromstring(f'<BehaviorTree ID="Caller">{call}</BehaviorTree>'))
    return etree.tostring(root, encoding="unicode")


def test_the_text_prompt_subtree_takes_the_configs_camera_when_no_topic_is_given(
    registry: Any, context: Any
) -> None:
    """MoveIt Pro's copy defaults to its wrist camera; Kinema's to the config's default camera: lab_sim's
    images reach the model, which then fails honestly (Kinema runs no segmentation model)."""
    from kinema.testing import publish_repeatedly, run_objective
    from kinema.transport import from_dict

    image = from_dict(
        "sensor_msgs/msg/Image",
        {
            "header": {"frame_id": "wrist_camera_optical_frame"},
            "height": 2,
            "width": 2,
            "encoding": "rgb8",
            "step": 6,
            "data": list(range(12)),
        },
    )
    xml = _calling(
        "segment_image_from_text_prompt_subtree.xml",
        '<SubTree ID="Segment Image from Text Prompt Subtree" text_prompt="conical flask" />',
    )
    with publish_repeatedly(context.node, "sensor_msgs/msg/Image", "/wrist_camera/color", image):
        run = run_objective(xml, registry=registry, context=context, timeout=30.0)
    assert run.status is NodeStatus.FAILURE
    assert run.toasts and run.toasts[-1].startswith("GetMasks2DFromExemplar: Kinema does not run"), run.toasts
