"""RIHS01 type hashes (REP-2016), the ``RIHS01_<sha256>`` strings rmw_zenoh puts in keys and tokens.

A hash covers a type's field list and every type it references, serialised as the JSON of a
``type_description_interfaces/TypeDescription`` without default values. Services and actions hash
synthetic wrapper structs (``request_message``/``response_message``/``event_message`` and
``goal``/``result``/``feedback``/``send_goal_service``/``get_result_service``/``feedback_message``),
which the registry builds; this module only turns field definitions into the hash.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from typing import Any

from rosbags.typesys.base import Nodetype

# type_description_interfaces/msg/FieldType ids. `.msg` `char` is an alias of uint8 in rosidl (the IDL
# the hash is computed from never sees `char`), and `byte` is `octet`.
_FIELD_TYPE_IDS: dict[str, int] = {
    "int8": 2,
    "uint8": 3,
    "char": 3,
    "int16": 4,
    "uint16": 5,
    "int32": 6,
    "uint32": 7,
    "int64": 8,
    "uint64": 9,
    "float32": 10,
    "float64": 11,
    "float128": 12,
    "bool": 15,
    "byte": 16,
    "octet": 16,
    "string": 17,
    "wstring": 18,
}
_NESTED = 1
_BOUNDED_STRING = 21
_BOUNDED_WSTRING = 22
_ARRAY_OFFSET = 48
_BOUNDED_SEQUENCE_OFFSET = 96
_SEQUENCE_OFFSET = 144

# rosidl gives an empty struct one dummy member; the hash includes it.
_EMPTY_STRUCT_MEMBER = ("structure_needs_at_least_one_member", (Nodetype.BASE, ("uint8", 0)))

FieldDefs = Mapping[str, tuple[Any, list[tuple[str, Any]]]]
"""type name -> (constants, [(field name, rosbags field descriptor)]), as in ``Typestore.fielddefs``."""


def _field_type(desc: Any) -> tuple[dict[str, Any], str | None]:
    offset, capacity = 0, 0
    kind, rest = desc
    if kind == Nodetype.ARRAY:
        offset, capacity = _ARRAY_OFFSET, rest[1]
        kind, rest = rest[0]
    elif kind == Nodetype.SEQUENCE:
        bound = rest[1]
        offset, capacity = (_BOUNDED_SEQUENCE_OFFSET, bound) if bound else (_SEQUENCE_OFFSET, 0)
        kind, rest = rest[0]
    nested: str | None = None
    string_capacity = 0
    if kind == Nodetype.NAME:
        type_id, nested = _NESTED, rest
    else:
        base, bound = rest
        if base in ("string", "wstring") and bound:
            type_id, string_capacity = (_BOUNDED_STRING if base == "string" else _BOUNDED_WSTRING), bound
        else:
            type_id = _FIELD_TYPE_IDS[base]
    return (
        {
            "type_id": type_id + offset,
            "capacity": capacity,
            "string_capacity": string_capacity,
            "nested_type_name": nested or "",
        },
        nested,
    )


def _description(name: str, defs: FieldDefs, seen: dict[str, dict[str, Any]]) -> dict[str, Any]:
    if name in seen:
        return seen[name]
    try:
        fields = list(defs[name][1]) or [_EMPTY_STRUCT_MEMBER]
    except KeyError:
        raise KeyError(f"type {name!r} is referenced but not defined") from None
    described: list[dict[str, Any]] = []
    struct = {"type_name": name, "fields": described}
    seen[name] = struct
    for field_name, desc in fields:
        field_type, nested = _field_type(desc)
        described.append({"name": field_name, "type": field_type})
        if nested is not None:
            _description(nested, defs, seen)
    return struct


def type_description_json(name: str, defs: FieldDefs) -> str:
    """Return the JSON text REP-2016 hashes for ``name`` (compact separators as rosidl writes them)."""
    seen: dict[str, dict[str, Any]] = {}
    main = _description(name, defs, seen)
    referenced = [seen[key] for key in sorted(seen) if key != name]
    document = {"type_description": main, "referenced_type_descriptions": referenced}
    return json.dumps(document, separators=(", ", ": "))


def rihs01(name: str, defs: FieldDefs) -> str:
    """Return ``RIHS01_<sha256 hex>`` of ``name``; ``defs`` holds it and every type it references."""
    digest = hashlib.sha256(type_description_json(name, defs).encode()).hexdigest()
    return f"RIHS01_{digest}"
