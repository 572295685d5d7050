"""Core behaviors, by family: vectors, messages, poses, motion, controllers, waypoints, UI, waiting, ...

Loaded by ``kinema::CoreBehaviorsLoader`` (alias ``moveit_pro::behaviors::CoreBehaviorsLoader``). IDs and
ports are MoveIt Pro's, so its objectives run unchanged. Each family is a package whose ``BEHAVIORS``
tuple lists what it registers; this loader registers their union. Planning runs in the agent
(``kinema.motion``); execution goes to the driver's controllers over the transport.
"""

from __future__ import annotations

from kinema.plugins import RegisterBehavior, hookimpl

from . import (
    controllers,
    files,
    flow,
    io,
    messages,
    motion,
    mpc,
    perception,
    planning_scene,
    poses,
    task_planning,
    ui,
    vectors,
    waiting,
    waypoints,
)

FAMILIES = (controllers, files, io, messages, motion, planning_scene, poses, ui, vectors, waiting, waypoints)
FAMILIES += (task_planning,)  # issue 13's family, kept on its own line
FAMILIES += (perception,)  # issue 14's family, kept on its own line
FAMILIES += (mpc,)  # issue 30's MPC family, kept on its own line
FAMILIES += (flow,)  # the example-workspace loops and coin flip, kept on its own line

BEHAVIORS = tuple(behavior for family in FAMILIES for behavior in family.BEHAVIORS)


@hookimpl
def register_behaviors(register: RegisterBehavior) -> None:
    """Register the core behaviors under their class names (MoveIt Pro's IDs)."""
    for behavior in BEHAVIORS:
        register(behavior)
