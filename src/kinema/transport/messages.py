"""Messages as Python objects: build them from dicts or YAML flow text, turn them back into dicts/YAML.

Messages are rosbags dataclasses (``std_msgs__msg__String(data=...)``); their constants are class
attributes (``MoveItErrorCodes.SUCCESS``). Numeric arrays are numpy arrays, as rosbags serialises them.
``parse_yaml_flow("example_interfaces/srv/AddTwoInts_Request", "{a: 1, b: 2}")`` accepts what
``ros2 topic pub`` / ``ros2 service call`` take; missing fields get ROS defaults (0, "", false, empty).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

import numpy as np
import yaml
from rosbags.typesys.base import Nodetype

from kinema.errors import TransportError, did_you_mean
from kinema.interfaces import TypeRegistry, load_interfaces

_NUMPY_DTYPES: dict[str, Any] = {
    "bool": np.bool_,
    "byte": np.uint8,
    "char": np.uint8,
    "octet": np.uint8,
    "int8": np.int8,
    "uint8": np.uint8,
    "int16": np.int16,
    "uint16": np.uint16,
    "int32": np.int32,
    "uint32": np.uint32,
    "int64": np.int64,
    "uint64": np.uint64,
    "float32": np.float32,
    "float64": np.float64,
}
_INTEGERS = {
    "byte",
    "char",
    "octet",
    "int8",
    "uint8",
    "int16",
    "uint16",
    "int32",
    "uint32",
    "int64",
    "uint64",
}
_FLOATS = {"float32", "float64", "float128"}


def _at(where: str) -> str:
    return f"{where}: " if where else ""


def _registry(registry: TypeRegistry | None) -> TypeRegistry:
    return registry if registry is not None else load_interfaces()


def _fields(registry: TypeRegistry, type_name: str) -> list[tuple[str, Any]]:
    return registry.fields(type_name)


def _base_default(base: str) -> Any:
    if base == "bool":
        return False
    if base in _INTEGERS:
        return 0
    if base in _FLOATS:
        return 0.0
    return ""


def _convert_base(base: str, value: Any, where: str) -> Any:
    if base == "bool":
        if isinstance(value, bool | np.bool_):
            return bool(value)
    elif base in _INTEGERS:
        if isinstance(value, int | np.integer) and not isinstance(value, bool):
            number = int(value)
            info = np.iinfo(_NUMPY_DTYPES[base])
            if not int(info.min) <= number <= int(info.max):
                raise TransportError(
                    f"{_at(where)}{number} does not fit in {base} ({int(info.min)}..{int(info.max)})"
                )
            return number
    elif base in _FLOATS:
        if isinstance(value, int | float | np.integer | np.floating) and not isinstance(value, bool):
            return float(value)
    elif isinstance(value, str):
        return value
    raise TransportError(f"{_at(where)}expected {base}, got {type(value).__name__} {value!r}")


# Default values the ROS interface definitions state (``float64 w 1``), which the rosbags definitions of
# ROS's common interfaces do not carry: an unset orientation is the identity rotation, as in rclpy and rclcpp.
_STATED_DEFAULTS: dict[str, dict[str, Any]] = {"geometry_msgs/msg/Quaternion": {"w": 1.0}}


def _default(registry: TypeRegistry, desc: Any, where: str) -> Any:
    kind, rest = desc
    if kind == Nodetype.BASE:
        return _base_default(rest[0])
    if kind == Nodetype.NAME:
        return _build(registry, rest, {}, where)
    (sub_kind, sub_rest), size = rest
    if kind == Nodetype.SEQUENCE:
        size = 0
    if sub_kind == Nodetype.BASE and sub_rest[0] in _NUMPY_DTYPES:
        return np.zeros(size, dtype=_NUMPY_DTYPES[sub_rest[0]])
    return [_default(registry, (sub_kind, sub_rest), f"{where}[{i}]") for i in range(size)]


def _convert(registry: TypeRegistry, desc: Any, value: Any, where: str) -> Any:
    kind, rest = desc
    if kind == Nodetype.BASE:
        return _convert_base(rest[0], value, where)
    if kind == Nodetype.NAME:
        return _build(registry, rest, value, where)
    (sub_kind, sub_rest), size = rest
    if (
        isinstance(value, np.ndarray)
        and value.ndim == 1
        and sub_kind == Nodetype.BASE
        and sub_rest[0] in _NUMPY_DTYPES
        and np.can_cast(value.dtype, _NUMPY_DTYPES[sub_rest[0]], "safe")
        and (kind != Nodetype.ARRAY or len(value) == size)
        and not (kind == Nodetype.SEQUENCE and size and len(value) > size)
    ):
        # A numpy array whose every value the field's type holds: no per-element conversion.
        return np.asarray(value, dtype=_NUMPY_DTYPES[sub_rest[0]])
    if isinstance(value, str | bytes | Mapping) or not hasattr(value, "__iter__"):
        if not (
            isinstance(value, bytes)
            and sub_kind == Nodetype.BASE
            and sub_rest[0] in ("uint8", "byte", "octet", "char")
        ):
            raise TransportError(f"{_at(where)}expected a list, got {type(value).__name__} {value!r}")
    items = list(value)
    if kind == Nodetype.ARRAY and len(items) != size:
        raise TransportError(f"{_at(where)}expected exactly {size} items, got {len(items)}")
    if kind == Nodetype.SEQUENCE and size and len(items) > size:
        raise TransportError(f"{_at(where)}at most {size} items allowed, got {len(items)}")
    converted = [
        _convert(registry, (sub_kind, sub_rest), item, f"{where}[{i}]") for i, item in enumerate(items)
    ]
    if sub_kind == Nodetype.BASE and sub_rest[0] in _NUMPY_DTYPES:
        return np.array(converted, dtype=_NUMPY_DTYPES[sub_rest[0]])
    return converted


def _build(registry: TypeRegistry, type_name: str, data: Any, where: str) -> Any:
    cls = registry.typestore.types[type_name]
    if isinstance(data, cls):
        return data
    if data is None:
        data = {}
    if not isinstance(data, Mapping):
        raise TransportError(
            f"{_at(where)}expected a mapping of {type_name} fields, got {type(data).__name__} {data!r}"
        )
    fields = _fields(registry, type_name)
    names = [name for name, _ in fields]
    for key in data:
        if key not in names:
            raise TransportError(
                f"{_at(where)}{type_name} has no field {key!r} ({did_you_mean(str(key), names)})"
            )
    values = {}
    stated = _STATED_DEFAULTS.get(type_name, {})
    for name, desc in fields:
        path = f"{where}.{name}" if where else name
        if name in data:
            values[name] = _convert(registry, desc, data[name], path)
        elif name in stated:
            values[name] = stated[name]
        else:
            values[name] = _default(registry, desc, path)
    return cls(**values)


def from_dict(
    type_name: str, data: Mapping[str, Any] | None = None, *, registry: TypeRegistry | None = None
) -> Any:
    """Build a message of ``type_name`` from a (nested) dict; missing fields get ROS default values.

    Raises:
        TransportError: unknown type or field (with the valid names), or a value of the wrong type.
    """
    reg = _registry(registry)
    full = reg.message_type(type_name)
    return _build(reg, full, data, "")


def msg(type_name: str, **fields: Any) -> Any:
    """Build a message: ``msg("std_msgs/msg/String", data="hi")``. Unset fields get default values."""
    return from_dict(type_name, fields)


def parse_yaml_flow(type_name: str, text: str | None, *, registry: TypeRegistry | None = None) -> Any:
    """Build a message from YAML text as ``ros2 topic pub`` takes it, e.g. ``"{a: 1, b: 2}"``.

    An empty string (or ``None``) gives the default message.
    """
    if text is None or not text.strip():
        return from_dict(type_name, {}, registry=registry)
    from kinema.nesting import load_yaml

    try:
        data = load_yaml(text, f"the YAML for {type_name}")
    except ValueError as error:
        raise TransportError(str(error)) from None
    except yaml.YAMLError as error:
        raise TransportError(f"cannot parse {text!r} as YAML for {type_name}: {error}") from error
    return from_dict(type_name, data, registry=registry)


_DATA_FIELDS: dict[type, tuple[str, ...]] = {}


def _data_fields(cls: type) -> tuple[str, ...]:
    """The fields of a message class that carry data, in order.

    The generated classes hold the type's constants (and ``__msgtype__``) as fields with a default
    value; data fields have none. ``ros2 topic echo`` leaves constants out, and so do we.
    """
    names = _DATA_FIELDS.get(cls)
    if names is None:
        names = _DATA_FIELDS[cls] = tuple(
            name
            for name, spec in getattr(cls, "__dataclass_fields__", {}).items()
            if spec.default is dataclasses.MISSING
        )
    return names


def to_dict(message: Any) -> Any:
    """Turn a message (or a list/array of them) into plain dicts, lists, numbers and strings.

    Constants of the message type are left out (they are the same in every message).
    """
    if hasattr(message, "__msgtype__") and hasattr(message, "__dataclass_fields__"):
        return {name: to_dict(getattr(message, name)) for name in _data_fields(type(message))}
    if isinstance(message, np.ndarray):
        return message.tolist()
    if isinstance(message, list | tuple):
        return [to_dict(item) for item in message]
    if isinstance(message, np.generic):
        return message.item()
    return message


def to_yaml(message: Any, *, flow: bool = False) -> str:
    """Render a message as YAML: block style as ``ros2 topic echo`` prints, or one flow line."""
    data = to_dict(message)
    if flow:
        return yaml.safe_dump(data, default_flow_style=True, sort_keys=False, width=1 << 30).strip()
    return yaml.safe_dump(data, default_flow_style=False, sort_keys=False, allow_unicode=True)


def type_of(message: Any) -> str:
    """The ROS type name of a message object (``pkg/msg/Name``)."""
    name = getattr(message, "__msgtype__", None)
    if not isinstance(name, str):
        raise TransportError(f"{type(message).__name__} is not a ROS message object")
    return name
