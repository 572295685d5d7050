"""Read every required input port at once and report all the missing ones in one message.

MoveIt Pro's ``getRequiredInputs(getInput<A>(..), getInput<B>(..))`` returns the values or one error;
the Python form returns a tuple or raises :class:`MissingInputsError`, whose message names every port
that has no value (not only the first).
"""

from __future__ import annotations

from typing import Any

from kinema.errors import ObjectiveError


class MissingInputsError(ObjectiveError):
    """One or more required input ports have no usable value."""

    def __init__(self, node_path: str, problems: dict[str, str]) -> None:
        listing = "; ".join(f"'{port}': {problem}" for port, problem in problems.items())
        where = f" of '{node_path}'" if node_path else ""
        super().__init__(f"Failed to get required values from input data ports{where}: {listing}")
        self.node_path = node_path
        self.problems = problems


def get_required_inputs(node: Any, *names: str) -> tuple[Any, ...]:
    """Return the values of the input ports ``names`` of ``node``, in order.

    Args:
        node: a behavior (any BT node with ``get_input``).
        names: the port names to read.

    Raises:
        MissingInputsError: naming every port that is missing or cannot be converted.
    """
    values: list[Any] = []
    problems: dict[str, str] = {}
    for name in names:
        try:
            value = node.get_input(name)
        except Exception as error:
            problems[name] = str(error) or type(error).__name__
            continue
        if value is None:
            problems[name] = "no value (set it in the objective or give the port a default)"
            continue
        values.append(value)
    if problems:
        raise MissingInputsError(str(getattr(node, "full_path", "") or getattr(node, "name", "")), problems)
    return tuple(values)
