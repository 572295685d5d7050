"""Name rules for node types, tree IDs, ports and instance names (BT.CPP docs/name_validation_rules.md)."""

from __future__ import annotations

import functools
import re

from kinema.bt.ports import RESERVED_PORT_NAMES

_FORBIDDEN = " \t\n\r<>&\"'/\\:*?|."
# The first forbidden character in one regex search (a loop over characters cost registering the bundled
# behaviors several ms); control characters and DEL are forbidden too, UTF-8 beyond ASCII is allowed.
_FIRST_FORBIDDEN = re.compile("[\x00-\x1f\x7f" + re.escape(_FORBIDDEN) + "]")
_FIRST_FORBIDDEN_BUT_SPACE = re.compile("[\x00-\x1f\x7f" + re.escape(_FORBIDDEN.replace(" ", "")) + "]")

PRE_CONDITIONS = ("_failureIf", "_successIf", "_skipIf", "_while")
POST_CONDITIONS = ("_onSuccess", "_onFailure", "_onHalted", "_post")
RESERVED_ATTRIBUTES = frozenset(("name", "ID", "_autoremap", *PRE_CONDITIONS, *POST_CONDITIONS))


def forbidden_char(name: str, *, allow_space: bool = False) -> str | None:
    """The first forbidden character of ``name``, or None (UTF-8 beyond ASCII is allowed)."""
    found = (_FIRST_FORBIDDEN_BUT_SPACE if allow_space else _FIRST_FORBIDDEN).search(name)
    return None if found is None else found.group()


def describe_char(c: str) -> str:
    """How an error message shows a forbidden character."""
    if ord(c) < 32 or ord(c) == 127:
        return f"control character (ASCII {ord(c)})"
    return f"'{c}'"


@functools.lru_cache(maxsize=4096)
def model_name_problem(name: str, *, tree_id: bool = False) -> str | None:
    """Why ``name`` is not a valid node type / tree ID, or None.

    Tree IDs may contain spaces: MoveIt Pro objectives are named like "Move to Waypoint", which
    BT.CPP 4.10's validator would reject; Kinema must load those files unchanged.
    """
    if not name:
        return "Model/Node type name cannot be empty"
    if name in ("Root", "root"):
        return "'Root' is a reserved name and cannot be used as a node type"
    c = forbidden_char(name, allow_space=tree_id)
    if c is not None:
        return f"Model name '{name}' contains forbidden character {describe_char(c)}"
    return None


def port_name_problem(name: str) -> str | None:
    """Why ``name`` is not a valid port name, or None."""
    if not name:
        return "Port name cannot be empty"
    if name[0].isdigit():
        return f"Port name '{name}' cannot start with a digit"
    c = forbidden_char(name)
    if c is not None:
        return f"Port name '{name}' contains forbidden character {describe_char(c)}"
    if name in RESERVED_PORT_NAMES or name in RESERVED_ATTRIBUTES:
        return f"Port name '{name}' is a reserved attribute name"
    return None


@functools.lru_cache(maxsize=4096)
@functools.lru_cache(maxsize=4096)  # attribute names repeat: every element's are checked when compiled
def is_allowed_port_name(name: str) -> bool:
    """``IsAllowedPortName``: an attribute that is treated as a port."""
    if not name or not (name[0].isalpha() and ord(name[0]) < 0x80):
        return False
    if forbidden_char(name) is not None:
        return False
    return name not in RESERVED_ATTRIBUTES


def instance_name_problem(name: str) -> str | None:
    """Why ``name`` is not a valid instance name (only control characters are refused), or None."""
    found = _CONTROL_CHARACTER.search(name)
    if found is None:
        return None
    return f"Instance name '{name}' contains invalid control character (ASCII {ord(found.group())})"


# ASCII control characters other than tab, newline and carriage return, and DEL.
_CONTROL_CHARACTER = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")
