"""``ServiceClientBehavior["example_interfaces/srv/AddTwoInts"]``: naming the interface a base talks.

Kinema's transport names interfaces by their ROS type name (``pkg/srv/Name``), so the subscript is that
string. ``Base[type_name]`` returns a subclass of ``Base`` whose interface class attribute is set; an
author derives from it. Setting the class attribute directly is equivalent.
"""

from __future__ import annotations

import re

from kinema.errors import PluginError

_TYPE_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*/(msg|srv|action)/[A-Za-z_][A-Za-z0-9_]*$")


def parametrize(base: type, attribute: str, kind: str, type_name: object) -> type:
    """Return a subclass of ``base`` with ``attribute = type_name`` after checking the name's shape.

    Raises:
        PluginError: ``type_name`` is not ``pkg/<kind>/Name``.
    """
    if not isinstance(type_name, str) or not _TYPE_NAME.match(type_name) or f"/{kind}/" not in type_name:
        raise PluginError(
            f"{base.__name__}[...] takes a ROS {kind} type name like 'pkg/{kind}/Name', got {type_name!r}"
        )
    namespace = {"__slots__": (), "__module__": base.__module__, attribute: type_name}
    return type(f"{base.__name__}[{type_name}]", (base,), namespace)
