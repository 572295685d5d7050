"""Override values are YAML text parsed into the port's type; wrong types are refused with a reason."""

from __future__ import annotations

import enum

import pytest

from kinema.errors import ObjectiveError
from kinema.runtime.overrides import ParameterOverride, parse_yaml_value


class Mode(enum.Enum):
    FAST = 1
    SLOW = 2


@pytest.mark.parametrize(
    ("text", "port_type", "expected"),
    [
        ("42", int, 42),
        ("-3", int, -3),
        ("2.0", int, 2),
        ("1.5", float, 1.5),
        ("3", float, 3.0),
        ("1e3", float, 1000.0),  # YAML 1.1 leaves it a string; it is all number
        ("0x10", int, 16),
        ("08", int, 8),  # not YAML 1.1 octal: a string, and all decimal digits
        ("true", bool, True),
        ("false", bool, False),
        ("Look at Table", str, "Look at Table"),
        ("007", str, "007"),
        ("'quoted'", str, "quoted"),
        ("[1, 2, 3]", list[int], [1, 2, 3]),
        ("1;2;3", list[int], [1, 2, 3]),
        ("[0.5, 1]", list[float], [0.5, 1.0]),
        ("{a: 1}", None, {"a": 1}),
        ("12", None, 12),
        ("SLOW", Mode, Mode.SLOW),
    ],
)
def test_values_parse_into_the_port_type(text: str, port_type: object, expected: object) -> None:
    value = parse_yaml_value(text, port_type)
    assert value == expected
    assert type(value) is type(expected)


@pytest.mark.parametrize(
    ("text", "port_type", "reason"),
    [
        ("abc", int, "int"),
        ("0.5x", float, "'0.5x' is not a valid double"),  # BT.CPP would read 0.5 and drop the rest
        ("5000 apples", int, "'5000 apples' is not a valid int"),
        ("1.5", int, "int"),
        ("true", int, "int"),
        ("maybe", bool, "bool"),
        ("[1, x]", list[int], "int"),
        ("{a: [1", None, "not valid YAML"),
        ("MEDIUM", Mode, "FAST, SLOW"),
    ],
)
def test_wrong_values_are_refused_with_the_expected_type(text: str, port_type: object, reason: str) -> None:
    with pytest.raises(ValueError, match=reason):
        parse_yaml_value(text, port_type)


def test_cli_assignments_split_at_the_first_equals_sign() -> None:
    assert ParameterOverride.parse("waypoint_name=Look at Table") == ParameterOverride(
        "waypoint_name", "Look at Table"
    )
    assert ParameterOverride.parse("expr=a=b").value == "a=b"
    with pytest.raises(ObjectiveError, match="NAME=VALUE"):
        ParameterOverride.parse("no_equals")
