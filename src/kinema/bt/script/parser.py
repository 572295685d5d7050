"""Pratt parser for BT.CPP 4.10 scripts, and the :class:`Script` object nodes execute.

Binding powers (higher binds tighter): assignments 2 (right side is a full expression), ternary 4
(the else branch is parsed at 4, so ternaries nest to the right), ``||`` 6, ``&&`` 8, comparisons 10
(chained: ``1 < 2 < 3`` is ``1<2 && 2<3``), ``| ^`` 12, ``&`` 14, ``+ - ..`` 16, ``* /`` 18, prefix
``- ~ !`` 20. Statements are separated by ``;`` but need no separator at all.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Any

from kinema.bt.conversions import int64_from_digits, parse_double_prefix
from kinema.bt.errors import BTError, ScriptError, ScriptParseError
from kinema.bt.script.ast import Assignment, Binary, Comparison, Expr, Literal, Name, Ternary, Unary
from kinema.bt.script.compiled import compile_expr
from kinema.bt.script.tokenizer import Tok, Token, tokenize

if TYPE_CHECKING:
    from kinema.bt.blackboard import Blackboard

_ASSIGNMENT_BP = 2
_TERNARY_BP = 4
_COMPARISON_BP = 10
_PREFIX_BP = 20
# Deeper nesting than this is reported as a parse error instead of exhausting the Python stack.
MAX_NESTING = 200

_INFIX_BP: dict[str, int] = {
    ":=": _ASSIGNMENT_BP,
    "=": _ASSIGNMENT_BP,
    "+=": _ASSIGNMENT_BP,
    "-=": _ASSIGNMENT_BP,
    "*=": _ASSIGNMENT_BP,
    "/=": _ASSIGNMENT_BP,
    "?": _TERNARY_BP,
    "||": 6,
    "&&": 8,
    "==": _COMPARISON_BP,
    "!=": _COMPARISON_BP,
    "<": _COMPARISON_BP,
    ">": _COMPARISON_BP,
    "<=": _COMPARISON_BP,
    ">=": _COMPARISON_BP,
    "|": 12,
    "^": 12,
    "&": 14,
    "+": 16,
    "-": 16,
    "..": 16,
    "*": 18,
    "/": 18,
}
_ASSIGNMENTS = frozenset({":=", "=", "+=", "-=", "*=", "/="})
_COMPARISONS = frozenset({"==", "!=", "<", ">", "<=", ">="})


class _Parser:
    def __init__(self, tokens: list[Token]) -> None:
        self.tokens = tokens
        self.pos = 0
        self.depth = 0

    def peek(self) -> Token:
        return self.tokens[self.pos]

    def advance(self) -> Token:
        token = self.tokens[self.pos]
        if token.kind is not Tok.END:
            self.pos += 1
        return token

    def is_op(self, text: str) -> bool:
        token = self.tokens[self.pos]
        return token.kind is Tok.OPERATOR and token.text == text

    def parse_all(self) -> list[Expr]:
        statements: list[Expr] = []
        while True:
            while self.is_op(";"):
                self.advance()
            if self.peek().kind is Tok.END:
                return statements
            statements.append(self.parse_expr(0))

    def parse_expr(self, min_bp: int) -> Expr:
        self.depth += 1
        if self.depth > MAX_NESTING:
            raise ScriptParseError(f"the expression nests deeper than {MAX_NESTING} levels")
        try:
            left = self.parse_prefix()
            while True:
                token = self.peek()
                if token.kind is not Tok.OPERATOR:
                    break
                bp = _INFIX_BP.get(token.text)
                if bp is None or bp < min_bp:
                    break
                op = token.text
                if op in _ASSIGNMENTS:
                    self.advance()
                    left = Assignment(left, op, self.parse_expr(0))
                    break
                if op == "?":
                    self.advance()
                    then = self.parse_expr(0)
                    if not self.is_op(":"):
                        bad = self.peek()
                        raise ScriptParseError(
                            f"Parse error at position {bad.pos}: expected ':' in ternary expression "
                            f"(got '{bad.text}')"
                        )
                    self.advance()
                    left = Ternary(left, then, self.parse_expr(_TERNARY_BP))
                    break
                if op in _COMPARISONS:
                    operands = [left]
                    ops: list[str] = []
                    while self.peek().kind is Tok.OPERATOR and self.peek().text in _COMPARISONS:
                        ops.append(self.advance().text)
                        operands.append(self.parse_expr(_COMPARISON_BP + 1))
                    left = Comparison(operands, ops)
                    continue
                self.advance()
                left = Binary(left, op, self.parse_expr(bp + 1))
            return left
        finally:
            self.depth -= 1

    def parse_prefix(self) -> Expr:
        token = self.peek()
        kind = token.kind
        if kind is Tok.OPERATOR:
            if token.text in ("-", "~", "!"):
                self.advance()
                return Unary(token.text, self.parse_expr(_PREFIX_BP))
            if token.text == "(":
                self.advance()
                inner = self.parse_expr(0)
                if not self.is_op(")"):
                    bad = self.peek()
                    raise ScriptParseError(
                        f"Parse error at position {bad.pos}: expected ')' (got '{bad.text}')"
                    )
                self.advance()
                return inner
        elif kind is Tok.BOOLEAN:
            self.advance()
            return Literal(1.0 if token.text == "true" else 0.0)
        elif kind is Tok.INTEGER:
            self.advance()
            text = token.text
            is_hex = text[:2] in ("0x", "0X")
            value = int64_from_digits(text[2:] if is_hex else text, 16 if is_hex else 10)
            # from_chars leaves the value untouched (0) when it overflows int64
            return Literal(0 if value is None else value)
        elif kind is Tok.REAL:
            self.advance()
            try:
                return Literal(parse_double_prefix(token.text))
            except BTError as error:
                raise ScriptParseError(f"Invalid number '{token.text[:40]}': {error.message}") from None
        elif kind is Tok.STRING:
            self.advance()
            return Literal(token.text)
        elif kind is Tok.IDENTIFIER:
            self.advance()
            return Name(token.text)
        elif kind is Tok.ERROR:
            raise ScriptParseError(f"Invalid token '{token.text}' at position {token.pos}")
        raise ScriptParseError(f"Expected operand at position {token.pos} (got '{token.text}')")


class Script:
    """A parsed script, ready to run against a blackboard.

    Attributes:
        code: the source text.
        statements: the parsed statements; the value of the script is that of the last one.
    """

    __slots__ = ("_fns", "code", "single", "statements")

    def __init__(self, code: str, statements: list[Expr]) -> None:
        self.code = code
        self.statements = statements
        self._fns = [compile_expr(statement) for statement in statements]
        # The compiled statement of a one-statement script (nearly all): callers on a hot path call it
        # directly, turning an exception into the ScriptError run() raises with error().
        self.single = self._fns[0] if len(self._fns) == 1 else None

    def run(self, blackboard: Blackboard, enums: dict[str, int] | None = None) -> Any:
        """Execute every statement and return the value of the last one.

        Raises:
            ScriptError: "Error in script [<code>]" followed by what went wrong.
        """
        try:
            fns = self._fns
            if len(fns) == 1:
                return fns[0](blackboard, enums)
            value = None
            for fn in fns:
                value = fn(blackboard, enums)
            return value
        except Exception as error:
            raise self.error(error) from None

    def error(self, error: Exception) -> ScriptError:
        """What :meth:`run` raises for ``error`` raised while running (a ScriptError as it is)."""
        if isinstance(error, ScriptError):
            return error
        message = getattr(error, "message", None) or str(error)
        return ScriptError(f"Error in script [{self.code}]\n{message}")

    def __repr__(self) -> str:
        return f"Script({self.code!r})"


#: Scripts up to this length are parsed once and shared (trees repeat the same conditions and
#: counters many times; a parsed Script holds no state of its own).
_CACHED_CODE_CHARS = 4096


def parse_script(code: str) -> Script:
    """Parse ``code`` (a short one at most once: the same Script object is returned again).

    Raises:
        ScriptParseError: a syntax error, or an empty script ("Empty Script").
    """
    if len(code) <= _CACHED_CODE_CHARS:
        return _parse_cached(code)
    return _parse(code)


@functools.lru_cache(maxsize=2048)
def _parse_cached(code: str) -> Script:
    return _parse(code)  # an error is raised each time, never cached


def _parse(code: str) -> Script:
    try:
        statements = _Parser(tokenize(code)).parse_all()
    except ScriptParseError:
        raise
    except RecursionError:
        raise ScriptParseError(f"the script [{code[:60]}] nests too deeply") from None
    if not statements:
        raise ScriptParseError("Empty Script")
    return Script(code, statements)


def validate_script(code: str) -> str | None:
    """None if ``code`` parses, else the error message."""
    try:
        parse_script(code)
    except ScriptParseError as error:
        return error.message
    return None
