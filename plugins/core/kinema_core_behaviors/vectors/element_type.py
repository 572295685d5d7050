"""What kind of element a vector holds, so a vector of PoseStamped stays one.

Blackboard vectors hold any value (MoveIt Pro's vector behaviors work on ``std::vector<BT::Any>``
besides their typed forms); Kinema keeps them homogeneous by checking a new element against the ones
already there: a message must have the same ROS type, a number may join numbers, a string strings.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any


def kind_of(value: Any) -> str:
    """A short name of the value's kind: the ROS type of a message, else ``number``, ``string``, ..."""
    ros_type = getattr(value, "__msgtype__", None)
    if isinstance(ros_type, str):
        return ros_type
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, int | float):
        return "number"
    if isinstance(value, str):
        return "string"
    if isinstance(value, list | tuple):
        return "vector"
    return type(value).__name__


def mismatch(vector: Sequence[Any], element: Any) -> str | None:
    """Why ``element`` does not belong in ``vector`` (None when it does, or the vector is empty)."""
    if not vector:
        return None
    held, new = kind_of(vector[0]), kind_of(element)
    if held == new:
        return None
    return f"the vector holds {held} elements, the element is a {new}"
