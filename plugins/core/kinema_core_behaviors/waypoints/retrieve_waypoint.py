"""RetrieveWaypoint: a saved waypoint's joint state, for the joints of one planning group."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import FormerSpelling, PortInfo, ServiceClientBehavior, input_port, output_port
from kinema.behaviors.cell_ports import cell_input_port
from kinema.errors import did_you_mean
from kinema.waypoint_services import GET_WAYPOINTS_SERVICE as GET_WAYPOINTS

from ..messages.conversions import joint_state_message


class RetrieveWaypoint(ServiceClientBehavior["moveit_studio_agent_msgs/srv/GetWaypoints"]):
    """Looks up waypoint ``waypoint_name`` in the config's waypoints file and writes its joint state.

    Only the joints of ``joint_group_name`` are kept (a waypoint also stores the gripper opening, which
    an arm motion must not try to reach). The waypoints come from the runtime's waypoint service, so
    waypoints saved while the runtime runs are found at once.
    """

    subcategory = "Motion - Planning"
    # MoveIt Studio's MoveToWaypoint behavior is the core "Move to Waypoint" subtree today, which is built
    # on this behavior; its planning_group_name is the subtree's joint_group_name.
    former_spellings = (
        FormerSpelling(
            "MoveToWaypoint",
            current_id="Move to Waypoint",
            subtree=True,
            ports={"planning_group_name": "joint_group_name"},
        ),
    )

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("waypoint_name", str, "", "Name of the waypoint, as saved in the waypoints file."),
            cell_input_port(
                "joint_group_name",
                str,
                "planning_group",
                "Planning group whose joints are kept (empty: the default below).",
            ),
            output_port(
                "waypoint_joint_state",
                None,
                "{target_joint_state}",
                "The waypoint's joint state (sensor_msgs/JointState).",
            ),
        ]

    def get_service_name(self) -> str:
        return GET_WAYPOINTS

    def get_response_timeout(self) -> float:
        return 5.0

    def create_request(self) -> dict[str, Any]:
        return {}

    def process_response(self, response: Any) -> bool:
        name = str(self.get_input("waypoint_name"))
        group = str(self.get_input("joint_group_name"))
        if not response.status.success:
            self.logger.publish_failure(
                f"RetrieveWaypoint: cannot read the waypoints: {response.status.error_message}"
            )
            return False
        waypoints = {str(w.name): w for w in response.waypoints}
        waypoint = waypoints.get(name)
        if waypoint is None:
            self.logger.publish_failure(
                f"RetrieveWaypoint: unknown waypoint {name!r}; {did_you_mean(name, list(waypoints))}"
            )
            return False
        names = [str(n) for n in waypoint.joint_state.name]
        positions = [float(p) for p in waypoint.joint_state.position]
        model = self.context.robot_model
        if model is not None:
            unknown = [n for n in names if n not in model.moving_joint_names]
            if unknown:
                # Edited by hand while the runtime runs (it reads the file again, unchecked): moving the
                # other joints would end the motion somewhere nobody saved.
                self.logger.publish_failure(
                    f"RetrieveWaypoint: waypoint {name!r} names joint {unknown[0]!r}, which robot "
                    f"{model.name!r} does not have; {did_you_mean(unknown[0], model.moving_joint_names)} "
                    "(correct it in the waypoints file, or save the waypoint again)"
                )
                return False
        if group:
            if model is not None:
                if group not in model.groups:
                    self.logger.publish_failure(
                        f"RetrieveWaypoint: unknown planning group {group!r}; "
                        f"{did_you_mean(group, list(model.groups))}"
                    )
                    return False
                members = set(model.group(group).joint_names)
                kept = [(n, p) for n, p in zip(names, positions, strict=True) if n in members]
                if not kept:
                    self.logger.publish_failure(
                        f"RetrieveWaypoint: waypoint {name!r} has no joint of group {group!r} "
                        f"(it stores {', '.join(names)})"
                    )
                    return False
                names, positions = [n for n, _ in kept], [p for _, p in kept]
        self.set_output("waypoint_joint_state", joint_state_message(names, positions))
        return True
