"""Planning scene: the collision objects plans avoid (add, inspect, reset), URDF objects the robot can
carry (add, attach, detach, remove), what is attached, and the scene as a message."""

from __future__ import annotations

from .add_collision_box import AddCollisionBox
from .add_collision_object import AddCollisionObject
from .add_urdf import AddURDF
from .attach_urdf import AttachURDF
from .attached_objects import IsAnyObjectAttached, WhichObjectIsAttached
from .detach_urdf import DetachURDF
from .get_current_planning_scene import GetCurrentPlanningScene
from .is_collision_object_in_planning_scene import IsCollisionObjectInPlanningScene
from .remove_urdf_from_scene import RemoveURDFFromScene
from .reset_planning_scene_objects import ResetPlanningSceneObjects

BEHAVIORS = (
    AddCollisionBox,
    AddCollisionObject,
    GetCurrentPlanningScene,
    IsCollisionObjectInPlanningScene,
    ResetPlanningSceneObjects,
    AddURDF,
    AttachURDF,
    DetachURDF,
    RemoveURDFFromScene,
    IsAnyObjectAttached,
    WhichObjectIsAttached,
)
