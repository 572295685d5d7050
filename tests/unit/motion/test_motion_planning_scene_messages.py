"""kinema.motion.planning_scene_messages: the planning scene to moveit_msgs and back, in one module."""

from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from kinema.errors import ObjectiveError
from kinema.motion.planning_scene import CollisionObject, PlanningScene
from kinema.motion.planning_scene_messages import (
    collision_object_message,
    planning_scene_dict,
    planning_scene_message,
    primitives_of,
    shape_constants,
)
from kinema.transforms import pose_matrix
from kinema.transport import from_dict

REPO = Path(__file__).resolve().parents[3]


def _scene() -> PlanningScene:
    scene = PlanningScene()
    turned = pose_matrix([0.5, 0.1, 0.2], [0.0, 0.0, np.sqrt(0.5), np.sqrt(0.5)])
    scene.add_world_object(
        "tray",
        [
            CollisionObject("", "box", (0.1, 0.2, 0.05), turned),
            CollisionObject("", "sphere", (0.03,), pose_matrix([1, 0, 0], [0, 0, 0, 1])),
            CollisionObject("", "cylinder", (0.02, 0.1), pose_matrix([0, 1, 0], [0, 0, 0, 1])),
        ],
    )
    return scene


def test_the_constants_are_the_message_classes_own() -> None:
    s = shape_constants()
    assert (s.BOX, s.SPHERE, s.CYLINDER, s.CONE) == (1, 2, 3, 4)
    ops = collision_object_message()
    assert (ops.ADD, ops.REMOVE, ops.APPEND, ops.MOVE) == (0, 1, 2, 3)


def test_scene_to_message_and_back_keeps_every_primitive() -> None:
    scene = _scene()
    message = planning_scene_message(scene, "lab_sim")
    assert message.robot_model_name == "lab_sim" and not message.is_diff
    (obj,) = message.world.collision_objects
    assert obj.id == "tray" and [int(p.type) for p in obj.primitives] == [1, 2, 3]
    assert [list(p.dimensions) for p in obj.primitives] == [[0.2, 0.4, 0.1], [0.03], [0.2, 0.02]]
    back = primitives_of(obj, None)
    for before, after in zip(scene.world_object("tray"), back, strict=True):
        assert after.shape == before.shape
        np.testing.assert_allclose(after.size, before.size)
        np.testing.assert_allclose(after.world_T_object, before.world_T_object, atol=1e-12)


@pytest.mark.parametrize(
    ("components", "keys", "geometry"),
    [
        (0, {"is_diff", "name", "robot_model_name", "world"}, True),  # 0: everything, as move_group
        (8, {"is_diff", "world"}, False),  # WORLD_OBJECT_NAMES: ids only
        (1, {"is_diff", "name", "robot_model_name"}, False),  # SCENE_SETTINGS
    ],
)
def test_components_select_the_parts(components: int, keys: set[str], geometry: bool) -> None:
    data = planning_scene_dict(_scene(), "lab_sim", None, components)
    assert set(data) == keys
    if "world" in data:
        (obj,) = data["world"]["collision_objects"]
        assert ("primitives" in obj) is geometry


def test_an_object_in_another_frame_is_placed_through_the_frames_given() -> None:
    message = from_dict(
        "moveit_msgs/msg/CollisionObject",
        {
            "header": {"frame_id": "tool0"},
            "id": "held",
            "pose": {"position": {"z": 0.1}},  # all-zero orientation: the identity
            "primitives": [{"type": 2, "dimensions": [0.05]}],
            "primitive_poses": [{}],
        },
    )
    world_T_tool = pose_matrix([1.0, 2.0, 3.0], [0, 0, 0, 1])
    (sphere,) = primitives_of(message, lambda frame: {"tool0": world_T_tool}[frame])
    np.testing.assert_allclose(sphere.world_T_object[:3, 3], [1.0, 2.0, 3.1])
    frames = SimpleNamespace(world_T=lambda frame: world_T_tool)
    np.testing.assert_allclose(primitives_of(message, frames)[0].world_T_object, sphere.world_T_object)


def test_a_cone_is_refused_with_the_shapes_that_work() -> None:
    message = from_dict(
        "moveit_msgs/msg/CollisionObject",
        {"id": "c", "primitives": [{"type": 4, "dimensions": [0.1, 0.1]}], "primitive_poses": [{}]},
    )
    with pytest.raises(ObjectiveError, match=r"CONE \(4\).*BOX \(1\), SPHERE \(2\), CYLINDER \(3\)"):
        primitives_of(message, None)


def test_no_other_module_numbers_the_shapes_itself() -> None:
    numbered = re.compile(r"BOX, SPHERE, CYLINDER\w*(, \w+)* = 1, 2, 3")
    offenders = [
        str(path.relative_to(REPO))
        for root in (REPO / "src" / "kinema", REPO / "plugins")
        for path in root.rglob("*.py")
        if numbered.search(path.read_text(encoding="utf-8"))
    ]
    assert offenders == []
