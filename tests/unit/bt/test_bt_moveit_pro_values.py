"""Values MoveIt Pro's objectives write, parsed as BT.CPP 4.8 parses them (checked against the real library).

MoveIt Pro's lab_sim objectives write vectors of doubles with spaces after the ';' (``"0.0; 0.0; 1.0"``)
or a trailing ';' (``"0.1;0.2;0.3;"``), and double-quoted strings in scripts
(``viz_marker_name:=&quot;place_pose_&quot;..viz_idx``). BT.CPP 4.8 (``std::stod``, the lexy script
grammar) accepts all of these; 4.9+ (``std::from_chars``, the hand-written tokenizer) rejects the
spaces and the double quotes. Kinema follows 4.8 here. Where ``behaviortreepy`` (BT.CPP 4.8.2) is
installed, every row is also run through the real library.
"""

from __future__ import annotations

import math

import pytest

from kinema.bt import BehaviorTreeFactory, NodeStatus, TreeNode
from kinema.bt.conversions import convert_from_string
from kinema.bt.errors import BTError

ERROR = "error"

# (queue text, what BT.CPP 4.8.2's convertFromString<std::vector<double>> gives)
DOUBLE_VECTORS = [
    ("0.0; 0.0; 1.0", [0.0, 0.0, 1.0]),  # corpus: spaces after ';'
    ("0.1;0.2;0.3;", [0.1, 0.2, 0.3]),  # corpus: a trailing ';' adds nothing
    ("-0.076413; 0.97; 0.42;", [-0.076413, 0.97, 0.42]),  # add_table_to_planning_scene.xml
    ("0.; 0.; 0.; 1.", [0.0, 0.0, 0.0, 1.0]),  # get_transform_frame_pose.xml
    ("0.000; 1.000; 0.000; 0.000", [0.0, 1.0, 0.0, 0.0]),
    ("", []),
    ("+1.5", [1.5]),
    ("0x10", [16.0]),  # hex floats (strtod)
    ("-0x.8p1", [-1.0]),
    ("1.5abc;2", [1.5, 2.0]),  # a numeric prefix is enough
    ("1,5", [1.0]),
    ("nan", [math.nan]),
    ("-Infinity", [-math.inf]),
    ("1e+", [1.0]),
    ("2.2250738585072014e-308", [2.2250738585072014e-308]),
    ("1;;2", ERROR),  # an empty element between two ';'
    ("1; ;2", ERROR),
    (";", ERROR),
    ("1e400", ERROR),  # overflow: std::stod throws out_of_range
    ("1e-310", ERROR),  # underflow to a subnormal, likewise
    ("..5", ERROR),
    ("+-1", ERROR),
]


def _same(actual: object, expected: object) -> bool:
    if isinstance(actual, list) and isinstance(expected, list):
        return len(actual) == len(expected) and all(
            (math.isnan(a) and math.isnan(e)) or a == e for a, e in zip(actual, expected, strict=True)
        )
    return actual == expected


def _kinema_vector(text: str) -> object:
    try:
        return convert_from_string(list[float], text)
    except BTError:
        return ERROR


@pytest.mark.parametrize(("text", "expected"), DOUBLE_VECTORS)
def test_double_vectors_parse_as_btcpp_4_8(text: str, expected: object) -> None:
    actual = _kinema_vector(text)
    assert _same(actual, expected), f"{text!r}: Kinema gives {actual}, BT.CPP 4.8 gives {expected}"


def test_a_corpus_vector_port_reaches_the_node_as_three_numbers() -> None:
    """A LoopDouble over ``"0.0; 0.0; 1.0"`` visits three values (no load error)."""
    factory = BehaviorTreeFactory()
    seen: list[float] = []

    def record(node: TreeNode) -> NodeStatus:
        seen.append(float(node.config.blackboard.get("v")))
        return NodeStatus.SUCCESS

    factory.register_simple_action("Record", record)
    tree = factory.create_tree_from_text(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><LoopDouble queue="0.0; 0.0; 1.0" value="{v}">'
        "<Record/></LoopDouble></BehaviorTree></root>"
    )
    assert tree.tick_while_running() is NodeStatus.SUCCESS
    assert seen == [0.0, 0.0, 1.0]


# (script setting up viz_idx, the corpus script, the value of viz_marker_name)
SCRIPTS = [
    ("viz_idx:=3", "viz_marker_name:=&quot;place_pose_&quot;..viz_idx", "place_pose_3"),
    ("viz_idx:='7'", "viz_marker_name:=&quot;place_pose_&quot;..viz_idx", "place_pose_7"),
    (
        "viz_idx:=1",
        "viz_marker_name:=&quot;it&apos;s &quot;..&apos;a &quot;test&quot;&apos;",
        'it\'s a "test"',
    ),
]


def _kinema_script(setup: str, code: str) -> object:
    factory = BehaviorTreeFactory()
    tree = factory.create_tree_from_text(
        f'<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence><Script code="{setup}"/>'
        f'<Script code="{code}"/></Sequence></BehaviorTree></root>'
    )
    assert tree.tick_while_running() is NodeStatus.SUCCESS
    return tree.root_blackboard.get("viz_marker_name")


@pytest.mark.parametrize(("setup", "code", "expected"), SCRIPTS)
def test_double_quoted_script_strings_as_in_pick_all_pill_bottles(
    setup: str, code: str, expected: str
) -> None:
    assert _kinema_script(setup, code) == expected


def test_an_unterminated_double_quote_is_a_script_error_naming_the_node() -> None:
    factory = BehaviorTreeFactory()
    with pytest.raises(BTError) as error:
        factory.create_tree_from_text(
            '<root BTCPP_format="4"><BehaviorTree ID="T"><Script code="x:=&quot;abc"/></BehaviorTree></root>'
        )
    assert 'x:="abc' in str(error.value)


# --- the same rows through the real BT.CPP 4.8.2 -------------------------------------------------


def _btcpp_vector(btcpp: object, text: str) -> object:
    factory = btcpp.BehaviorTreeFactory()  # type: ignore[attr-defined]
    seen: list[float] = []
    holder: dict[str, object] = {}

    def record(*_: object) -> object:
        seen.append(holder["tree"].root_blackboard().get_double("v"))  # type: ignore[attr-defined]
        return btcpp.NodeStatus.SUCCESS  # type: ignore[attr-defined]

    factory.register_simple_action("Record", record)
    xml = (
        f'<root BTCPP_format="4"><BehaviorTree ID="T"><LoopDouble queue="{text}" value="{{v}}">'
        "<Record/></LoopDouble></BehaviorTree></root>"
    )
    try:
        tree = factory.create_tree_from_text(xml)
    except RuntimeError:
        return ERROR
    holder["tree"] = tree
    tree.tick_while_running()
    return seen


@pytest.mark.parametrize(("text", "expected"), DOUBLE_VECTORS)
def test_the_table_is_what_btcpp_4_8_does(text: str, expected: object) -> None:
    btcpp = pytest.importorskip("behaviortreepy", reason="behaviortreepy (BT.CPP 4.8.2) is not installed")
    actual = _btcpp_vector(btcpp, text)
    assert _same(actual, expected), f"{text!r}: BT.CPP gives {actual}, the table says {expected}"


@pytest.mark.parametrize(("setup", "code", "expected"), SCRIPTS)
def test_the_script_rows_are_what_btcpp_4_8_does(setup: str, code: str, expected: str) -> None:
    btcpp = pytest.importorskip("behaviortreepy", reason="behaviortreepy (BT.CPP 4.8.2) is not installed")
    tree = btcpp.BehaviorTreeFactory().create_tree_from_text(
        f'<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence><Script code="{setup}"/>'
        f'<Script code="{code}"/></Sequence></BehaviorTree></root>'
    )
    assert tree.tick_while_running() == btcpp.NodeStatus.SUCCESS
    assert tree.root_blackboard().get_string("viz_marker_name") == expected
