"""SwitchController: activate and deactivate controllers of the controller manager."""

from __future__ import annotations

import threading
import time
from typing import Any

from kinema.behaviors import AsyncBehavior, FormerSpelling, PortInfo, input_port
from kinema.errors import TransportError

BEST_EFFORT = 1
STRICT = 2
LIST_TYPE = "controller_manager_msgs/srv/ListControllers"
SWITCH_TYPE = "controller_manager_msgs/srv/SwitchController"


def _names(values: list[str]) -> list[str]:
    """Controller names without blanks or the leading '/' MoveIt Pro objectives sometimes give; a value
    may also list several separated by spaces, as MoveIt Studio's objectives wrote them
    ("/arm_controller /gripper_controller"): a controller name has no space."""
    return [name.lstrip("/") for value in values for name in value.split() if name.lstrip("/")]


def conflicting_active(controllers: dict[str, Any], activate: list[str]) -> list[str]:
    """The active controllers, besides ``activate``, that command an interface one of ``activate`` needs.

    ``controllers`` maps names to ListControllers entries (``state``, ``required_command_interfaces``).
    """
    wanted = {i for n in activate if n in controllers for i in controllers[n].required_command_interfaces}
    return [
        name
        for name, controller in controllers.items()
        if controller.state == "active"
        and name not in activate
        and wanted.intersection(controller.required_command_interfaces)
    ]


def switch_request(
    activate: list[str], deactivate: list[str], strictness: int, activate_asap: bool, timeout: float
) -> dict[str, Any]:
    """The controller manager's SwitchController request; a ``timeout`` of 0 or less means none."""
    wait = max(timeout, 0.0)  # ros2_control reads a zero timeout as none
    return {
        "activate_controllers": activate,
        "deactivate_controllers": deactivate,
        "strictness": strictness,
        "activate_asap": activate_asap,
        "timeout": {"sec": int(wait), "nanosec": int((wait % 1.0) * 1e9)},
    }


# How long a listing of the controllers is trusted: as MoveIt's trajectory execution manager, which reads
# the controller states again only when what it knows is older than a second
# (DEFAULT_CONTROLLER_INFORMATION_VALIDITY_AGE), not before every trajectory.
STATES_VALID_FOR = 1.0


class ControllerStates:
    """What this cell's behaviors last learned of the controllers' states, per ListControllers service.

    A controller seen active within :data:`STATES_VALID_FOR` is taken as still active: a motion does not
    ask the controller manager again (SwitchController, then ExecuteTrajectory, asked twice per motion).
    A switch this cell makes forgets what it knew. A switch made elsewhere within that second shows as the
    controller's refusal of the trajectory, as with MoveIt.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._known: dict[str, tuple[float, dict[str, str]]] = {}

    def remember(self, service: str, controllers: dict[str, Any]) -> None:
        """Keep the states of a ListControllers response (``controllers`` by name)."""
        states = {name: str(controller.state) for name, controller in controllers.items()}
        with self._lock:
            self._known[service] = (time.monotonic(), states)

    def forget(self, service: str) -> None:
        """Forget the states (a switch was asked for)."""
        with self._lock:
            self._known.pop(service, None)

    def active(self, service: str, names: list[str]) -> bool:
        """Whether every one of ``names`` was seen active within STATES_VALID_FOR."""
        with self._lock:
            known = self._known.get(service)
        if known is None or time.monotonic() - known[0] > STATES_VALID_FOR:
            return False
        return all(known[1].get(name) == "active" for name in names)


def controller_states(context: Any) -> ControllerStates:
    """The cell's :class:`ControllerStates` (one per behavior context)."""
    states: ControllerStates = context.shared("controller_states", ControllerStates)
    return states


_FOREVER = 1e9  # seconds: "no timeout" for a service call (halting the objective still ends the wait)


class SwitchController(AsyncBehavior):
    """Activates ``activate_controllers`` and deactivates ``deactivate_controllers`` in one switch.

    With ``automatic_deactivation`` (default), active controllers that command the same joints as a
    controller being activated are deactivated in the same switch. With ``automatic_activation``,
    deactivating a controller activates the inactive ones that command the same joints. Activating an
    active controller, or deactivating an inactive one, changes nothing and succeeds.
    """

    subcategory = "Controllers"
    former_spellings = (
        FormerSpelling("ActivateControllers", ports={"controller_names": "activate_controllers"}),
    )

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "controller_switch_action_name",
                str,
                "/controller_manager/switch_controller",
                "The controller manager's SwitchController service.",
            ),
            input_port(
                "controller_list_action_name",
                str,
                "/controller_manager/list_controllers",
                "The controller manager's ListControllers service (for automatic (de)activation).",
            ),
            input_port("activate_controllers", list[str], "", "Controllers to activate (';'-separated)."),
            input_port("deactivate_controllers", list[str], "", "Controllers to deactivate (';'-separated)."),
            input_port(
                "automatic_deactivation",
                bool,
                True,
                "Also deactivate active controllers that command the joints of an activated one.",
            ),
            input_port(
                "automatic_activation",
                bool,
                False,
                "Also activate inactive controllers that command the joints of a deactivated one.",
            ),
            input_port("activate_asap", bool, True, "Start the activated controllers at once."),
            input_port("strictness", int, STRICT, "1: best effort, 2: strict (fail on any problem)."),
            input_port(
                "timeout",
                float,
                10.0,
                "Seconds to wait for the controller manager; 0 or less waits as long as it takes (MoveIt "
                "Pro's objectives pass -1), until the objective is halted.",
            ),
        ]

    async def do_work(self) -> bool:
        import asyncio

        node = self.context.require_node(self.registration_id)
        activate = _names(self.get_input_or("activate_controllers", []))
        deactivate = _names(self.get_input_or("deactivate_controllers", []))
        strictness = int(self.get_input("strictness"))
        given = float(self.get_input("timeout"))
        timeout = given if given > 0 else _FOREVER
        if strictness not in (BEST_EFFORT, STRICT):
            self.logger.publish_failure(
                f"SwitchController: strictness must be 1 (best effort) or 2 (strict), got {strictness}"
            )
            return False
        if not activate and not deactivate:
            self.logger.publish_info("SwitchController: no controller to activate or deactivate")
            return True
        automatic_deactivation = bool(self.get_input("automatic_deactivation"))
        automatic_activation = bool(self.get_input("automatic_activation"))
        list_name = str(self.get_input("controller_list_action_name"))
        known = controller_states(self.context)
        if automatic_deactivation and activate and not deactivate and known.active(list_name, activate):
            # Active a moment ago: nothing to switch, and nothing active can share their interfaces.
            return True
        if (automatic_deactivation and activate) or (automatic_activation and deactivate):
            client = self.context.service_client(node, LIST_TYPE, list_name)
            try:
                listing = await asyncio.wrap_future(client.call_async({}, timeout))
            except TransportError as error:
                self.logger.publish_failure(
                    f"SwitchController: cannot list the controllers ({list_name}): {error}"
                )
                return False
            controllers = {str(c.name): c for c in listing.controller}
            known.remember(list_name, controllers)
            if automatic_deactivation:
                deactivate += [n for n in conflicting_active(controllers, activate) if n not in deactivate]
            if automatic_activation:
                freed = {
                    i
                    for n in deactivate
                    if n in controllers
                    for i in controllers[n].required_command_interfaces
                }
                for name, controller in controllers.items():
                    if (
                        controller.state != "active"
                        and name not in deactivate
                        and freed.intersection(controller.required_command_interfaces)
                    ):
                        activate.append(name)
            states = {name: str(c.state) for name, c in controllers.items()}
            if all(states.get(n) == "active" for n in activate) and all(
                n in states and states[n] != "active" for n in deactivate
            ):
                return True  # already as asked: skip the switch (a round trip per motion)
        switch_name = str(self.get_input("controller_switch_action_name"))
        client = self.context.service_client(node, SWITCH_TYPE, switch_name)
        known.forget(list_name)
        request = switch_request(
            activate, deactivate, strictness, bool(self.get_input("activate_asap")), given
        )
        try:
            response = await asyncio.wrap_future(client.call_async(request, timeout))
        except TransportError as error:
            self.logger.publish_failure(
                f"SwitchController: cannot reach the controller manager ({switch_name}): {error}"
            )
            return False
        if not response.ok:
            self.logger.publish_failure(
                f"SwitchController: the switch (activate {activate or '-'}, deactivate {deactivate or '-'}) "
                f"was refused: {response.message}"
            )
            return False
        return True
