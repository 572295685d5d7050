"""Reading a vector: GetElementOfVector and GetSizeOfVector."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from ..messages.ports import fails_on_bad_input, index_in, read_input, read_vector, write_output


class GetElementOfVector(SyncBehavior):
    """Writes the element at ``index`` of ``vector_in`` to ``element``; fails if the index is outside it."""

    subcategory = "Vector Handling"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("vector_in", None, "{vector}", "The vector to read."),
            input_port("index", int, 0, "Position of the element (0 = first)."),
            output_port("element", None, "{element}", "The element at that position."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        vector = read_vector(self, "vector_in")
        write_output(self, "element", vector[index_in(self, "index", read_input(self, "index"), vector)])
        return NodeStatus.SUCCESS


class GetSizeOfVector(SyncBehavior):
    """Writes the number of elements of ``vector_in`` to ``vector_size``."""

    subcategory = "Vector Handling"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("vector_in", None, "{vector}", "The vector to measure."),
            output_port("vector_size", int, "{vector_size}", "Its number of elements."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        self.set_output("vector_size", len(read_vector(self, "vector_in")))
        return NodeStatus.SUCCESS
