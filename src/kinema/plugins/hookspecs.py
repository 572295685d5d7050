"""The hooks a Kinema plugin can implement.

A plugin is a module (or any object) whose functions are marked with :data:`hookimpl`. Kinema's own
bundled behaviors load through exactly the same hooks as third-party and workspace plugins.

Example::

    from kinema.plugins import hookimpl

    @hookimpl
    def register_behaviors(register):
        register(MyBehavior)
        register(MyAddTwoIntsServiceClient, "MyServiceClient")
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import pluggy

if TYPE_CHECKING:
    from kinema.plugins.registration import RegisterBehavior

PROJECT_NAME = "kinema"

hookspec = pluggy.HookspecMarker(PROJECT_NAME)
hookimpl = pluggy.HookimplMarker(PROJECT_NAME)


@hookspec
def register_behaviors(register: RegisterBehavior) -> None:
    """Register behavior classes by calling ``register(cls, behavior_id=None)`` once per behavior."""
