"""Script expressions compiled once into Python closures (never ``eval``/``exec`` of text).

:func:`compile_expr` turns a parsed expression into ``fn(bb, enums) -> value`` with the same
semantics as ``expr.evaluate``. The shapes that dominate real trees get specialised closures:
literals, blackboard names, infix operators, a single comparison of two operands (``counter >= 0``)
and a compound assignment of a literal or a name (``counter += 1``). Numbers take a short path; anything else
goes through the same helpers :mod:`.ast` uses, so errors and conversions stay BT.CPP's. Every
other expression is its own ``evaluate``.
"""

from __future__ import annotations

import operator
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from kinema.bt.conversions import FLT_EPSILON
from kinema.bt.script.ast import (
    Assignment,
    Binary,
    Comparison,
    EvalError,
    Expr,
    Literal,
    Name,
    binary_values,
    compare_operands,
    to_double,
)

if TYPE_CHECKING:
    from kinema.bt.blackboard import Blackboard

Evaluator = Callable[["Blackboard", "dict[str, int] | None"], Any]

_NUMBERS = (int, float)  # exact classes: bools and enums take the general path

_FLOAT_COMPARE: dict[str, Callable[[float, float], bool]] = {
    "==": lambda a, b: abs(a - b) <= FLT_EPSILON,
    "!=": lambda a, b: not abs(a - b) <= FLT_EPSILON,
    "<": operator.lt,
    ">": operator.gt,
    "<=": operator.le,
    ">=": operator.ge,
}

_MAX_EXACT_INT = 2**53 - 1  # to_double's limit: integers up to it are exact doubles


def _number_literal(expr: Expr) -> float | int | None:
    """The value of a literal int/float a double holds exactly, else None."""
    if type(expr) is Literal and expr.value.__class__ in _NUMBERS:  # type: ignore[attr-defined]
        value = expr.value  # type: ignore[attr-defined]
        if value.__class__ is float or -_MAX_EXACT_INT <= value <= _MAX_EXACT_INT:
            return value
    return None


def compile_expr(expr: Expr) -> Evaluator:
    """A closure evaluating ``expr`` exactly as ``expr.evaluate`` does."""
    kind = type(expr)
    if kind is Literal:
        return _literal(expr)  # type: ignore[arg-type]
    if kind is Name:
        return _name(expr)  # type: ignore[arg-type]
    if kind is Comparison and len(expr.ops) == 1:  # type: ignore[attr-defined]
        return _comparison(expr)  # type: ignore[arg-type]
    if kind is Binary:
        return _binary(expr)  # type: ignore[arg-type]
    if kind is Assignment:
        fast = _compound_assignment(expr)  # type: ignore[arg-type]
        if fast is not None:
            return fast
    return expr.evaluate


def _literal(expr: Literal) -> Evaluator:
    value = expr.value

    def literal(bb: Blackboard, enums: dict[str, int] | None) -> Any:
        return value

    return literal


def _name(expr: Name) -> Evaluator:
    name = expr.name

    def lookup(bb: Blackboard, enums: dict[str, int] | None) -> Any:
        if enums and name in enums:
            return float(enums[name])
        entry = bb.get_entry(name)
        if entry is None:
            raise EvalError(f"Variable not found: {name}")
        return entry.value

    return lookup


def _binary(expr: Binary) -> Evaluator:
    left = compile_expr(expr.lhs)
    right = compile_expr(expr.rhs)
    op = expr.op

    def binary(bb: Blackboard, enums: dict[str, int] | None) -> Any:
        return binary_values(op, left(bb, enums), right(bb, enums))

    return binary


def _comparison(expr: Comparison) -> Evaluator:
    general = _comparison_general(expr)
    lhs_expr, rhs_expr = expr.operands
    literal = _number_literal(rhs_expr)
    if type(lhs_expr) is not Name or literal is None:
        return general
    # `name op number`, the usual condition: the entry is read inline; an int within the exact
    # range compares with the same result as its double; anything else takes the general path.
    name = lhs_expr.name  # type: ignore[attr-defined]
    floats = _FLOAT_COMPARE[expr.ops[0]]
    local = name[:1] != "@"

    def name_vs_number(bb: Blackboard, enums: dict[str, int] | None) -> Any:
        if not enums or name not in enums:
            # get_entry's first step inline: an entry of this scope is the one it would return.
            entry = (bb._storage.get(name) if local else None) or bb.get_entry(name)
            if entry is not None:
                value = entry.value
                kind = value.__class__
                if kind is float or (kind is int and -_MAX_EXACT_INT <= value <= _MAX_EXACT_INT):
                    return 1.0 if floats(value, literal) else 0.0
        return general(bb, enums)

    return name_vs_number


def _comparison_general(expr: Comparison) -> Evaluator:
    left = compile_expr(expr.operands[0])
    right = compile_expr(expr.operands[1])
    op = expr.ops[0]
    floats = _FLOAT_COMPARE[op]

    def comparison(bb: Blackboard, enums: dict[str, int] | None) -> Any:
        lhs = left(bb, enums)
        rhs = right(bb, enums)
        if lhs.__class__ in _NUMBERS and rhs.__class__ in _NUMBERS:
            ok = floats(to_double(lhs), to_double(rhs))
        else:
            ok = compare_operands(op, lhs, rhs, enums)
        return 1.0 if ok else 0.0

    return comparison


def _compound_assignment(expr: Assignment) -> Evaluator | None:
    """``name op= literal-or-name`` on numbers; None for every other assignment."""
    if expr.op not in ("+=", "-=", "*=") or type(expr.lhs) is not Name:
        return None
    if type(expr.rhs) is not Literal and type(expr.rhs) is not Name:
        return None  # only pure right operands: the general path may evaluate it again
    key = expr.lhs.name  # type: ignore[attr-defined]
    rhs = compile_expr(expr.rhs)
    op = expr.op
    general = expr.evaluate
    step = _number_literal(expr.rhs)
    if step is not None and step.__class__ is int:
        return _int_step(key, op, step, _compound(key, op, rhs, general))
    return _compound(key, op, rhs, general)


def _int_step(key: str, op: str, step: int, slow: Evaluator) -> Evaluator:
    """``counter += 1`` on an int entry in integer arithmetic: while operands and result stay
    within 2**53 - 1 the double arithmetic BT.CPP does is exact, so the result is the same."""
    apply = operator.add if op == "+=" else operator.sub if op == "-=" else operator.mul
    local = key[:1] != "@"

    def int_step(bb: Blackboard, enums: dict[str, int] | None) -> Any:
        # get_entry's first step inline: an entry of this scope is the one it would return.
        entry = (bb._storage.get(key) if local else None) or bb.get_entry(key)
        if entry is not None:
            dst = entry.value
            if dst.__class__ is int and -_MAX_EXACT_INT <= dst <= _MAX_EXACT_INT:
                new = apply(dst, step)
                if -_MAX_EXACT_INT <= new <= _MAX_EXACT_INT:
                    entry.value = new
                    # Blackboard._written inline: the write's sequence id, stamp and observers.
                    entry.sequence_id += 1
                    source = bb.time_source
                    if source is not None:
                        entry.stamp = source()
                    observers = entry.owner._observers
                    if observers:
                        for callback in tuple(observers):
                            callback(key, entry)
                    return new
        return slow(bb, enums)

    return int_step


def _compound(key: str, op: str, rhs: Evaluator, general: Evaluator) -> Evaluator:
    def compound(bb: Blackboard, enums: dict[str, int] | None) -> Any:
        entry = bb.get_entry(key)
        if entry is not None:
            dst = entry.value
            value = rhs(bb, enums)
            if dst.__class__ in _NUMBERS and value.__class__ in _NUMBERS:
                lv = to_double(dst)
                rv = to_double(value)
                temp = lv + rv if op == "+=" else lv - rv if op == "-=" else lv * rv
                if dst.__class__ is float:
                    new: Any = temp
                elif temp.is_integer():
                    new = int(temp)  # the common `counter += 1` on an int entry
                else:
                    return general(bb, enums)  # raises BT.CPP's conversion error
                entry.value = new
                bb._written(key, entry)  # notify_written without the extra call
                return new
        return general(bb, enums)

    return compound
