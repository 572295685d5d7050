"""Text from the network nests at most MAX_NESTING levels: refused with a sentence, never a RecursionError."""

from __future__ import annotations

import pytest

from kinema.nesting import MAX_NESTING, NestingError, check_nesting, load_yaml, loads_json

DEEP = "[" * 100_000 + "]" * 100_000


@pytest.mark.parametrize(
    "parse",
    [
        loads_json,
        load_yaml,
        lambda text: __import__("kinema.runtime.quick_protocol").runtime.quick_protocol.decode(text.encode()),
    ],
)
def test_deep_nesting_is_refused_with_a_sentence(parse) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(NestingError, match=f"more than {MAX_NESTING} levels deep"):
        parse('{"a": ' + DEEP + "}")


def test_block_yaml_nested_past_the_parser_is_refused_too() -> None:
    text = "".join(" " * i + "a:\n" for i in range(5000))
    with pytest.raises(NestingError):
        load_yaml(text)


def test_ordinary_text_parses_and_brackets_in_strings_do_not_count() -> None:
    assert loads_json('{"a": [1, {"b": "]]]]"}]}') == {"a": [1, {"b": "]]]]"}]}
    check_nesting('"' + "[" * 500 + '"')
    check_nesting("[" * MAX_NESTING + "]" * MAX_NESTING)
    assert load_yaml("{x: [1, 2]}") == {"x": [1, 2]}


def test_override_values_and_json_port_values_refuse_deep_nesting() -> None:
    from kinema.bt.conversions import ConversionError, convert_from_string
    from kinema.runtime.overrides import parse_yaml_value

    with pytest.raises(ValueError, match="levels deep"):
        parse_yaml_value(DEEP, None)
    with pytest.raises(ConversionError, match="levels deep"):
        convert_from_string(list[int], "json:" + DEEP)
