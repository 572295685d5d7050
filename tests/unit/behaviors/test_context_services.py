"""The services a behavior gets from its cell are members of its BehaviorContext, one set per context."""

from __future__ import annotations

import ast
import threading
from pathlib import Path

import numpy as np
import pytest

from kinema.behaviors import BehaviorContext
from kinema.errors import ObjectiveError
from kinema.motion.planning_scene import CollisionObject, PlanningScene

REPO = Path(__file__).resolve().parents[3]


def test_the_planning_scene_is_made_once_per_context_and_listeners_hear_of_it() -> None:
    made: list[BehaviorContext] = []

    def provider(context: BehaviorContext) -> PlanningScene:
        made.append(context)
        return PlanningScene()

    first, second = BehaviorContext(planning_scene=provider), BehaviorContext(planning_scene=provider)
    heard: list[PlanningScene] = []
    first.on_planning_scene(heard.append)
    assert first.loaded_planning_scene is None and made == []  # nothing is loaded until asked for
    scene = first.planning_scene
    assert first.planning_scene is scene and made == [first] and heard == [scene]
    assert second.planning_scene is not scene  # two cells never share a scene
    replacement = PlanningScene()
    first.set_planning_scene(replacement)
    assert first.planning_scene is replacement and heard == [scene, replacement]
    late: list[PlanningScene] = []
    first.on_planning_scene(late.append)
    assert late == [replacement]  # a listener added later hears of the scene in place


def test_without_a_config_the_default_scene_is_empty() -> None:
    scene = BehaviorContext().planning_scene
    assert scene.objects == {} and scene.world_objects() == {}


def test_the_frames_place_cameras_and_scene_objects_beside_the_robot() -> None:
    from kinema.config import resolve_config
    from kinema.motion import RobotDescription

    context = BehaviorContext(
        robot_model=RobotDescription.lab_sim().load_model, config=resolve_config("lab_sim")
    )
    assert "scene_camera" in context.cameras and context.cameras["scene_camera"].shape == (4, 4)
    assert context.frames is context.frames
    pose = np.eye(4)
    pose[:3, 3] = [0.5, 0.0, 0.8]
    context.planning_scene.add_world_object("box", [CollisionObject("", "box", (0.1, 0.1, 0.1), pose)])
    model = context.robot_model
    assert model is not None
    tree = context.frames.tree(np.zeros(len(model.joint_names)))
    np.testing.assert_allclose(tree.world_T("box"), pose)
    np.testing.assert_allclose(tree.world_T("scene_camera"), context.cameras["scene_camera"])
    assert tree.world_T("grasp_link").shape == (4, 4)


def test_joint_states_need_the_transport_and_say_so() -> None:
    with pytest.raises(ObjectiveError, match="needs the transport"):
        _ = BehaviorContext().joint_states


def test_shared_state_is_per_context_and_made_once() -> None:
    made: list[int] = []

    def make() -> threading.local:
        made.append(1)
        return threading.local()

    a, b = BehaviorContext(), BehaviorContext()
    assert a.shared("cache", make) is a.shared("cache", make)
    assert b.shared("cache", make) is not a.shared("cache", make)
    assert len(made) == 2


def _python_files(*roots: Path) -> list[Path]:
    return [path for root in roots for path in root.rglob("*.py")]


def test_no_plugin_imports_the_runtime() -> None:
    offenders = []
    for path in _python_files(REPO / "plugins"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = (
                [alias.name for alias in node.names]
                if isinstance(node, ast.Import)
                else [node.module or ""]
                if isinstance(node, ast.ImportFrom)
                else []
            )
            if any(name == "kinema.runtime" or name.startswith("kinema.runtime.") for name in names):
                offenders.append(f"{path.relative_to(REPO)}:{node.lineno}")
    assert offenders == []


def test_no_module_keeps_per_cell_state_in_a_global_table() -> None:
    """Tables keyed on the context (WeakKeyDictionary, or dicts keyed by id(context)) are gone."""
    offenders = []
    for path in _python_files(REPO / "src" / "kinema", REPO / "plugins"):
        text = path.read_text(encoding="utf-8")
        if "WeakKeyDictionary" in text or "id(context)" in text or "id(self.context)" in text:
            offenders.append(str(path.relative_to(REPO)))
    assert offenders == []
