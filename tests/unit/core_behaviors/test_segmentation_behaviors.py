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
