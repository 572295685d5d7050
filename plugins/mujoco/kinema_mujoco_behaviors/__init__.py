"""Simulation-only behaviors (MuJoCo state, keyframes).

Loaded by ``kinema::MujocoBehaviorsLoader`` (alias ``moveit_pro::behaviors::MujocoBehaviorsLoader``).
"""

from __future__ import annotations

from kinema.plugins import RegisterBehavior, hookimpl

from .reset_mujoco_keyframe import ResetMujocoKeyframe
from .set_mujoco_state import SetMujocoState


@hookimpl
def register_behaviors(register: RegisterBehavior) -> None:
    """Register the MuJoCo behaviors."""
    register(SetMujocoState)
    register(ResetMujocoKeyframe)
