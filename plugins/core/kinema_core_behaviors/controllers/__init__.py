"""Controllers: list and switch the driver's ros2_control-style controllers; velocity-force control;
admittance parameters."""

from __future__ import annotations

from .list_controllers import ListControllers
from .set_admittance_parameters import SetAdmittanceParameters
from .switch_controller import SwitchController
from .velocity_force import ForceExceedsThreshold, PublishVelocityForceCommand

BEHAVIORS = (
    ListControllers,
    SwitchController,
    PublishVelocityForceCommand,
    ForceExceedsThreshold,
    SetAdmittanceParameters,
)
