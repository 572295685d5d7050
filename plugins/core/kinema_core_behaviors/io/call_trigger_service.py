"""CallTriggerService: call a ``std_srvs/Trigger`` service and succeed when it reports success."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import PortInfo, ServiceClientBehavior, input_port


class CallTriggerService(ServiceClientBehavior["std_srvs/srv/Trigger"]):
    """Calls the ``std_srvs/Trigger`` service ``service_name``; fails if it answers ``success: false``.

    The service's ``message`` is shown as a toast (info on success, failure otherwise).
    """

    subcategory = "ROS Messaging"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("service_name", str, "", "The Trigger service to call, e.g. /start_recording."),
            input_port("response_timeout", float, 3.0, "Seconds to wait for the response."),
            input_port(
                "wait_for_server_available_timeout",
                float,
                3.0,
                "Seconds to wait for the service to appear (Kinema waits once, within the response time "
                "budget of both).",
            ),
        ]

    def create_request(self) -> Any:
        return {}

    def get_response_timeout(self) -> float:
        timeout = float(self.get_input("response_timeout"))
        waiting = float(self.get_input("wait_for_server_available_timeout"))
        return max(timeout, 0.0) + max(waiting, 0.0)

    def process_response(self, response: Any) -> bool:
        text = str(response.message)
        if not response.success:
            self.logger.publish_failure(
                f"{self.get_service_name()} answered success=false" + (f": {text}" if text else "")
            )
            return False
        if text:
            self.logger.publish_info(f"{self.get_service_name()}: {text}")
        return True
