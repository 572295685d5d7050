"""What planning behaviors plan with: the robot model, the planning scene, a collision checker per thread.

The model comes from the behavior context (the runtime builds it from the config's URDF/SRDF); the
planning scene is the static part of the config's MuJoCo scene (tables, walls, trays), or whatever
:func:`set_planning_scene` installed. Collision checkers are not thread-safe, so each worker thread gets
its own, rebuilt when the scene changes.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from kinema.errors import ObjectiveError

if TYPE_CHECKING:
    from kinema.motion import CollisionChecker, PlanningScene, RobotModel

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
    from kinema.runtime.planning_scene_service import set_scene

    set_scene(context, scene)


def existing_planning_scene(context: Any) -> PlanningScene | None:
    """The context's planning scene if a behavior has made or set one, else None (nothing is loaded)."""
    from kinema.runtime.planning_scene_service import existing_scene

    return existing_scene(context)


def planning_scene(context: Any, model: RobotModel) -> PlanningScene:
    """The planning scene of ``context``: the static geometry of its config's MuJoCo scene by default.

    It is the agent's: published on ``/monitored_planning_scene`` and served on ``/get_planning_scene``
    (:mod:`kinema.runtime.planning_scene_service`).
    """
    from kinema.runtime.planning_scene_service import scene_of

    return scene_of(context, model)


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
