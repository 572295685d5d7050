"""Core behaviors: motion, gripper, waypoints, blackboard and vector utilities, logging.

Loaded by ``kinema::CoreBehaviorsLoader`` (alias ``moveit_pro::behaviors::CoreBehaviorsLoader``).
"""

from __future__ import annotations

from kinema.plugins import RegisterBehavior, hookimpl


@hookimpl
def register_behaviors(register: RegisterBehavior) -> None:
    """Register the core behaviors."""
