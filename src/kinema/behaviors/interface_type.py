"""``ServiceClientBehavior[AddTwoInts.Request, AddTwoInts.Response]``: naming the interface a base talks.

The subscript is either the interface's message classes (from ``kinema.interfaces.typed``, or any
class the transport builds), which also types the base's hooks for ``mypy`` and editors, or the ROS
type name string (``"example_interfaces/srv/AddTwoInts"``), which leaves them ``Any``.
``Base[...]`` returns a subclass of ``Base`` whose interface class attribute is set; an author derives
from it. Setting the class attribute directly is equivalent.
"""

from __future__ import annotations

import re

from kinema.errors import PluginError

_TYPE_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*/(msg|srv|action)/[A-Za-z_][A-Za-z0-9_]*$")


def parametrize(
    base: type, attribute: str, kind: str, type_name: object, parts: tuple[str, ...] = ()
) -> type:
    """Return a subclass of ``base`` with ``attribute = type_name`` after checking the name's shape.

    ``type_name`` may also be a tuple of the interface's message classes in the order of ``parts``
    (``("Request", "Response")``); the type name is read from them.

    Raises:
        PluginError: ``type_name`` is not ``pkg/<kind>/Name``, or the classes are not the parts of
            one interface.
    """
    if isinstance(type_name, tuple) and parts:
        type_name = _type_name_of_parts(base, kind, type_name, parts)
    if not isinstance(type_name, str) or not _TYPE_NAME.match(type_name) or f"/{kind}/" not in type_name:
        raise PluginError(
            f"{base.__name__}[...] takes a ROS {kind} type name like 'pkg/{kind}/Name', got {type_name!r}"
        )
    namespace = {"__slots__": (), "__module__": base.__module__, attribute: type_name}
    return type(f"{base.__name__}[{type_name}]", (base,), namespace)


def _type_name_of_parts(base: type, kind: str, classes: tuple[object, ...], parts: tuple[str, ...]) -> str:
    """``pkg/<kind>/Name`` from the message classes ``Name_<part>`` of one interface, in order."""
    names = [getattr(cls, "__msgtype__", None) for cls in classes]
    expected = ", ".join(f"Name.{part}" for part in parts)
    first = names[0] if names else None
    if (
        len(classes) != len(parts)
        or not isinstance(first, str)
        or not first.endswith(f"_{parts[0]}")
        or f"/{kind}/" not in first
    ):
        raise PluginError(
            f"{base.__name__}[...] takes the message classes {expected} of one {kind} interface "
            f"(kinema.interfaces.typed), got {', '.join(map(repr, classes))}"
        )
    type_name = first[: -len(parts[0]) - 1]
    wanted = [f"{type_name}_{part}" for part in parts]
    if names != wanted:
        raise PluginError(
            f"{base.__name__}[...]: the message classes must be {', '.join(wanted)} in that order, "
            f"got {', '.join(str(name) for name in names)}"
        )
    return type_name
