"""MyBehavior: the tutorial's first behavior, an asynchronous adder."""

from __future__ import annotations

from kinema.behaviors import AsyncBehavior, PortInfo, input_port, output_port


class MyBehavior(AsyncBehavior):
    """Adds ``int_1`` and ``int_2`` and writes the sum to ``int_out``."""

    subcategory = "Example Behaviors"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("int_1", int, 0, "The first number to add."),
            input_port("int_2", int, 0, "The second number to add."),
            output_port("int_out", int, "{int_out}", "The sum of int_1 and int_2."),
        ]

    async def do_work(self) -> bool:
        int_1, int_2 = self.get_required_inputs("int_1", "int_2")
        self.set_output("int_out", int_1 + int_2)
        return True
