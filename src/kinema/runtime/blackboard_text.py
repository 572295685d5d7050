"""Blackboard values as one short line of text, for the blackboard stream, recordings and displays.

The guarantee: rendering a value costs about the same whatever its size. A value larger than
:data:`VALUE_SIZE_CAP` (a string, bytes, an array) is never formatted: it renders as a marker naming its
type and size (``<str: 1992294 bytes, not shown>``); lists are cut to :data:`MAX_LIST_ITEMS` items and
strings inside values to :data:`MAX_VALUE_CHARS` characters *before* YAML sees them, and the text is cut
to :data:`MAX_VALUE_CHARS`. (A 1.9 MB attribute once spent 22 s in ``yaml.safe_dump`` on the tick thread.)
Renderings happen off the tick thread all the same (:mod:`kinema.runtime.background_work`).
"""

from __future__ import annotations

import sys
from typing import Any

# Blackboard values are rendered for display; longer renderings are cut.
MAX_VALUE_CHARS = 2000
MAX_LIST_ITEMS = 16
# Beyond this many bytes a value is not rendered at all: a marker says its type and size.
VALUE_SIZE_CAP = 64 * 1024

# Texts of plain values already rendered (short str, int, bool, None: equal values of one type render
# alike). Every blackboard snapshot renders every entry twice (stream and recording), YAML takes about
# 100 µs for a short string, and a tree's scopes hold the same few strings and numbers snapshot after
# snapshot.
_RENDERED: dict[tuple[type, Any], str] = {}
_RENDERED_MOST = 4096
_PLAIN = frozenset({str, int, bool, type(None)})


def size_marker(value: Any) -> str | None:
    """``<type: N bytes, not shown>`` for a value beyond :data:`VALUE_SIZE_CAP`; None for others.

    Only sizes known without walking the value count: strings, bytes, numpy arrays.
    """
    size: int | None = None
    unit = "bytes"
    if isinstance(value, str):
        size, unit = len(value), "characters"
    elif isinstance(value, bytes | bytearray | memoryview):
        size = len(value)
    else:
        numpy = sys.modules.get("numpy")
        if numpy is not None and isinstance(value, numpy.ndarray):
            size = int(value.nbytes)
    if size is None or size <= VALUE_SIZE_CAP:
        return None
    return f"<{type(value).__name__}: {size} {unit}, not shown>"


def render_value(value: Any) -> str:
    """A blackboard value as one line of YAML flow text (messages as their fields), cut when long."""
    kind = type(value)
    if kind in _PLAIN and (kind is not str or len(value) <= MAX_VALUE_CHARS):
        key = (kind, value)
        text = _RENDERED.get(key)
        if text is None:
            if len(_RENDERED) >= _RENDERED_MOST:
                _RENDERED.clear()
            text = _RENDERED[key] = _render(value)
        return text
    return _render(value)


def _render(value: Any) -> str:
    import yaml

    marker = size_marker(value)
    if marker is not None:
        return marker
    try:
        data = _preview(value)
        flow = _flow(data) if type(data) is dict or type(data) is list else None
        if flow is not None:
            text = flow
        elif isinstance(data, str | int | float | bool | list | dict | type(None)):
            text = yaml.safe_dump(data, default_flow_style=True, width=1 << 30).strip()
            if text.endswith("\n..."):
                text = text[:-4].strip()
            text = text.removesuffix("...").strip()
        else:
            text = repr(value)
    except Exception:
        text = repr(value)
    return text if len(text) <= MAX_VALUE_CHARS else text[: MAX_VALUE_CHARS - 1] + "…"


# Strings as they appear inside a YAML flow collection (plain, or quoted when YAML would quote them).
_FLOW_STRINGS: dict[str, str] = {}
# Longer keys are written as complex keys (``? key``); longer strings are left to YAML.
_FLOW_KEY_MOST = 128
_FLOW_STRING_MOST = 256


class _NotFlow(Exception):
    """A value the fast flow writer leaves to YAML."""


def _flow(data: dict[Any, Any] | list[Any]) -> str | None:
    """``data`` as ``yaml.safe_dump(data, default_flow_style=True)`` writes it, without YAML's cost.

    Only for dicts with non-empty string keys, lists, short one-line strings, ints, floats, bools and None
    (what a message's preview holds), each collection met once; None for anything else, which YAML then
    renders. A trajectory's preview took
    YAML about 10 ms per rendering, on the thread that competes with the tick thread and the simulation.
    """
    parts: list[str] = []
    try:
        _flow_into(data, parts, set())
    except _NotFlow:
        return None
    return "".join(parts)


def _flow_into(value: Any, parts: list[str], seen: set[int]) -> None:
    kind = type(value)
    if kind is list or kind is dict:
        if id(value) in seen:
            raise _NotFlow  # YAML writes a collection met twice as an anchor and aliases
        seen.add(id(value))
    if kind is str:
        parts.append(_flow_string(value))
    elif kind is float:
        parts.append(_flow_float(value))
    elif kind is bool:
        parts.append("true" if value else "false")
    elif kind is int:
        parts.append(str(value))
    elif value is None:
        parts.append("null")
    elif kind is list:
        parts.append("[")
        for index, item in enumerate(value):
            if index:
                parts.append(", ")
            _flow_into(item, parts, seen)
        parts.append("]")
    elif kind is dict:
        if not all(type(key) is str and 0 < len(key) < _FLOW_KEY_MOST for key in value):
            raise _NotFlow
        parts.append("{")
        for index, key in enumerate(sorted(value)):
            if index:
                parts.append(", ")
            parts.append(_flow_string(key))
            parts.append(": ")
            _flow_into(value[key], parts, seen)
        parts.append("}")
    else:
        raise _NotFlow


def _flow_float(value: float) -> str:
    # SafeRepresenter.represent_float's spelling.
    if value != value:
        return ".nan"
    if value == float("inf"):
        return ".inf"
    if value == float("-inf"):
        return "-.inf"
    text = repr(value).lower()
    if "." not in text and "e" in text:
        text = text.replace("e", ".0e", 1)
    return text


def _flow_string(value: str) -> str:
    text = _FLOW_STRINGS.get(value)
    if text is not None:
        return text
    if len(value) > _FLOW_STRING_MOST or not value.isprintable():
        raise _NotFlow  # long or multi-line strings: YAML's own line breaking applies
    import yaml

    text = yaml.safe_dump([value], default_flow_style=True, width=1 << 30).strip()[1:-1]
    if len(_FLOW_STRINGS) >= _RENDERED_MOST:
        _FLOW_STRINGS.clear()
    _FLOW_STRINGS[value] = text
    return text


# Nesting shown before "...": deeper values (a JSON bomb, a self-referencing list) are not walked.
MAX_DEPTH = 24


def _preview(value: Any, depth: int = 0) -> Any:
    """``to_dict(value)`` with every list cut to MAX_LIST_ITEMS items (plus a "... N more" marker).

    Lists and mappings are cut before their items are converted, strings before YAML sees them: the
    text is cut at MAX_VALUE_CHARS anyway, and converting and YAML-dumping a whole trajectory (hundreds
    of points) at every blackboard snapshot stalled the tree (and the simulation sharing the process)
    for most of each second.
    """
    import dataclasses
    import itertools

    import numpy as np

    from kinema.transport.messages import to_dict

    if depth > MAX_DEPTH:
        return "..."
    if isinstance(value, str):
        return value[:MAX_VALUE_CHARS]  # the text is cut there anyway: YAML never sees more
    marker = size_marker(value)
    if marker is not None:
        return marker
    if hasattr(value, "__msgtype__") and dataclasses.is_dataclass(value):
        return {
            field.name: _preview(getattr(value, field.name), depth + 1)
            for field in dataclasses.fields(value)
            if field.default is dataclasses.MISSING and field.name != "__msgtype__"
        }
    if isinstance(value, dict):
        shown = {
            key: _preview(item, depth + 1) for key, item in itertools.islice(value.items(), MAX_LIST_ITEMS)
        }
        if len(value) > MAX_LIST_ITEMS:
            shown["..."] = f"{len(value) - MAX_LIST_ITEMS} more"
        return shown
    if isinstance(value, list | tuple | np.ndarray):
        head = [_preview(item, depth + 1) for item in value[:MAX_LIST_ITEMS]]
        if len(value) > MAX_LIST_ITEMS:
            return [*head, f"... {len(value) - MAX_LIST_ITEMS} more"]
        return head
    return to_dict(value)
