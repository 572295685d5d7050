"""Editing a vector: PushBackVector, InsertInVector, RemoveFromVector, ReplaceInVector.

Each reads ``input_vector`` and writes the edited copy to ``output_vector`` (usually the same
blackboard entry). The element must match the kind of the elements already there
(:mod:`.element_type`); an index outside the vector fails, naming the valid range.
"""

from __future__ import annotations

from typing import Any

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from ..messages.ports import fails_on_bad_input, index_in, port_error, read_input, read_vector, write_output
from .element_type import mismatch

SUBCATEGORY = "Vector Handling"


def _vector_ports(*extra: PortInfo) -> list[PortInfo]:
    return [
        input_port(
            "input_vector",
            None,
            "{vector}",
            "The vector to edit (any element kind). MoveIt Pro's default is not public; Kinema's: {vector}.",
        ),
        *extra,
        output_port(
            "output_vector",
            None,
            "{vector}",
            "The edited vector. MoveIt Pro's objectives point it at the same entry as input_vector, so "
            "that is Kinema's default.",
        ),
    ]


def _element(node: Any, vector: list[Any]) -> Any:
    element = read_input(node, "element")
    problem = mismatch(vector, element)
    if problem is not None:
        raise port_error(node, "element", problem, "give an element of the vector's type")
    return element


class PushBackVector(SyncBehavior):
    """Appends ``element`` to the end of ``input_vector`` and writes the result to ``output_vector``."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _vector_ports(input_port("element", None, "{element}", "The element to append."))

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        vector = read_vector(self, "input_vector")
        vector.append(_element(self, vector))
        write_output(self, "output_vector", vector)
        return NodeStatus.SUCCESS


class InsertInVector(SyncBehavior):
    """Inserts ``element`` before position ``index`` of ``input_vector`` (``index`` = size appends)."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _vector_ports(
            input_port("element", None, "{element}", "The element to insert."),
            input_port("index", int, 0, "Position the element takes (0 = front)."),
        )

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        vector = read_vector(self, "input_vector")
        index = index_in(self, "index", read_input(self, "index"), vector, insert=True)
        vector.insert(index, _element(self, vector))
        write_output(self, "output_vector", vector)
        return NodeStatus.SUCCESS


class RemoveFromVector(SyncBehavior):
    """Removes the element at ``index`` of ``input_vector``."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _vector_ports(input_port("index", int, 0, "Position of the element to remove."))

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        vector = read_vector(self, "input_vector")
        del vector[index_in(self, "index", read_input(self, "index"), vector)]
        write_output(self, "output_vector", vector)
        return NodeStatus.SUCCESS


class ReplaceInVector(SyncBehavior):
    """Replaces the element at ``index`` of ``input_vector`` with ``element``."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _vector_ports(
            input_port("element", None, "{element}", "The new element."),
            input_port("index", int, 0, "Position of the element to replace."),
        )

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        vector = read_vector(self, "input_vector")
        index = index_in(self, "index", read_input(self, "index"), vector)
        vector[index] = _element(self, vector)
        write_output(self, "output_vector", vector)
        return NodeStatus.SUCCESS
