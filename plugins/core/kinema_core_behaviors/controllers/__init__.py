"""Controllers: list and switch the driver's ros2_control-style controllers."""

from __future__ import annotations

from .list_controllers import ListControllers
from .switch_controller import SwitchController

BEHAVIORS = (ListControllers, SwitchController)
