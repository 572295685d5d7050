"""Planning scene: the collision objects plans avoid (add, inspect, reset), the scene as a message."""

from __future__ import annotations

from .add_collision_box import AddCollisionBox
from .add_collision_object import AddCollisionObject
from .get_current_planning_scene import GetCurrentPlanningScene
from .is_collision_object_in_planning_scene import IsCollisionObjectInPlanningScene
from .reset_planning_scene_objects import ResetPlanningSceneObjects

BEHAVIORS = (
    AddCollisionBox,
    AddCollisionObject,
    GetCurrentPlanningScene,
    IsCollisionObjectInPlanningScene,
    ResetPlanningSceneObjects,
)
