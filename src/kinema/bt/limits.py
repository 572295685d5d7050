"""Size limits on what a running objective may build, so a runaway tree fails instead of eating the machine.

BT.CPP has no such limits; Kinema adds them because an objective runs unattended next to a robot
(documented in docs/runtime.md, "Limits"):

* a string a script produces (``..``, ``+``, ``+=``) holds at most :data:`MAX_SCRIPT_STRING_CHARS`
  characters: ``s := s .. s`` on every tick fails after about 20 ticks;
* a value written to a blackboard entry (``Blackboard.set``: node outputs, SetBlackboard, parameter
  overrides) is a string or bytes of at most :data:`MAX_ENTRY_CHARS` characters, or a list, tuple,
  dict or set of at most :data:`MAX_ENTRY_ITEMS` items;
* a tree has at most :data:`MAX_TREE_NODES` nodes (node uids are 16-bit in BT.CPP's and Groot2's
  formats and in the status streams).

Passing one raises :class:`~kinema.bt.errors.BTRuntimeError` (a script: ScriptError) naming the
limit, which fails the objective with the node's path.
"""

from __future__ import annotations

from typing import Any

from kinema.bt.errors import BTRuntimeError

#: Characters in one string produced by a script (1 Mi).
MAX_SCRIPT_STRING_CHARS = 1 << 20

#: Characters (or bytes) in one string/bytes blackboard value (16 Mi).
MAX_ENTRY_CHARS = 1 << 24

#: Items in one list/tuple/dict/set blackboard value (1 Mi).
MAX_ENTRY_ITEMS = 1 << 20

#: Nodes in one tree, SubTree nodes and the nodes of every SubTree instance included.
MAX_TREE_NODES = 65_535

_CHARS = (str, bytes, bytearray)
_ITEMS = (list, tuple, dict, set, frozenset)
#: The value classes whose size is checked (exact classes: a cheap test on every write).
SIZED_TYPES = frozenset(_CHARS + _ITEMS)


def check_entry_value(key: str, value: Any) -> None:
    """Raise if ``value`` is too large to store under blackboard ``key``.

    Raises:
        BTRuntimeError: naming the key, the size and the limit.
    """
    cls = value.__class__
    if cls in _CHARS:
        if len(value) > MAX_ENTRY_CHARS:
            raise BTRuntimeError(
                f"blackboard entry [{key}]: a value of {len(value):,} characters passes the limit of "
                f"{MAX_ENTRY_CHARS:,} (kinema.bt.limits.MAX_ENTRY_CHARS)"
            )
    elif cls in _ITEMS and len(value) > MAX_ENTRY_ITEMS:
        raise BTRuntimeError(
            f"blackboard entry [{key}]: a {cls.__name__} of {len(value):,} items passes the limit of "
            f"{MAX_ENTRY_ITEMS:,} (kinema.bt.limits.MAX_ENTRY_ITEMS)"
        )


def script_string_too_long(length: int) -> str:
    """The error text for a script string of ``length`` characters."""
    return (
        f"a script string of {length:,} characters passes the limit of {MAX_SCRIPT_STRING_CHARS:,} "
        "(kinema.bt.limits.MAX_SCRIPT_STRING_CHARS)"
    )
