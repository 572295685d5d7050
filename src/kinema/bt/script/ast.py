"""Script expressions and how they evaluate (BT.CPP 4.10 ``scripting/operators.hpp`` semantics).

Values are Python objects standing for ``BT::Any``: ``int`` (int64; a stored ``bool`` counts as one),
``float`` (double), ``str``, ``None`` (an empty entry) or any other object. Arithmetic on numbers
always yields a float; comparisons and logic yield 1.0/0.0; ``==`` on numbers tolerates a float
epsilon. Each node's ``evaluate(bb, enums)`` reads and writes the given blackboard.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from kinema.bt.conversions import (
    FLT_EPSILON,
    ConversionError,
    convert_from_string,
    has_converter,
    is_strongly_typed,
    number_to_string,
    parse_double_prefix,
    value_type_name,
)
from kinema.bt.errors import BTLogicError, BTRuntimeError
from kinema.bt.limits import MAX_SCRIPT_STRING_CHARS, script_string_too_long

if TYPE_CHECKING:
    from kinema.bt.blackboard import Blackboard


class EvalError(BTRuntimeError):
    """An operator or assignment failed while a script ran."""


_NUMBER = (int, float)


def is_num(v: Any) -> bool:
    """A number in the script world (int, float, bool, IntEnum)."""
    return isinstance(v, _NUMBER)


def to_bool(v: Any) -> bool:
    """``Any::cast<bool>``: a float is true when non-zero, an int must be 0 or 1, strings fail."""
    if isinstance(v, float):
        return v != 0.0
    if isinstance(v, int):
        if v == 0 or v == 1:
            return bool(v)
        raise EvalError(f"Implicit casting to bool is not allowed (value {v})")
    raise EvalError(f"[Any::convert]: no known safe conversion between [{value_type_name(v)}] and [bool]")


_MAX_EXACT_INT = 2**53 - 1  # the largest integer a double holds exactly (and everything below it)


def to_double(v: Any) -> float:
    """``Any::cast<double>`` of a number: an integer a double cannot hold exactly raises.

    Raises:
        EvalError: ``|v| > 2**53 - 1`` (so ``9223372036854775807 + 1`` fails instead of rounding).
    """
    if v.__class__ is float:
        return v
    if -_MAX_EXACT_INT <= v <= _MAX_EXACT_INT:
        return float(v)
    raise EvalError(f"Loss of precision when converting a large integer number to floating point:{v}")


def to_int64(v: Any) -> int:
    """``Any::cast<int64_t>`` of a number: floats must be integral."""
    if isinstance(v, float):
        if not v.is_integer():
            raise EvalError("Floating point truncated")
        v = int(v)
    value = int(v)
    if value < -(2**63) or value > 2**63 - 1:
        raise EvalError("Value outside the int64 range")
    return value


def string_to_double(text: str, enums: dict[str, int] | None) -> float:
    """``StringToDouble``: ``true``/``false``, an enum name, else the numeric prefix."""
    if text == "true":
        return 1.0
    if text == "false":
        return 0.0
    if enums and text in enums:
        return float(enums[text])
    try:
        return parse_double_prefix(text)
    except ConversionError as error:
        raise EvalError(error.message) from None


def copy_into(value: Any, dst: Any) -> Any:
    """``Any::copyInto``: the value to store over ``dst`` keeping ``dst``'s internal type."""
    if dst is None:
        return value
    if type(value) is type(dst):
        return value
    if is_num(value) and is_num(dst):
        if isinstance(dst, float):
            return float(value)
        if isinstance(value, float):
            if not value.is_integer():
                raise EvalError("Invalid floating point to integer conversion")
            value = int(value)
        if isinstance(dst, bool) and value in (0, 1):
            return bool(value)
        return int(value)
    if isinstance(value, str) and isinstance(dst, str):
        return value
    if isinstance(dst, str) or isinstance(value, str):
        raise EvalError("no known safe conversion between string and number")
    if isinstance(value, type(dst)):
        return value
    raise EvalError("incompatible types")


class Expr:
    """Base class of expressions."""

    __slots__ = ()

    def evaluate(self, bb: Blackboard, enums: dict[str, int] | None) -> Any:
        raise NotImplementedError


class Literal(Expr):
    __slots__ = ("value",)

    def __init__(self, value: Any) -> None:
        self.value = value

    def evaluate(self, bb: Blackboard, enums: dict[str, int] | None) -> Any:
        return self.value


class Name(Expr):
    __slots__ = ("name",)

    def __init__(self, name: str) -> None:
        self.name = name

    def evaluate(self, bb: Blackboard, enums: dict[str, int] | None) -> Any:
        name = self.name
        if enums and name in enums:
            return float(enums[name])
        entry = bb.get_entry(name)
        if entry is None:
            raise EvalError(f"Variable not found: {name}")
        return entry.value


def _not_init(side: str, op: str) -> EvalError:
    return EvalError(f"The {side} operand of the operator [{op}] is not initialized")


class Unary(Expr):
    __slots__ = ("op", "operand")

    def __init__(self, op: str, operand: Expr) -> None:
        self.op = op
        self.operand = operand

    def evaluate(self, bb: Blackboard, enums: dict[str, int] | None) -> Any:
        v = self.operand.evaluate(bb, enums)
        if is_num(v):
            rv = to_double(v)
            op = self.op
            if op == "-":
                return -rv
            if op == "!":
                return 0.0 if rv != 0.0 else 1.0
            if math.isnan(rv) or rv >= 9.223372036854775807e18 or rv < -9.223372036854775808e18:
                raise EvalError("Number out of range for bitwise operation")
            return float(~int(rv))
        if isinstance(v, str):
            raise EvalError("Invalid operator for std::string")
        raise EvalError("ExprUnaryArithmetic: undefined")


def _bounded(text: str) -> str:
    """``text`` if it is within the script string limit (kinema.bt.limits), else EvalError."""
    if len(text) > MAX_SCRIPT_STRING_CHARS:
        raise EvalError(script_string_too_long(len(text)))
    return text


def _divide(a: float, b: float) -> float:
    try:
        return a / b
    except ZeroDivisionError:
        if a == 0.0 or math.isnan(a):
            return math.nan
        return math.copysign(math.inf, a) * math.copysign(1.0, b)


class Binary(Expr):
    __slots__ = ("lhs", "op", "rhs")

    def __init__(self, lhs: Expr, op: str, rhs: Expr) -> None:
        self.lhs = lhs
        self.op = op
        self.rhs = rhs

    def evaluate(self, bb: Blackboard, enums: dict[str, int] | None) -> Any:
        return binary_values(self.op, self.lhs.evaluate(bb, enums), self.rhs.evaluate(bb, enums))


def binary_values(op: str, lv: Any, rv: Any) -> Any:
    """The value of ``lv op rv`` for an infix operator other than comparisons and assignments."""
    if lv is None:
        raise _not_init("left", op)
    if rv is None:
        raise _not_init("right", op)
    lnum = isinstance(lv, _NUMBER)
    rnum = isinstance(rv, _NUMBER)
    if lnum and rnum:
        # BT.CPP casts both to double first, whatever the operator
        lf = lv if lv.__class__ is float else to_double(lv)
        rf = rv if rv.__class__ is float else to_double(rv)
        if op == "+":
            return lf + rf
        if op == "-":
            return lf - rf
        if op == "*":
            return lf * rf
        if op == "/":
            return _divide(lf, rf)
        if op in ("&", "|", "^"):
            try:
                li, ri = to_int64(lv), to_int64(rv)
            except EvalError:
                raise EvalError(
                    "Binary operators are not allowed if one of the operands is not an integer"
                ) from None
            if op == "&":
                return float(li & ri)
            if op == "|":
                return float(li | ri)
            return float(li ^ ri)
        if op in ("&&", "||"):
            try:
                lb, rb = to_bool(lv), to_bool(rv)
            except EvalError:
                raise EvalError(
                    "Logic operators are not allowed if one of the operands is not castable to bool"
                ) from None
            return float(lb and rb) if op == "&&" else float(lb or rb)
        return None  # number .. number: BT.CPP silently yields an empty value
    lstr = isinstance(lv, str)
    rstr = isinstance(rv, str)
    if lstr and rstr and op == "+":
        return _bounded(lv + rv)
    if op == ".." and ((lstr and rstr) or (lstr and rnum) or (lnum and rstr)):
        left = lv if lstr else number_to_string(lv)
        right = rv if rstr else number_to_string(rv)
        return _bounded(left + right)
    raise EvalError("Operation not permitted")


def _compare(op: str, lv: Any, rv: Any) -> bool:
    if isinstance(lv, float):
        if op == "==":
            return abs(lv - rv) <= FLT_EPSILON
        if op == "!=":
            return not abs(lv - rv) <= FLT_EPSILON
    elif op == "==":
        return lv == rv
    elif op == "!=":
        return lv != rv
    if op == "<":
        return lv < rv
    if op == ">":
        return lv > rv
    if op == "<=":
        return lv <= rv
    return lv >= rv


class Comparison(Expr):
    __slots__ = ("operands", "ops")

    def __init__(self, operands: list[Expr], ops: list[str]) -> None:
        self.operands = operands
        self.ops = ops

    def evaluate(self, bb: Blackboard, enums: dict[str, int] | None) -> Any:
        operands = self.operands
        lhs = operands[0].evaluate(bb, enums)
        for i, op in enumerate(self.ops):
            rhs = operands[i + 1].evaluate(bb, enums)
            if not compare_operands(op, lhs, rhs, enums):
                return 0.0
            lhs = rhs
        return 1.0


def compare_operands(op: str, lhs: Any, rhs: Any, enums: dict[str, int] | None) -> bool:
    """One link of a comparison chain: numbers as doubles, strings as text, a string against a
    number through ``StringToDouble``; anything else raises."""
    if lhs is None:
        raise _not_init("left", op)
    if rhs is None:
        raise _not_init("right", op)
    lnum = isinstance(lhs, _NUMBER)
    rnum = isinstance(rhs, _NUMBER)
    if lnum and rnum:
        return _compare(op, to_double(lhs), to_double(rhs))
    if isinstance(lhs, str) and isinstance(rhs, str):
        return _compare(op, lhs, rhs)
    if isinstance(lhs, str) and rnum:
        return _compare(op, string_to_double(lhs, enums), to_double(rhs))
    if lnum and isinstance(rhs, str):
        return _compare(op, to_double(lhs), string_to_double(rhs, enums))
    raise EvalError(
        f"Can't mix different types in Comparison. Left operand [{value_type_name(lhs)}] "
        f"right operand [{value_type_name(rhs)}]"
    )


class Ternary(Expr):
    __slots__ = ("condition", "else_", "then")

    def __init__(self, condition: Expr, then: Expr, else_: Expr) -> None:
        self.condition = condition
        self.then = then
        self.else_ = else_

    def evaluate(self, bb: Blackboard, enums: dict[str, int] | None) -> Any:
        c = self.condition.evaluate(bb, enums)
        if isinstance(c, str) and c:
            valid = True
        elif isinstance(c, str):
            raise EvalError(
                "Any failed string to number conversion: the ternary condition is an empty string"
            )
        elif is_num(c):
            valid = to_double(c) != 0.0
        elif c is None:
            raise EvalError("The condition of the ternary operator is not initialized")
        else:
            raise EvalError(f"the ternary condition has type [{value_type_name(c)}], not a number")
        return self.then.evaluate(bb, enums) if valid else self.else_.evaluate(bb, enums)


class Assignment(Expr):
    __slots__ = ("lhs", "op", "rhs")

    def __init__(self, lhs: Expr, op: str, rhs: Expr) -> None:
        self.lhs = lhs
        self.op = op
        self.rhs = rhs

    def evaluate(self, bb: Blackboard, enums: dict[str, int] | None) -> Any:
        if not isinstance(self.lhs, Name):
            raise EvalError("Assignment left operand not a blackboard entry")
        key = self.lhs.name
        op = self.op
        entry = bb.get_entry(key)
        if entry is None:
            if op != ":=":
                raise EvalError(
                    f"The blackboard entry [{key}] doesn't exist, yet.\n"
                    "If you want to create a new one, use the operator [:=] instead of [=]"
                )
            try:
                entry = bb.create_entry(key, None)
            except BTLogicError as error:
                raise EvalError(error.message) from None
        value = self.rhs.evaluate(bb, enums)
        if value is None:
            raise _not_init("right", op)
        dst = entry.value
        if op == ":=" or op == "=":
            if dst is None and not is_strongly_typed(entry.type):
                new = value
            elif isinstance(value, str) and not isinstance(dst, str):
                if entry.type is not None and has_converter(entry.type):
                    try:
                        new = convert_from_string(entry.type, value, enums)
                    except ConversionError as error:
                        raise EvalError(error.message) from None
                elif is_num(dst):
                    new = string_to_double(value, enums)
                else:
                    raise EvalError(
                        f"Error assigning a value to entry [{key}] with type [{entry.type_name}]. "
                        f"\nThe right operand is a string, can't convert to {entry.type_name}"
                    )
            else:
                try:
                    new = copy_into(value, dst)
                except EvalError:
                    raise EvalError(
                        f"Error assigning a value to entry [{key}] with type [{entry.type_name}]. "
                        f"\nThe right operand has type [{value_type_name(value)}] and can't be converted "
                        f"to [{value_type_name(dst)}]"
                    ) from None
        else:
            if dst is None:
                raise _not_init("left", op)
            if isinstance(value, _NUMBER):
                if not isinstance(dst, _NUMBER):
                    raise EvalError("This Assignment operator can't be used with a non-numeric type")
                lv, rv = to_double(dst), to_double(value)
                if op == "+=":
                    temp: Any = lv + rv
                elif op == "-=":
                    temp = lv - rv
                elif op == "*=":
                    temp = lv * rv
                else:
                    temp = _divide(lv, rv)
            elif isinstance(value, str):
                if op != "+=":
                    raise EvalError("Operator not supported for strings")
                if not isinstance(dst, str):
                    raise EvalError("Operation not permitted: the left operand is not a string")
                temp = _bounded(dst + value)
            else:
                raise EvalError("Operation not permitted")
            dst_type = type(dst)
            if dst_type is type(temp):
                new = temp
            elif dst_type is int and temp.__class__ is float and temp.is_integer():
                new = int(temp)  # the common `counter += 1` on an int entry
            else:
                new = copy_into(temp, dst)
        entry.value = new
        bb.notify_written(key, entry)
        return new
