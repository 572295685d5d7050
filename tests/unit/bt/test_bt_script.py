"""The scripting language: literals, precedence, types, assignment and errors (BT.CPP 4.10 rules)."""

from __future__ import annotations

import math

import pytest

from kinema.bt import Blackboard
from kinema.bt.errors import ScriptError, ScriptParseError
from kinema.bt.script import parse_script


def run(code: str, bb: Blackboard | None = None, enums: dict[str, int] | None = None) -> object:
    return parse_script(code).run(bb if bb is not None else Blackboard.create(), enums or {})


@pytest.mark.parametrize(
    ("code", "expected"),
    [
        # literals keep their kind: integers are int64, reals and booleans are doubles
        ("42", 42),
        ("0x1F", 31),
        ("0X100", 256),
        ("2.5", 2.5),
        ("3e2", 300.0),
        ("3.14e-2", 0.0314),
        ("true", 1.0),
        ("false", 0.0),
        ("'some text '", "some text "),
        # arithmetic on numbers is always double
        ("3 + 4", 7.0),
        ("7 / 2", 3.5),
        ("-(3 + 2)", -5.0),
        # left associativity (fixed in 4.9)
        ("10 - 3 - 2", 5.0),
        ("5 - 2 + 1", 4.0),
        ("12 / 3 / 2", 2.0),
        ("12 / 3 * 2", 8.0),
        ("2 + 3 * 4", 14.0),
        ("(2 + 3) * 4", 20.0),
        # && binds tighter than || (4.9+)
        ("true || false && false", 1.0),
        ("false || true && true", 1.0),
        ("false && true || true", 1.0),
        # chained comparisons
        ("1 < 2 < 3", 1.0),
        ("3 > 2 > 2", 0.0),
        ("5 == 5 != 3", 1.0),
        # bitwise operators work on integral values and return doubles
        ("5 & 3", 1.0),
        ("5 | 3", 7.0),
        ("5 ^ 3", 6.0),
        ("~0", -1.0),
        ("1 + 2 & 3", 3.0),
        # unary
        ("!true", 0.0),
        ("!!true", 1.0),
        ("!0", 1.0),
        # equality on doubles tolerates a float epsilon
        ("0.1 + 0.2 == 0.3", 1.0),
        ("1.0 == 1.0000001", 1.0),
        ("1.0 == 1.001", 0.0),
        # strings
        ("'a' + 'b'", "ab"),
        ("'x' .. 2", "x2"),
        ("1.5 .. 'x'", "1.500000x"),
        ("'abc' < 'abd'", 1.0),
        ("'3abc' == 3", 1.0),
        ("'true' == 1", 1.0),
        # ternary, nesting to the right
        ("true ? 1 : 2", 1),
        ("false ? 1 : true ? 2 : 3", 2),
        ("'yes' ? 1 : 2", 1),
        ("'0' ? 1 : 2", 1),
        # several statements, with or without separators
        ("a := 1; b := 2; a + b", 3.0),
        ("a := 1 b := 2 a + b", 3.0),
        ("a:=1;;; b:=2;; a+b", 3.0),
        # the value of an assignment is the stored value
        ("a := b := 5", 5),
    ],
)
def test_expression_values(code: str, expected: object) -> None:
    result = run(code)
    assert result == expected
    assert type(result) is type(expected)


def test_division_by_zero_gives_infinity_like_cpp() -> None:
    assert run("1 / 0") == math.inf
    assert run("-1 / 0") == -math.inf
    assert math.isnan(run("0 / 0"))  # type: ignore[arg-type]


def test_number_concatenation_yields_an_empty_value_that_cannot_be_stored() -> None:
    assert run("1 .. 2") is None
    with pytest.raises(ScriptError, match="right operand of the operator \\[:=\\] is not initialized"):
        run("c := 1 .. 2")


@pytest.mark.parametrize(
    "code",
    [
        "",
        "   ",
        "3e",
        "65.",
        "0x",
        "0xG",
        "3foo",
        "0X100.",
        "'open",
        '"open',  # double quotes are strings (BT.CPP 4.8, MoveIt Pro's objectives), but must close
        "'mixed\"",
        "(1 + 2",
        "1 +",
        "a ? 1",
        "#",
        "1 2 3 )",
    ],
)
def test_parse_errors(code: str) -> None:
    with pytest.raises(ScriptParseError):
        parse_script(code)


def test_range_operator_tokens() -> None:
    assert run("'a' .. 'b'") == "ab"
    assert run("65..'x'") == "65x"


@pytest.mark.parametrize(
    ("code", "message"),
    [
        ("foo", "Variable not found: foo"),
        ("new_var = 69", "use the operator [:=] instead of [=]"),
        ("'a' + 1", "Operation not permitted"),
        ("'a' - 'b'", "Operation not permitted"),
        ("2 && 1", "Logic operators are not allowed"),
        ("1.5 | 1", "Binary operators are not allowed"),
        ("-'a'", "Invalid operator for std::string"),
        ("a := 'hello'; a = 1.0", "can't be converted"),
        ("a := 1; a = 2.5", "can't be converted"),
        ("a := 1; a += 0.5", "Invalid floating point to integer conversion"),
        ("a := 'x'; a -= 'y'", "Operator not supported for strings"),
        ("'' ? 1 : 2", ""),
        ("1 = 2", "Assignment left operand not a blackboard entry"),
        ("x := y", "Variable not found: y"),
    ],
)
def test_evaluation_errors(code: str, message: str) -> None:
    with pytest.raises(ScriptError) as info:
        run(code)
    assert message in info.value.message
    assert info.value.message.startswith(f"Error in script [{code}]")


def test_assignment_typing_rules() -> None:
    bb = Blackboard.create()
    run("i := 3; d := 3.5; s := 'text'", bb)
    assert (bb.get("i"), bb.get("d"), bb.get("s")) == (3, 3.5, "text")
    run("i = 2.0", bb)  # an integral double converts into the int entry
    assert bb.get("i") == 2 and type(bb.get("i")) is int
    run("d = 4", bb)  # an int converts into the double entry
    assert bb.get("d") == 4.0 and type(bb.get("d")) is float
    run("i += 1", bb)  # computed in double, stored back as int
    assert bb.get("i") == 3 and type(bb.get("i")) is int
    run("s += ' more'", bb)
    assert bb.get("s") == "text more"
    run("n := -1", bb)  # unary minus yields a double
    assert bb.get("n") == -1.0 and type(bb.get("n")) is float
    run("i = '7'", bb)  # a string into a numeric entry goes through StringToDouble
    assert bb.get("i") == 7.0


def test_assignment_increments_the_sequence_id() -> None:
    bb = Blackboard.create()
    run("x := 1", bb)
    first = bb.get_entry("x").sequence_id  # type: ignore[union-attr]
    run("x = 1", bb)
    assert bb.get_entry("x").sequence_id == first + 1  # type: ignore[union-attr]


def test_enums_shadow_the_blackboard_and_are_doubles() -> None:
    bb = Blackboard.create()
    bb.set("RED", 99)
    assert run("RED", bb, {"RED": 1}) == 1.0
    assert run("c := GREEN; c == GREEN", bb, {"GREEN": 2}) == 1.0
    assert run("'GREEN' == 2", bb, {"GREEN": 2}) == 1.0


def test_root_blackboard_reference_with_at() -> None:
    root = Blackboard.create()
    child = Blackboard.create(root)
    run("@g := 5; local := 1", child)
    assert root.get("g") == 5
    assert "local" not in root.keys() and child.get("local") == 1
    assert run("@g + 1", child) == 6.0


def test_logic_operators_evaluate_both_sides() -> None:
    bb = Blackboard.create()
    run("x := 0", bb)
    run("false && (x := 1)", bb)
    assert bb.get("x") == 1  # no short-circuit, as in BT.CPP


@pytest.mark.parametrize(
    ("code", "expected"),
    [
        ("9" * 5000, 0),
        ("0x" + "F" * 5000, 0),
        ("9223372036854775807", 2**63 - 1),
    ],
)
def test_overlong_numbers_behave_like_from_chars(code: str, expected: object) -> None:
    assert run(code) == expected  # an int64 overflow leaves 0, as std::from_chars does


def test_an_out_of_range_real_literal_is_a_parse_error() -> None:
    with pytest.raises(ScriptParseError, match="out of bound"):
        parse_script("1e" + "9" * 5000)


def test_bitwise_operators_need_int64_operands() -> None:
    with pytest.raises(ScriptError, match="Binary operators are not allowed"):
        run("1e300 | 1")


def test_deep_nesting_is_a_parse_error_not_a_crash() -> None:
    with pytest.raises(ScriptParseError, match="nests deeper"):
        parse_script("(" * 5000 + "1" + ")" * 5000)
    with pytest.raises(ScriptParseError):
        parse_script("-" * 5000 + "1")


_EDGE_VALUES = [
    0,
    1,
    -1,
    7,
    2**53 - 2,
    2**53 - 1,
    2**53,
    -(2**53 - 1),
    -(2**53),
    2**62,
    0.5,
    -2.5,
    1e300,
    True,
    "3",
    None,
]


@pytest.mark.parametrize(
    "code",
    [
        "x += 1",
        "x -= 1",
        "x *= 3",
        "x *= 2",
        "x += 0",
        "x >= 0",
        "x < 1",
        "x == 1",
        "x != 7",
        "x > 2.5",
        "x <= -1",
    ],
)
@pytest.mark.parametrize("start", _EDGE_VALUES, ids=repr)
def test_compiled_fast_paths_match_the_tree_walking_evaluator(code: str, start: object) -> None:
    """The closures for `name op= int` and `name cmp number` give what the AST evaluator gives:
    the same value, the same entry afterwards, or the same error (2**53 limits, types, empty)."""
    script = parse_script(code)
    results = []
    for evaluate in (script.run, lambda bb, enums: script.statements[0].evaluate(bb, enums)):
        bb = Blackboard.create()
        bb.set("x", start)
        try:
            outcome: object = ("value", evaluate(bb, {}))
        except Exception as error:  # compared below
            outcome = ("error", str(error).splitlines()[-1])
        entry = bb.get_entry("x")
        results.append((outcome, entry.value if entry is not None else None))
    assert results[0] == results[1], f"{code} with x={start!r}: compiled {results[0]}, evaluator {results[1]}"


def test_compiled_comparison_reads_an_enum_before_the_blackboard() -> None:
    bb = Blackboard.create()
    bb.set("RED", 5)
    assert run("RED == 2", bb, {"RED": 2}) == 1.0
    assert run("RED == 5", bb, {"BLUE": 1}) == 1.0
