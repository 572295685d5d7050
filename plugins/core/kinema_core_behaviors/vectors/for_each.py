"""ForEach and ForEachUntilSuccess: tick the child once per element of a vector.

Before each run of the child the element is written to ``out`` and its position to ``index``. The vector
is read once, when the loop starts, so the child may edit the vector without changing the iteration.
Between two elements the decorator returns RUNNING once (as BT.CPP's Repeat does after a synchronous
child), so a long vector never holds the tick thread.
"""

from __future__ import annotations

from typing import Any

from kinema.behaviors import NodeStatus, PortInfo, input_port, output_port
from kinema.behaviors.base import Behavior
from kinema.bt import DecoratorNode

from ..messages.ports import PortValueError, read_vector, write_output

IDLE, RUNNING, SUCCESS, FAILURE, SKIPPED = (
    NodeStatus.IDLE,
    NodeStatus.RUNNING,
    NodeStatus.SUCCESS,
    NodeStatus.FAILURE,
    NodeStatus.SKIPPED,
)


class _VectorLoop(Behavior, DecoratorNode):
    """Shared loop: subclasses say which child result ends the loop and what an empty vector gives."""

    subcategory = "Vector Handling"
    stop_on: NodeStatus = FAILURE
    if_exhausted: NodeStatus = SUCCESS

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("vector_in", None, "{vector}", "The vector to iterate over (any element type)."),
            output_port("out", None, "{out}", "The current element."),
            output_port("index", int, "{index}", "Position of the current element (0 = first)."),
        ]

    def __init__(self, name: str, config: Any = None) -> None:
        DecoratorNode.__init__(self, name, config)
        self._elements: list[Any] | None = None
        self._position = 0

    def tick(self) -> NodeStatus:
        if self._elements is None:
            try:
                self._elements = read_vector(self, "vector_in")
            except PortValueError as error:
                self.logger.publish_failure(error.message)
                return FAILURE
            self._position = 0
        child = self.child
        assert child is not None
        while self._position < len(self._elements):
            prev = child.status
            if prev is IDLE:
                try:
                    write_output(self, "out", self._elements[self._position])
                    write_output(self, "index", self._position)
                except PortValueError as error:
                    self.logger.publish_failure(error.message)
                    return self._finish(FAILURE)
            status = child.execute_tick()
            if status is RUNNING:
                return RUNNING
            self.reset_child()
            if status is self.stop_on:
                return self._finish(status)
            self._position += 1
            if prev is IDLE and self._position < len(self._elements):
                self.emit_wake_up_signal()
                return RUNNING
        return self._finish(self.if_exhausted)

    def _finish(self, status: NodeStatus) -> NodeStatus:
        self._elements = None
        self._position = 0
        return status

    def halt(self) -> None:
        self._elements = None
        self._position = 0
        DecoratorNode.halt(self)


class ForEach(_VectorLoop):
    """Runs the child for each element of ``vector_in``; fails at the first failure, else succeeds.

    An empty vector succeeds without running the child. A child returning SKIPPED moves on to the next
    element.
    """


class ForEachUntilSuccess(_VectorLoop):
    """Runs the child for each element of ``vector_in`` until one succeeds; fails if none does.

    An empty vector fails (there was nothing that could succeed).
    """

    stop_on = SUCCESS
    if_exhausted = FAILURE
