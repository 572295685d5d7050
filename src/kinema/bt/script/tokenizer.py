"""Split script text into tokens, with BT.CPP 4.10's lexical rules.

Identifiers are ASCII (``[A-Za-z_@][A-Za-z0-9_]*``), strings use single quotes without escapes, and
a number glued to letters, a dangling ``.`` or an empty exponent (``3foo``, ``65.``, ``0x``, ``3e``)
is an error token, while ``65..66`` is ``65 .. 66``.

Strings may also be double-quoted (``"place_pose_"``), as BT.CPP up to 4.8 accepts and MoveIt Pro's
objectives use (written ``&quot;`` inside an XML attribute); 4.9 and later reject the ``"``. Either
quote may appear inside a string delimited by the other (``"it's"``); there are no escapes.
"""

from __future__ import annotations

from enum import Enum, auto


class Tok(Enum):
    """Token kinds."""

    INTEGER = auto()
    REAL = auto()
    STRING = auto()
    BOOLEAN = auto()
    IDENTIFIER = auto()
    OPERATOR = auto()
    ERROR = auto()
    END = auto()


class Token:
    """One token: its kind, its text (an operator's text is the operator) and its offset."""

    __slots__ = ("kind", "pos", "text")

    def __init__(self, kind: Tok, text: str, pos: int) -> None:
        self.kind = kind
        self.text = text
        self.pos = pos

    def __repr__(self) -> str:
        return f"Token({self.kind.name}, {self.text!r}, {self.pos})"


_TWO_CHAR_OPS = frozenset({"..", "&&", "||", "==", "!=", "<=", ">=", ":=", "+=", "-=", "*=", "/="})
_ONE_CHAR_OPS = frozenset("+-*/&|^~!<>=?:();")
_WHITESPACE = frozenset(" \t\n\r")


def _is_alpha(c: str) -> bool:
    return ("a" <= c <= "z") or ("A" <= c <= "Z")


def _is_digit(c: str) -> bool:
    return "0" <= c <= "9"


def _is_ident_start(c: str) -> bool:
    return _is_alpha(c) or c == "_" or c == "@"


def _is_ident_char(c: str) -> bool:
    return _is_alpha(c) or _is_digit(c) or c == "_"


def _is_hex(c: str) -> bool:
    return _is_digit(c) or ("a" <= c <= "f") or ("A" <= c <= "F")


def _skip_garbage(src: str, i: int) -> int:
    while i < len(src) and (_is_ident_char(src[i]) or src[i] == "."):
        i += 1
    return i


def _scan_hex(src: str, i: int) -> tuple[int, bool]:
    n = len(src)
    i += 2
    error = False
    if i >= n or not _is_hex(src[i]):
        error = True
    else:
        while i < n and _is_hex(src[i]):
            i += 1
    if i < n and (src[i] == "." or _is_ident_char(src[i])):
        error = True
        i = _skip_garbage(src, i)
    return i, error


def _scan_decimal(src: str, i: int) -> tuple[int, bool, bool]:
    """Return (end, is_real, error)."""
    n = len(src)
    real = False
    error = False
    while i < n and _is_digit(src[i]):
        i += 1
    if i < n and src[i] == ".":
        if i + 1 < n and src[i + 1] == ".":
            pass  # "65..66": the dots are the concatenation operator
        elif i + 1 < n and _is_digit(src[i + 1]):
            real = True
            i += 1
            while i < n and _is_digit(src[i]):
                i += 1
        else:
            error = True
            i = _skip_garbage(src, i + 1)
    if not error and i < n and src[i] in "eE":
        real = True
        i += 1
        if i < n and src[i] in "+-":
            i += 1
        if i >= n or not _is_digit(src[i]):
            error = True
        else:
            while i < n and _is_digit(src[i]):
                i += 1
    if not error and i < n and _is_ident_start(src[i]):
        error = True
        while i < n and _is_ident_char(src[i]):
            i += 1
    return i, real, error


def tokenize(src: str) -> list[Token]:
    """Tokenize ``src``; errors become ERROR tokens (the parser reports them). Ends with END."""
    tokens: list[Token] = []
    n = len(src)
    i = 0
    while i < n:
        c = src[i]
        if c in _WHITESPACE:
            i += 1
            continue
        start = i
        if c in "'\"":
            end = src.find(c, i + 1)
            if end < 0:
                tokens.append(Token(Tok.ERROR, src[start:], start))
                i = n
            else:
                tokens.append(Token(Tok.STRING, src[start + 1 : end], start))
                i = end + 1
            continue
        if _is_digit(c):
            if c == "0" and i + 1 < n and src[i + 1] in "xX":
                i, error = _scan_hex(src, i)
                real = False
            else:
                i, real, error = _scan_decimal(src, i)
            text = src[start:i]
            kind = Tok.ERROR if error else (Tok.REAL if real else Tok.INTEGER)
            tokens.append(Token(kind, text, start))
            continue
        if _is_ident_start(c):
            i += 1
            while i < n and _is_ident_char(src[i]):
                i += 1
            text = src[start:i]
            kind = Tok.BOOLEAN if text in ("true", "false") else Tok.IDENTIFIER
            tokens.append(Token(kind, text, start))
            continue
        pair = src[i : i + 2]
        if pair in _TWO_CHAR_OPS:
            tokens.append(Token(Tok.OPERATOR, pair, start))
            i += 2
            continue
        if c in _ONE_CHAR_OPS:
            tokens.append(Token(Tok.OPERATOR, c, start))
            i += 1
            continue
        tokens.append(Token(Tok.ERROR, c, start))
        i += 1
    tokens.append(Token(Tok.END, "", n))
    return tokens
