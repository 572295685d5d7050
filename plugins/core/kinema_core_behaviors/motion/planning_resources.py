"""What planning behaviors plan with: the robot model, the planning scene, a collision checker per thread.

The model comes from the behavior context (the runtime builds it from the config's URDF/SRDF); the
planning scene is the static part of the config's MuJoCo scene (tables, walls, trays), or whatever
:func:`set_planning_scene` installed. Collision checkers are not thread-safe, so each worker thread gets
its own, rebuilt when the scene changes.
"""

from __future__ import annotations

import threading
import weakref
from typing import TYPE_CHECKING, Any

from kinema.errors import ObjectiveError

if TYPE_CHECKING:
    from kinema.motion import CollisionChecker, PlanningScene, RobotModel

_SCENES: weakref.WeakKeyDictionary[Any, PlanningScene] = weakref.WeakKeyDictionary()
_SCENES_LOCK = threading.Lock()
_THREAD = threading.local()


def robot_model(context: Any, behavior: str) -> RobotModel:
    """The context's robot model.

    Raises:
        ObjectiveError: the runtime gave this context no robot model (no config package).
    """
    model = context.robot_model
    if model is None:
        raise ObjectiveError(
            f"{behavior} needs the robot model, but this runtime has none; run a config package with "
            "hardware.robot_description (urdf, srdf)"
        )
    return model


def set_planning_scene(context: Any, scene: PlanningScene) -> None:
    """Plan against ``scene`` in every behavior of ``context`` from now on."""
    with _SCENES_LOCK:
        _SCENES[context] = scene


def existing_planning_scene(context: Any) -> PlanningScene | None:
    """The context's planning scene if a behavior has made or set one, else None (nothing is loaded)."""
    with _SCENES_LOCK:
        return _SCENES.get(context)


def planning_scene(context: Any, model: RobotModel) -> PlanningScene:
    """The planning scene of ``context``: the static geometry of its config's MuJoCo scene by default.

    With a transport node, every change of the scene is published (latched) on
    ``/monitored_planning_scene`` for ``kinema view`` and other subscribers.
    """
    from kinema.motion import PlanningScene

    with _SCENES_LOCK:
        scene = _SCENES.get(context)
        if scene is None:
            config = getattr(context, "config", None)
            path = getattr(config, "mujoco_model_path", None) if config is not None else None
            scene = PlanningScene.from_mjcf(path, model.link_names) if path is not None else PlanningScene()
            _SCENES[context] = scene
            if getattr(context, "node", None) is not None:
                _publish_changes(context, scene, model)
        return scene


def _publish_changes(context: Any, scene: PlanningScene, model: RobotModel) -> None:
    from ..planning_scene.scene_messages import (
        PLANNING_SCENE_TOPIC,
        PLANNING_SCENE_TYPE,
        planning_scene_message,
    )

    publisher = context.publisher(context.node, PLANNING_SCENE_TYPE, PLANNING_SCENE_TOPIC, latched=True)
    name = model.name if hasattr(model, "name") else ""

    def publish(changed: PlanningScene) -> None:
        publisher.publish(planning_scene_message(changed, str(name)))

    scene.subscribe(publish)
    publish(scene)


def collision_checker(context: Any, behavior: str, padding: float) -> CollisionChecker:
    """A collision checker for the calling thread, with ``padding`` (m) around the robot's links."""
    from kinema.motion import CollisionChecker

    model = robot_model(context, behavior)
    scene = planning_scene(context, model)
    cache: dict[int, tuple[Any, Any, int, CollisionChecker]] = getattr(_THREAD, "checkers", None) or {}
    _THREAD.checkers = cache
    entry = cache.get(id(context))
    if entry is None or entry[0] is not model or entry[1] is not scene or entry[2] != scene.version:
        checker = CollisionChecker(model, scene, padding=padding)
        cache[id(context)] = (model, scene, scene.version, checker)
    else:
        checker = entry[3]
        if checker.padding != padding:
            checker.padding = padding
    return checker
