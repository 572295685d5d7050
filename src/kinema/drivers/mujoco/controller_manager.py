"""The controller manager: which controllers exist, which are active, and switching them.

It answers ``controller_manager_msgs/srv/ListControllers`` and ``SwitchController`` the way
ros2_control's controller manager does: a controller is ``active`` or ``inactive``; activating claims
its command interfaces, which no other active controller may hold; ``STRICT`` switches fail as a whole
when a name is unknown or a switch is impossible, ``BEST_EFFORT`` ones do what they can. Names may be
given with a leading ``/`` (MoveIt Pro's objectives pass ``/joint_trajectory_controller``).

All methods run on the physics thread.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Any, Protocol

log = logging.getLogger(__name__)

BEST_EFFORT = 1
STRICT = 2


class Controller(Protocol):
    """What the manager needs of a controller."""

    name: str
    type_name: str
    active: bool

    @property
    def command_interfaces(self) -> list[str]:
        """Interfaces it claims while active (``<joint>/position``)."""
        ...

    @property
    def state_interfaces(self) -> list[str]:
        """Interfaces it reads."""
        ...

    def activate(self, data: Any) -> None:
        """Become active (hold the current state)."""
        ...

    def deactivate(self, data: Any) -> None:
        """Become inactive (abort what runs)."""
        ...


class Broadcaster:
    """A controller that only reads and publishes while active (the driver asks :attr:`active` first)."""

    type_name = ""

    def __init__(self, name: str) -> None:
        self.name = name
        self.active = False

    @property
    def command_interfaces(self) -> list[str]:
        """None: a broadcaster only reads."""
        return []

    def activate(self, data: Any) -> None:
        """Start publishing."""
        self.active = True

    def deactivate(self, data: Any) -> None:
        """Stop publishing."""
        self.active = False


class JointStateBroadcaster(Broadcaster):
    """Publishes ``/joint_states`` while active."""

    type_name = "joint_state_broadcaster/JointStateBroadcaster"

    def __init__(self, name: str, joint_names: Sequence[str]) -> None:
        super().__init__(name)
        self.joint_names = list(joint_names)

    @property
    def state_interfaces(self) -> list[str]:
        """Position, velocity and effort of every joint."""
        return [f"{name}/{kind}" for name in self.joint_names for kind in ("position", "velocity", "effort")]


def _normalize(name: str) -> str:
    return name.strip().lstrip("/")


class ControllerManager:
    """Holds the controllers and their activity.

    Args:
        controllers: every controller, in the order ``list_controllers`` reports them.
        update_rate: the control rate reported for each controller (Hz).
    """

    def __init__(self, controllers: Sequence[Controller], update_rate: int) -> None:
        self.controllers = {controller.name: controller for controller in controllers}
        self.update_rate = update_rate

    def get(self, name: str) -> Controller | None:
        """The controller called ``name`` (a leading ``/`` is ignored), or None."""
        return self.controllers.get(_normalize(name))

    def list_states(self) -> list[dict[str, Any]]:
        """``controller_manager_msgs/msg/ControllerState`` fields of every controller."""
        states = []
        for controller in self.controllers.values():
            commands = controller.command_interfaces
            states.append(
                {
                    "name": controller.name,
                    "state": "active" if controller.active else "inactive",
                    "type": controller.type_name,
                    "update_rate": self.update_rate,
                    "claimed_interfaces": commands if controller.active else [],
                    "required_command_interfaces": commands,
                    "required_state_interfaces": controller.state_interfaces,
                }
            )
        return states

    def switch(
        self, activate: Sequence[str], deactivate: Sequence[str], strictness: int, data: Any
    ) -> tuple[bool, str]:
        """Deactivate, then activate controllers; return ``(ok, message)``.

        ``strictness`` is ``STRICT`` (2) or ``BEST_EFFORT`` (1); 0 is taken as ``BEST_EFFORT``, as
        ros2_control does. Activating an active controller, or deactivating an inactive one, is a no-op.
        """
        strict = strictness == STRICT
        problems: list[str] = []
        to_deactivate: list[Controller] = []
        to_activate: list[Controller] = []
        for names, bucket in ((deactivate, to_deactivate), (activate, to_activate)):
            for raw in names:
                if not _normalize(raw):
                    continue
                controller = self.get(raw)
                if controller is None:
                    problems.append(f"unknown controller {raw!r} (known: {', '.join(self.controllers)})")
                elif controller not in bucket:
                    bucket.append(controller)
        both = [c.name for c in to_activate if c in to_deactivate]
        if both:
            problems.append(f"asked to both activate and deactivate {', '.join(both)}")
            to_activate = [c for c in to_activate if c.name not in both]
            to_deactivate = [c for c in to_deactivate if c.name not in both]
        staying = [c for c in self.controllers.values() if c.active and c not in to_deactivate]
        for controller in list(to_activate):
            if controller.active:
                continue
            claimed = {i for other in staying for i in other.command_interfaces}
            conflict = sorted(claimed.intersection(controller.command_interfaces))
            if conflict:
                holders = [o.name for o in staying if set(o.command_interfaces) & set(conflict)]
                problems.append(
                    f"cannot activate {controller.name}: {', '.join(conflict)} "
                    f"{'is' if len(conflict) == 1 else 'are'} claimed by {', '.join(holders)}"
                )
                to_activate.remove(controller)
            else:
                staying.append(controller)
        if problems and strict:
            message = "switch refused (STRICT): " + "; ".join(problems)
            log.warning(message)
            return False, message
        done = []
        for controller in to_deactivate:
            if controller.active:
                controller.deactivate(data)
                done.append(f"deactivated {controller.name}")
        for controller in to_activate:
            if not controller.active:
                controller.activate(data)
                done.append(f"activated {controller.name}")
        summary = ", ".join(done) if done else "nothing to switch"
        if problems:
            summary += "; skipped: " + "; ".join(problems)
        log.info("controller switch: %s", summary)
        return True, summary
