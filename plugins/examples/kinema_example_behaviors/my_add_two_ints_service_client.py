"""MyAddTwoIntsServiceClient (registered as MyServiceClient): the tutorial's service-client behavior."""

from __future__ import annotations

from kinema.behaviors import PortInfo, ServiceClientBehavior, input_port, output_port
from kinema.interfaces.typed import AddTwoInts


class MyAddTwoIntsServiceClient(ServiceClientBehavior[AddTwoInts.Request, AddTwoInts.Response]):
    """Asks an AddTwoInts service for ``addend1 + addend2``, writes the sum to ``result`` and shows it.

    Run `kinema example add-two-ints-server` to have a server on ``/add_two_ints``.
    """

    subcategory = "Example Behaviors"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("service_name", str, "/add_two_ints", "The AddTwoInts service to call."),
            input_port("addend1", int, 0, "The first number to add."),
            input_port("addend2", int, 0, "The second number to add."),
            output_port("result", int, "{result}", "The sum the service returned."),
        ]

    def create_request(self) -> AddTwoInts.Request:
        addend1, addend2 = self.get_required_inputs("addend1", "addend2")
        return AddTwoInts.Request(a=int(addend1), b=int(addend2))

    def process_response(self, response: AddTwoInts.Response) -> bool:
        self.set_output("result", response.sum)
        self.logger.publish_info(f"Sum: {response.sum}")
        return True
