"""JSON and YAML text from the network, parsed with bounded nesting.

Python's ``json`` and PyYAML parse nested arrays and mappings by recursion: ``[[[[...]]]]`` a few
thousand levels deep raises RecursionError (not a parse error) in whatever thread parsed it, and the
request that carried it got no answer. Every door that parses text a client sent (the agent's JSON
endpoints, ``json:`` port values, parameter overrides, message fields given as YAML) goes through
:func:`loads_json` or :func:`load_yaml`: nesting deeper than :data:`MAX_NESTING` is refused with a
ValueError a person can read, before the parser sees it.
"""

from __future__ import annotations

import json
from typing import Any

MAX_NESTING = 100


class NestingError(ValueError):
    """The text nests arrays or mappings deeper than :data:`MAX_NESTING`."""


def check_nesting(text: str, what: str = "the text") -> None:
    """Raise NestingError when ``text``'s brackets nest deeper than :data:`MAX_NESTING`.

    Brackets inside quoted strings do not count. Text with fewer brackets than the limit is not scanned.
    """
    if text.count("[") + text.count("{") <= MAX_NESTING:
        return
    depth = 0
    quote = ""
    escaped = False
    for char in text:
        if quote:
            if escaped:
                escaped = False
            elif char == "\\" and quote == '"':
                escaped = True
            elif char == quote:
                quote = ""
            continue
        if char == '"' or char == "'":
            quote = char
        elif char == "[" or char == "{":
            depth += 1
            if depth > MAX_NESTING:
                raise NestingError(
                    f"{what} nests arrays or mappings more than {MAX_NESTING} levels deep; refused"
                )
        elif char == "]" or char == "}":
            depth -= 1


def loads_json(text: str | bytes, what: str = "the JSON text") -> Any:
    """``json.loads`` with bounded nesting.

    Raises:
        ValueError: not JSON (json.JSONDecodeError), or nested too deep (NestingError).
    """
    if isinstance(text, bytes):
        text = text.decode()
    check_nesting(text, what)
    return json.loads(text)


def load_yaml(text: str, what: str = "the YAML text") -> Any:
    """``yaml.safe_load`` with bounded nesting (flow style by the brackets; block style by recursion).

    Raises:
        NestingError: nested too deep. yaml.YAMLError: not YAML.
    """
    import yaml

    check_nesting(text, what)
    try:
        return yaml.safe_load(text)
    except RecursionError:
        # Block style nests by indentation: thousands of levels are still possible, stopped here.
        raise NestingError(f"{what} nests more deeply than the parser can follow; refused") from None
