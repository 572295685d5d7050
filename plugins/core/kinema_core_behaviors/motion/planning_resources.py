"""What planning behaviors plan with: the robot model, the planning scene, a collision checker per thread.

The model and the planning scene come from the behavior context (the runtime builds the model from the
config's URDF/SRDF; the scene is the static part of the config's MuJoCo scene, tables, walls, trays, or
whatever ``context.set_planning_scene`` installed). Collision checkers are not thread-safe, so each worker
thread gets its own, kept in the context and rebuilt when the scene changes.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from kinema.errors import ObjectiveError

if TYPE_CHECKING:
    from kinema.behaviors import BehaviorContext
    from kinema.motion import CollisionChecker, RobotModel


def robot_model(context: BehaviorContext, behavior: str) -> RobotModel:
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


def collision_checker(context: BehaviorContext, behavior: str, padding: float) -> CollisionChecker:
    """A collision checker for the calling thread, with ``padding`` (m) around the robot's links."""
    from kinema.motion import CollisionChecker

    model = robot_model(context, behavior)
    scene = context.planning_scene
    per_thread = context.shared("collision_checkers", threading.local)
    entry: tuple[Any, Any, int, CollisionChecker] | None = getattr(per_thread, "entry", None)
    if entry is None or entry[0] is not model or entry[1] is not scene or entry[2] != scene.version:
        checker = CollisionChecker(model, scene, padding=padding)
        per_thread.entry = (model, scene, scene.version, checker)
    else:
        checker = entry[3]
        if checker.padding != padding:
            checker.padding = padding
    return checker
