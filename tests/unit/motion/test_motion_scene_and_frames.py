"""The planning scene's world objects (added, replaced, reset, heard, avoided) and the frame tree."""

from __future__ import annotations

import numpy as np
import pytest

from kinema.errors import MotionError
from kinema.motion import CollisionChecker, CollisionObject, FrameTree, PlanningScene, fk


def _at(x: float, y: float, z: float) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = [x, y, z]
    return pose


def test_world_objects_are_added_replaced_and_reset_leaving_the_environment(lab_scene: PlanningScene) -> None:
    scene = PlanningScene(dict(lab_scene.objects))
    environment = set(scene.objects)
    heard: list[int] = []
    scene.subscribe(lambda s: heard.append(s.version))
    scene.add_world_object("box", [CollisionObject("", "box", (0.1, 0.1, 0.1), _at(1, 0, 1))])
    assert scene.world == {"box": ("box",)} and "box" in scene.objects
    with pytest.raises(MotionError, match="already in the planning scene"):
        scene.add_world_object("box", [CollisionObject("", "sphere", (0.1,), _at(0, 0, 2))], replace=False)
    scene.add_world_object(
        "box",
        [
            CollisionObject("", "sphere", (0.1,), _at(0, 0, 2)),
            CollisionObject("", "box", (0.1, 0.2, 0.3), _at(0, 0, 3)),
        ],
    )
    assert scene.world["box"] == ("box/0", "box/1")
    assert [p.shape for p in scene.world_object("box")] == ["sphere", "box"]
    assert scene.reset_world() == 1
    assert set(scene.objects) == environment and scene.world == {}
    assert len(heard) == 3, heard  # add, replace, reset (the refused add changed nothing)


@pytest.mark.parametrize(
    ("object_id", "primitives", "message"),
    [
        ("", [CollisionObject("", "box", (0.1, 0.1, 0.1), np.eye(4))], "non-empty id"),
        ("b", [], "no shape"),
        ("b", [CollisionObject("", "box", (0.1, -0.1, 0.1), np.eye(4))], "must be finite and >= 0"),
        ("b", [CollisionObject("", "cone", (0.1, 0.1), np.eye(4))], "unknown collision shape"),
    ],
)
def test_bad_world_objects_are_refused_with_a_reason(object_id: str, primitives: list, message: str) -> None:
    scene = PlanningScene()
    with pytest.raises(MotionError, match=message):
        scene.add_world_object(object_id, primitives)
    assert scene.version == 0


def test_removing_an_unknown_world_object_names_those_there_are() -> None:
    scene = PlanningScene()
    scene.add_world_object("table_top", [CollisionObject("", "box", (1, 1, 0.05), np.eye(4))])
    with pytest.raises(MotionError, match="table_top"):
        scene.remove_world_object("table")


def test_a_box_added_at_the_tool_puts_that_configuration_in_collision(
    model, lab_scene: PlanningScene, waypoints: dict[str, dict[str, float]]
) -> None:
    scene = PlanningScene(dict(lab_scene.objects))
    checker = CollisionChecker(model, scene, padding=0.01)
    q = model.configuration(waypoints["Look at Table"])
    assert not checker.in_collision(q)
    scene.add_world_object(
        "obstacle", [CollisionObject("", "box", (0.05, 0.05, 0.05), fk(model, q, "grasp_link"))]
    )
    assert checker.in_collision(q)
    assert "obstacle" in checker.describe(q)
    scene.reset_world()
    assert not checker.in_collision(q)


def test_frame_tree_resolves_links_objects_and_world(model, waypoints: dict[str, dict[str, float]]) -> None:
    q = model.configuration(waypoints["Look at Table"])
    tree = FrameTree(model, q, {"cube": _at(-0.3, 0.62, 0.499)})
    assert np.allclose(tree.world_T("world"), np.eye(4)) and np.allclose(tree.world_T(""), np.eye(4))
    assert np.allclose(tree.world_T("grasp_link"), fk(model, q, "grasp_link"))
    for name in ("base_link", "tool0", "grasp_link", "cube"):
        assert name in tree.names() and name in tree
    # the cube's centre seen from the grasp link, and back
    in_grasp = tree.transform(np.eye(4), "cube", "grasp_link")
    assert np.allclose(tree.transform(in_grasp, "grasp_link", "world"), _at(-0.3, 0.62, 0.499))


def test_an_unknown_frame_names_the_closest_ones(model) -> None:
    tree = FrameTree(model, np.zeros(len(model.joint_names)))
    with pytest.raises(MotionError) as error:
        tree.world_T("grasp_lnk")
    assert "grasp_link" in str(error.value)
