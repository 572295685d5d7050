"""Ports, conversions and blackboard typing (reference §1.5, §6)."""

from __future__ import annotations

import math
from enum import IntEnum

import pytest

from kinema.bt import (
    Blackboard,
    BTError,
    BTLogicError,
    NodeStatus,
    SyncActionNode,
    input_port,
    output_port,
)
from kinema.bt.conversions import cast_value, convert_from_string

S, F = NodeStatus.SUCCESS, NodeStatus.FAILURE


@pytest.mark.parametrize(
    ("port_type", "text", "expected"),
    [
        (int, "42", 42),
        (int, "-7", -7),
        (int, "3abc", 3),  # a numeric prefix is enough
        (int, "2.7", 2),
        (float, "1.5", 1.5),
        (float, "1e3", 1000.0),
        (float, "2.5xyz", 2.5),
        (float, "inf", math.inf),
        (str, " spaced ", " spaced "),
        (bool, "true", True),
        (bool, "FALSE", False),
        (bool, "1", True),
        (NodeStatus, "RUNNING", NodeStatus.RUNNING),
        (list[int], "1;2;3", [1, 2, 3]),
        (list[str], "a;;b", ["a", "", "b"]),
        (list[str], "a;b;", ["a", "b"]),
        (list[float], "", []),
        (list[float], "json:[1.5, 2]", [1.5, 2.0]),
        (list[bool], "true;false", [True, False]),
    ],
)
def test_convert_from_string(port_type: object, text: str, expected: object) -> None:
    assert convert_from_string(port_type, text) == expected


@pytest.mark.parametrize(
    ("port_type", "text"),
    [
        (int, ""),
        (int, " 4"),
        (int, "abc"),
        (int, "+5"),
        (float, "x"),
        (bool, "yes"),
        (bool, "2"),
        (NodeStatus, "OK"),
    ],
)
def test_convert_from_string_rejects(port_type: object, text: str) -> None:
    with pytest.raises(BTError):
        convert_from_string(port_type, text)


@pytest.mark.parametrize(
    ("value", "target", "expected"),
    [
        (3, float, 3.0),
        (2.0, int, 2),
        (1, bool, True),
        (0.5, bool, True),
        (42, str, "42"),
        (42.0, str, "42.000000"),
        ("17abc", int, 17),
        ("2.5", float, 2.5),
        (True, int, 1),
    ],
)
def test_cast_value(value: object, target: object, expected: object) -> None:
    result = cast_value(value, target)
    assert result == expected and type(result) is type(expected)


@pytest.mark.parametrize(("value", "target"), [(2.5, int), (2, bool), ("true", bool), ([1], int)])
def test_cast_value_rejects(value: object, target: object) -> None:
    with pytest.raises(BTError):
        cast_value(value, target)


def test_blackboard_typing_rules() -> None:
    bb = Blackboard.create()
    bb.set("s", "text")  # a string creates a generic entry
    assert not bb.get_entry("s").strongly_typed  # type: ignore[union-attr]
    bb.set("s", 5)  # which takes the type of the next value
    assert bb.get_entry("s").type is int  # type: ignore[union-attr]
    bb.set("i", 5)
    bb.set("i", "7")  # a string is parsed with the entry's type
    assert bb.get("i") == 7
    bb.set("i", 3.0)  # an integral double converts
    assert bb.get("i") == 3 and type(bb.get("i")) is int
    with pytest.raises(BTLogicError, match="type of a port shall not change"):
        bb.set("i", 2.5)
    with pytest.raises(BTLogicError):
        bb.set("i", "not a number")
    bb.set("d", 1.5)
    bb.set("d", 2)
    assert bb.get("d") == 2.0 and type(bb.get("d")) is float


def test_blackboard_errors_name_the_key() -> None:
    bb = Blackboard.create()
    with pytest.raises(BTError, match=r"Missing key \[nope\]"):
        bb.get("nope")
    bb.create_entry("empty", int)
    with pytest.raises(BTError, match=r"Entry \[empty\] hasn't been initialized"):
        bb.get("empty")
    assert bb.get_or("nope", 7) == 7


def test_remapping_autoremap_private_and_root() -> None:
    root = Blackboard.create()
    child = Blackboard.create(root)
    child.add_subtree_remapping("inner", "outer")
    child.set("inner", 1)
    assert root.get("outer") == 1
    child.enable_auto_remapping(True)
    child.set("shared", 2)
    child.set("_private", 3)
    assert root.get("shared") == 2
    assert "_private" not in root.keys() and child.get("_private") == 3
    child.set("@top", 4)
    assert root.get("top") == 4
    child.unset("inner")  # local only: the parent's entry stays
    assert root.get("outer") == 1


def test_blackboard_observer_sees_every_write() -> None:
    bb = Blackboard.create()
    seen = []
    remove = bb.add_observer(lambda key, entry: seen.append((key, entry.value, entry.sequence_id)))
    bb.set("a", 1)
    bb.set("a", 2)
    remove()
    bb.set("a", 3)
    assert seen == [("a", 1, 1), ("a", 2, 2)]


def test_blackboard_observers_come_and_go_independently_even_from_a_callback() -> None:
    bb = Blackboard.create()
    other = Blackboard.create()
    calls: list[str] = []

    def once(key: str, entry: object) -> None:
        calls.append("once")
        remove_once()  # leaving during a write: the write still reaches the others

    remove_once = bb.add_observer(once)
    remove_all = bb.add_observer(lambda key, entry: calls.append("all"))
    bb.set("a", 1)
    bb.set("a", 2)
    other.set("a", 1)  # another scope's observers are its own
    assert calls == ["once", "all", "all"]
    remove_once()  # twice is harmless
    remove_all()
    bb.set("a", 3)
    assert calls == ["once", "all", "all"]


class Doubler(SyncActionNode):
    @classmethod
    def provided_ports(cls) -> list:
        return [input_port("in", int, description="value"), output_port("out", int)]

    def tick(self) -> NodeStatus:
        self.set_output("out", self.get_input("in") * 2)
        return S


def test_port_values_literal_pointer_default_and_same_name(bench) -> None:
    bench.factory.register_node_type(Doubler, "Doubler")
    tree = bench.tree(
        '<Sequence><Doubler in="21" out="{a}"/><Doubler in="{a}" out="{=}"/><Doubler in="{out}" out="{b}"/>'
        "</Sequence>"
    )
    assert tree.tick_once() is S
    bb = tree.root_blackboard
    assert (bb.get("a"), bb.get("out"), bb.get("b")) == (42, 84, 168)


def test_missing_input_error_names_node_and_port(bench) -> None:
    bench.factory.register_node_type(Doubler, "Doubler")
    tree = bench.tree('<Doubler name="twice" out="{x}"/>')
    with pytest.raises(BTError) as info:
        tree.tick_once()
    assert "twice" in str(info.value) and "[in]" in str(info.value)


def test_try_get_input_does_not_raise(bench) -> None:
    captured = []

    def probe(node):
        captured.append(node.try_get_input("x"))
        return S

    bench.factory.register_simple_action("Probe", probe, [input_port("x", int)])
    bench.tree('<Probe x="{missing}"/>').tick_once()
    assert not captured[0].ok and "missing" in captured[0].error


def test_unknown_port_and_output_literal(bench) -> None:
    bench.factory.register_node_type(Doubler, "Doubler")
    with pytest.raises(BTError, match="not in the providedPorts"):
        bench.tree('<Doubler inn="1" out="{x}"/>')
    with pytest.raises(BTLogicError, match="can not be converted to int"):
        bench.tree('<Doubler in="1" out="literal"/>')  # literals of typed ports are checked when building
    tree = bench.tree('<Doubler in="1" out="2"/>')
    with pytest.raises(BTError, match="blackboard pointer"):
        tree.tick_once()


def test_a_pointer_with_spaces_is_a_literal_for_typed_port_validation(bench) -> None:
    bench.factory.register_node_type(Doubler, "Doubler")
    with pytest.raises(BTLogicError):
        bench.tree('<Doubler in="{a}  " out="{b}"/>')


def test_typed_entries_are_created_when_the_tree_is_built(bench) -> None:
    bench.factory.register_node_type(Doubler, "Doubler")
    tree = bench.tree('<Sequence><Script code="out = 5"/><Doubler in="{out}" out="{res}"/></Sequence>')
    assert tree.root_blackboard.get_entry("res").type is int  # type: ignore[union-attr]
    assert tree.tick_once() is S  # `=` works: building created the entry "out"
    assert tree.root_blackboard.get("res") == 10


def test_conflicting_port_types_fail_at_creation(bench) -> None:
    bench.factory.register_node_type(Doubler, "Doubler")
    bench.factory.register_simple_action("Text", lambda n: S, [input_port("t", list[str])])
    with pytest.raises(BTError, match="was initially created with type"):
        bench.tree('<Sequence><Doubler in="1" out="{v}"/><Text t="{v}"/></Sequence>')


def _literal_into_timeout(msec: str) -> str:
    return f"""
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main"><Sequence><SubTree ID="Relax" wait_ms="{msec}"/></Sequence></BehaviorTree>
  <BehaviorTree ID="Relax">
    <Timeout msec="{{wait_ms}}"><Sleep msec="2000"/></Timeout>
  </BehaviorTree>
</root>"""


def test_a_subtree_number_literal_reaches_an_unsigned_port_as_moveit_pro_files_expect() -> None:
    """MoveIt Pro's Force Relaxation passes relaxation_time_ms="500" on to Timeout's unsigned msec: BT.CPP
    4.10 refuses it (the literal is an int since 4.9.1), MoveIt Pro's BT.CPP (text literals) runs it."""
    import time

    from kinema.bt import BehaviorTreeFactory

    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(_literal_into_timeout("30"))
    tree = factory.create_tree("Main")
    started = time.monotonic()
    assert tree.tick_while_running() is NodeStatus.FAILURE  # the 30 ms timeout fired, not the 2 s sleep
    assert time.monotonic() - started < 1.5
    for refused in ("-5", "1.5"):  # numbers an unsigned port cannot hold stay refused
        factory = BehaviorTreeFactory()
        factory.register_behavior_tree_from_text(_literal_into_timeout(refused))
        with pytest.raises(BTError, match="was initially created with type"):
            factory.create_tree("Main")


def test_enum_ports(bench) -> None:
    class Color(IntEnum):
        RED = 1
        BLUE = 2

    seen = []
    bench.factory.register_scripting_enum("GREEN", 3)
    bench.factory.register_simple_action(
        "Paint", lambda n: seen.append(n.get_input("c")) or S, [input_port("c", Color)]
    )
    bench.tree('<Sequence><Paint c="BLUE"/><Paint c="1"/></Sequence>').tick_once()
    assert seen == [Color.BLUE, Color.RED]


def test_register_scripting_enum_twice_with_another_value_fails(bench) -> None:
    bench.factory.register_scripting_enum("A", 1)
    bench.factory.register_scripting_enum("A", 1)
    with pytest.raises(BTLogicError):
        bench.factory.register_scripting_enum("A", 2)


def test_set_blackboard(bench) -> None:
    tree = bench.tree(
        '<Sequence><SetBlackboard output_key="a" value="hello"/><Script code="n := 5"/>'
        '<SetBlackboard output_key="b" value="{n}"/></Sequence>'
    )
    assert tree.tick_once() is S
    assert tree.root_blackboard.get("a") == "hello"
    assert tree.root_blackboard.get_entry("a").type is str  # type: ignore[union-attr]
    assert tree.root_blackboard.get("b") == 5


def test_set_blackboard_from_a_missing_entry_fails(bench) -> None:
    tree = bench.tree('<SetBlackboard output_key="b" value="{nothing}"/>')
    assert tree.tick_once() is F  # the port pre-created an empty entry: nothing to copy


def test_set_blackboard_into_a_script_entry_stores_an_empty_value(bench) -> None:
    tree = bench.tree('<Sequence><Script code="x := 5"/><SetBlackboard output_key="x" value="7"/></Sequence>')
    assert tree.tick_once() is S  # BT.CPP quirk: the entry ends up empty
    with pytest.raises(BTError, match="hasn't been initialized"):
        tree.root_blackboard.get("x")


def test_unset_blackboard(bench) -> None:
    tree = bench.tree('<Sequence><Script code="k := 1"/><UnsetBlackboard key="k"/></Sequence>')
    assert tree.tick_once() is S
    assert "k" not in tree.root_blackboard


class Point:
    def __init__(self, x: float, y: float) -> None:
        self.x, self.y = x, y

    @classmethod
    def from_string(cls, text: str) -> Point:
        x, y = text.split(";")
        return cls(float(x), float(y))


def test_custom_types_with_from_string(bench) -> None:
    seen = []
    bench.factory.register_simple_action(
        "Goto", lambda n: seen.append(n.get_input("p")) or S, [input_port("p", Point)]
    )
    bench.tree('<Goto p="1;2"/>').tick_once()
    assert (seen[0].x, seen[0].y) == (1.0, 2.0)
    with pytest.raises(BTError, match="can not be converted"):
        bench.tree('<Goto p="nonsense"/>')
