"""ListControllers: the names of the controllers the controller manager has, filtered by kind and state."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import PortInfo, ServiceClientBehavior, input_port, output_port

KINDS = ("", "command", "state")
STATES = ("", "active", "inactive")


class ListControllers(ServiceClientBehavior["controller_manager_msgs/srv/ListControllers"]):
    """Writes the names of the controllers matching ``type`` and ``state`` to ``controller_list``.

    ``type``: ``command`` keeps controllers that command joints (trajectory, gripper), ``state`` keeps
    the ones that only read (broadcasters), ``''`` keeps all. ``state``: ``active``, ``inactive`` or
    ``''`` for any.
    """

    subcategory = "Controllers"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "controller_list_action_name",
                str,
                "/controller_manager/list_controllers",
                "The controller manager's ListControllers service.",
            ),
            input_port("type", str, "", "command, state, or '' for every controller."),
            input_port("state", str, "", "active, inactive, or '' for any state."),
            output_port(
                "controller_list", list[str], "{controller_list}", "Names of the matching controllers."
            ),
        ]

    def get_service_name(self) -> str:
        return str(self.get_input("controller_list_action_name"))

    def create_request(self) -> dict[str, Any]:
        return {}

    def process_response(self, response: Any) -> bool:
        kind = str(self.get_input_or("type", "")).strip().lower()
        state = str(self.get_input_or("state", "")).strip().lower()
        if kind not in KINDS:
            self.logger.publish_failure(
                f"ListControllers: type must be one of command, state or '', got {kind!r}"
            )
            return False
        if state not in STATES:
            self.logger.publish_failure(
                f"ListControllers: state must be one of active, inactive or '', got {state!r}"
            )
            return False
        names = []
        for controller in response.controller:
            commands = len(controller.required_command_interfaces) > 0
            if (kind == "command" and not commands) or (kind == "state" and commands):
                continue
            if state and str(controller.state) != state:
                continue
            names.append(str(controller.name))
        self.set_output("controller_list", names)
        return True
