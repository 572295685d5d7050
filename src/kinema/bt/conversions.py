"""Type information and value conversions with BT.CPP's rules.

A port or blackboard entry type is a Python type: ``int``, ``float`` (BT.CPP ``double``), ``str``,
``bool``, ``list[int|float|str|bool]``, :class:`NodeStatus`, an ``Enum``, any other class (strongly
typed by class, parsed from text through an optional ``from_string`` classmethod), or ``None``
(``AnyTypeAllowed``: no type, no converter). :func:`convert_from_string` mirrors
``convertFromString<T>`` (a numeric prefix is enough, booleans are strict, ``a;b;c`` and ``json:[...]``
vectors) and :func:`cast_value` mirrors ``BT::Any::tryCast`` between stored values.

Doubles written in XML follow BT.CPP 4.8 (``std::stod``), the version MoveIt Pro's objectives are
written against: leading whitespace and a ``+`` sign are accepted, so ``"0.0; 0.0; 1.0"`` is three
numbers. BT.CPP 4.9 and later parse with ``std::from_chars`` and reject ``" 0.0"``; Kinema keeps 4.8's
rule because it only accepts more files, never changes the value of one 4.10 accepts.
"""

from __future__ import annotations

import enum
import json
import math
import re
import types
from collections.abc import Callable
from typing import Any

from kinema.bt.errors import BTLogicError, BTRuntimeError
from kinema.bt.status import STATUS_BY_NAME, NodeStatus

INT64_MIN = -(2**63)
INT64_MAX = 2**63 - 1
FLT_EPSILON = 1.1920928955078125e-07

_INT_PREFIX = re.compile(r"-?[0-9]+")
_FLOAT_PREFIX = re.compile(
    r"-?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?|inf(?:inity)?|nan(?:\([0-9A-Za-z_]*\))?)",
    re.IGNORECASE,
)
_BOOL_WORDS = {"1": True, "true": True, "TRUE": True, "True": True, "0": False, "false": False}
_BOOL_WORDS.update({"FALSE": False, "False": False})


class AnyValue:
    """Marker type for a ``BT::Any`` port: not strongly typed, keeps whatever it is given."""


class ConversionError(BTRuntimeError):
    """A value could not be converted to the requested type."""


def int64_from_digits(digits: str, base: int = 10) -> int | None:
    """``int(digits, base)`` if it fits int64, else None.

    Overlong inputs are rejected by length first: besides being out of range, Python refuses to
    convert decimal strings of more than 4300 digits.
    """
    significant = digits.lstrip("-+").lstrip("0")
    if len(significant) > (20 if base == 10 else 17):
        return None
    value = int(digits, base)
    return value if INT64_MIN <= value <= INT64_MAX else None


def parse_int_prefix(text: str) -> int:
    """``std::from_chars`` for int64: a leading integer (prefix is enough, no space, no '+')."""
    match = _INT_PREFIX.match(text)
    if match is None:
        raise ConversionError(f"Can't convert string [{text[:80]}] to integer")
    value = int64_from_digits(match.group())
    if value is None:
        raise ConversionError(f"Value out of bound when converting [{text[:80]}] to integer")
    return value


def parse_double_prefix(text: str) -> float:
    """``std::from_chars`` for double: a leading real number, ``inf`` or ``nan``."""
    match = _FLOAT_PREFIX.match(text)
    if match is None:
        raise ConversionError(f"Can't convert string [{text}] to double")
    token = match.group()
    lowered = token.lower()
    if lowered.startswith(("nan", "-nan")):
        return math.nan
    value = float(token)
    if math.isinf(value) and "inf" not in lowered:
        # from_chars reports result_out_of_range instead of rounding to infinity
        raise ConversionError(f"Value out of bound when converting [{text[:80]}] to double")
    return value


_STOD_SPACE = " \t\n\v\f\r"
_HEX_FLOAT = re.compile(r"[-+]?0[xX](?:[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)(?:[pP][-+]?[0-9]+)?")
_SIGNED_FLOAT = re.compile(r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?")
_SIGNED_SPECIAL = re.compile(r"[-+]?(?:inf(?:inity)?|nan(?:\([0-9A-Za-z_]*\))?)", re.IGNORECASE)
DBL_MIN = 2.2250738585072014e-308


def parse_double_stod(text: str) -> float:
    """``convertFromString<double>`` of BT.CPP 4.8 (``std::stod``): strtod's rules on a prefix.

    Leading whitespace is skipped, ``+``/``-`` signs, hex floats (``0x1p3``), ``inf`` and ``nan``
    are accepted, and parsing stops at the first character that does not continue the number. A
    result out of double's normal range (overflow, or underflow to zero or a subnormal) raises, as
    ``std::stod`` does.
    """
    body = text.lstrip(_STOD_SPACE)
    match = _HEX_FLOAT.match(body)
    if match is not None:
        token = match.group()
        mantissa = token.lower().split("p")[0][token.lower().index("x") + 1 :]
        try:
            value = float.fromhex(token)
        except OverflowError:
            raise ConversionError(f"Value out of bound when converting [{text[:80]}] to double") from None
    else:
        special = _SIGNED_SPECIAL.match(body)
        if special is not None:
            word = special.group().lower()
            if "nan" in word:
                return math.nan
            return -math.inf if word.startswith("-") else math.inf
        match = _SIGNED_FLOAT.match(body)
        if match is None:
            raise ConversionError(f"Can't convert string [{text}] to double")
        token = match.group()
        mantissa = token.lower().split("e")[0]
        value = float(token)
    nonzero = any(c not in "0.+-" for c in mantissa)
    if math.isinf(value) or (nonzero and abs(value) < DBL_MIN):
        raise ConversionError(f"Value out of bound when converting [{text[:80]}] to double")
    return value


def parse_int_full(text: str) -> int | None:
    """The whole text as an int64, or None (used where BT.CPP requires full consumption)."""
    if _INT_PREFIX.fullmatch(text) is None:
        return None
    return int64_from_digits(text)


def parse_double_full(text: str) -> float | None:
    """The whole text as a double (``inf``/``nan`` included), or None."""
    match = _FLOAT_PREFIX.fullmatch(text)
    if match is None:
        return None
    try:
        return parse_double_prefix(text)
    except ConversionError:  # out of range
        return None


class Unsigned(int):
    """Port type of BT.CPP's ``unsigned`` ports (the milliseconds of Sleep, Delay and Timeout).

    A marker for typing rules only: ``unsigned int`` entries and ports differ from ``int`` ones (a
    ``{key}`` shared with an ``int`` port is refused when the tree is built), literals must lie in
    0 .. 2**32-1, and what a node reads from such a port is a plain ``int``.
    """


_UINT32_MAX = 2**32 - 1


def _check_unsigned(value: int, text: Any) -> int:
    if value < 0 or value > _UINT32_MAX:
        raise ConversionError(f"Value out of bound when converting [{text}] to integer")
    return value


def parse_bool(text: str) -> bool:
    """Exactly ``0 1 true TRUE True false FALSE False``."""
    try:
        return _BOOL_WORDS[text]
    except KeyError:
        raise ConversionError(f"Invalid bool conversion from string [{text}]") from None


def split_string(text: str) -> list[str]:
    """BT.CPP ``splitString(text, ';')``: no trimming, a trailing ';' adds nothing, '' is empty."""
    if not text:
        return []
    parts = text.split(";")
    if parts[-1] == "":
        parts.pop()
    return parts


def list_item_type(port_type: Any) -> Any | None:
    """For ``list[T]`` return ``T``; otherwise None."""
    if isinstance(port_type, types.GenericAlias) and port_type.__origin__ is list:
        args = port_type.__args__
        return args[0] if args else None
    return None


def type_name(port_type: Any) -> str:
    """The type name BT.CPP would print (``int``, ``double``, ``std::string``, ...)."""
    if port_type is None:
        return "BT::AnyTypeAllowed"
    if port_type is AnyValue:
        return "BT::Any"
    simple = _SIMPLE_NAMES.get(port_type)
    if simple is not None:
        return simple
    item = list_item_type(port_type)
    if item is not None:
        return f"std::vector<{type_name(item)}>"
    if port_type is list:
        return "std::vector<BT::Any>"
    return getattr(port_type, "__qualname__", str(port_type))


_SIMPLE_NAMES: dict[Any, str] = {
    int: "int",
    Unsigned: "unsigned int",
    float: "double",
    str: "std::string",
    bool: "bool",
    NodeStatus: "BT::NodeStatus",
    type(None): "void",
}


def value_type_name(value: Any) -> str:
    """Type name of a stored value (bools are int64 inside BT.CPP's Any, but named bool here)."""
    if value is None:
        return "empty"
    if isinstance(value, list):
        return "std::vector"
    return type_name(type(value))


def to_str(value: Any) -> str:
    """BT.CPP ``toStr``: how a port default is written into XML and models."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, NodeStatus):
        return value.name
    if isinstance(value, enum.Enum):
        return value.name
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return f"{value:f}"
    if isinstance(value, list | tuple):
        return "json:" + json.dumps(list(value))
    to_string = getattr(value, "to_string", None)
    if callable(to_string):
        return str(to_string())
    return str(value)


def number_to_string(value: int | float) -> str:
    """``std::to_string`` of a stored number (a bool is the int64 0/1 inside BT.CPP)."""
    if isinstance(value, float):
        return f"{value:f}"
    return str(int(value))


def _convert_list(item_type: Any, text: str, enums: dict[str, int] | None) -> list[Any]:
    if text.startswith("json:"):
        from kinema.nesting import loads_json  # beside the engine: kinema.bt imports only kinema.errors

        try:
            data = loads_json(text[5:], "the JSON value")
        except json.JSONDecodeError as error:
            raise ConversionError(f"invalid JSON in [{text}]: {error.msg}") from None
        except ValueError as error:
            raise ConversionError(f"[{text[:80]}...]: {error}") from None
        if not isinstance(data, list):
            raise ConversionError(f"[{text}] is not a JSON array")
        return [cast_value(item, item_type) for item in data]
    return [convert_from_string(item_type, part, enums) for part in split_string(text)]


def convert_from_string(port_type: Any, text: str, enums: dict[str, int] | None = None) -> Any:
    """Convert a literal port value to ``port_type`` as ``convertFromString<T>`` does.

    Raises:
        ConversionError: the text is not a valid value of that type.
        BTLogicError: the type has no converter at all.
    """
    if port_type is str or port_type is None or port_type is AnyValue:
        return text
    if port_type is int:
        return parse_int_prefix(text)
    if port_type is Unsigned:
        return _check_unsigned(parse_int_prefix(text), text[:80])
    if port_type is float:
        return parse_double_stod(text)
    if port_type is bool:
        return parse_bool(text)
    if port_type is NodeStatus:
        try:
            return STATUS_BY_NAME[text]
        except KeyError:
            raise ConversionError(f"Cannot convert [{text}] to NodeStatus") from None
    if isinstance(port_type, type) and issubclass(port_type, enum.Enum):
        return _convert_enum(port_type, text, enums)
    item = list_item_type(port_type)
    if item is not None or port_type is list:
        return _convert_list(item, text, enums)
    from_string = getattr(port_type, "from_string", None)
    if callable(from_string):
        try:
            return from_string(text)
        except (ValueError, TypeError) as error:
            raise ConversionError(
                f"Can't convert string [{text}] to {type_name(port_type)}: {error}"
            ) from None
    raise BTLogicError(
        f"You didn't implement the template specialization of convertFromString for this type: "
        f"{type_name(port_type)} (give the class a from_string classmethod)"
    )


def _convert_enum(enum_type: type[enum.Enum], text: str, enums: dict[str, int] | None) -> enum.Enum:
    if enums is not None and text in enums:
        return enum_type(enums[text])
    member = enum_type.__members__.get(text)
    if member is not None:
        return member
    number = parse_int_full(text)
    if number is not None:
        try:
            return enum_type(number)
        except ValueError:
            pass
    raise ConversionError(
        f"Can't convert string [{text}] to {enum_type.__name__}; valid: {', '.join(enum_type.__members__)}"
    )


def has_converter(port_type: Any) -> bool:
    """True if literals of this type are validated when the tree is built (enums and Any are not)."""
    if port_type is None or port_type is AnyValue:
        return False
    if isinstance(port_type, type) and issubclass(port_type, enum.Enum) and port_type is not NodeStatus:
        return False
    if port_type in (int, Unsigned, float, str, bool, NodeStatus, list):
        return True
    if list_item_type(port_type) is not None:
        return True
    return callable(getattr(port_type, "from_string", None))


def is_strongly_typed(port_type: Any) -> bool:
    """False for ``AnyTypeAllowed`` (None) and ``BT::Any``."""
    return port_type is not None and port_type is not AnyValue


def _no_conversion(value: Any, target: Any) -> ConversionError:
    return ConversionError(
        f"[Any::convert]: no known safe conversion between [{value_type_name(value)}] "
        f"and [{type_name(target)}]"
    )


def cast_value(value: Any, target: Any) -> Any:
    """Read a stored value as ``target`` (``BT::Any::tryCast`` rules).

    Integers become floats freely; floats become integers only when integral; an int becomes a
    bool only if it is 0 or 1; numbers become strings as ``std::to_string`` writes them; a string
    becomes a number by parsing its numeric prefix. Anything else raises :class:`ConversionError`.
    """
    if target is None or target is AnyValue:
        return value
    vtype = type(value)
    if vtype is target:
        return value
    if target is int:
        if vtype is bool:
            return int(value)
        if vtype is float:
            if value.is_integer():
                return int(value)
            raise ConversionError(f"Floating point truncated: can't convert {value!r} to an integer")
        if vtype is str:
            return parse_int_prefix(value)
        if isinstance(value, int):
            return int(value)
        raise _no_conversion(value, target)
    if target is Unsigned:
        return _check_unsigned(cast_value(value, int), value)
    if target is float:
        if isinstance(value, int):
            return float(value)
        if isinstance(value, float):
            return float(value)
        if vtype is str:
            return parse_double_prefix(value)
        raise _no_conversion(value, target)
    if target is str:
        if isinstance(value, bool):
            return "1" if value else "0"
        if isinstance(value, int | float):
            return number_to_string(value)
        raise _no_conversion(value, target)
    if target is bool:
        if isinstance(value, int):
            if value in (0, 1):
                return bool(value)
            raise ConversionError(f"Implicit casting to bool is not allowed (value {value})")
        if isinstance(value, float):
            return value != 0.0
        raise _no_conversion(value, target)
    if isinstance(target, type) and issubclass(target, enum.Enum):
        if isinstance(value, target):
            return value
        if isinstance(value, int | float) and float(value).is_integer():
            try:
                return target(int(value))
            except ValueError:
                raise _no_conversion(value, target) from None
        if vtype is str:
            return convert_from_string(target, value)
        raise _no_conversion(value, target)
    item = list_item_type(target)
    if item is not None or target is list:
        if isinstance(value, list | tuple):
            return list(value) if item is None else [cast_value(v, item) for v in value]
        if vtype is str:
            return convert_from_string(target, value)
        raise _no_conversion(value, target)
    if isinstance(target, type) and isinstance(value, target):
        return value
    raise _no_conversion(value, target)


def is_number(value: Any) -> bool:
    """True for ints, floats and bools (which BT.CPP stores as int64)."""
    return (isinstance(value, int | float) and not isinstance(value, enum.Enum)) or isinstance(
        value, enum.IntEnum
    )


def python_type_of(value: Any) -> Any:
    """The entry type implied by storing ``value`` with ``Blackboard.set``."""
    if isinstance(value, list):
        for candidate in (bool, int, float, str):
            if value and all(type(v) is candidate for v in value):
                return list[candidate]  # type: ignore[valid-type]
        return list
    return type(value)


Converter = Callable[[str], Any]
