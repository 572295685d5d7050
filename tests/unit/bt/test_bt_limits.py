"""Size limits (kinema.bt.limits): runaway scripts and entries fail, oversized trees are refused at load."""

from __future__ import annotations

import pytest

from kinema.bt import BehaviorTreeFactory, Blackboard, BTError, NodeStatus, SyncActionNode, output_port
from kinema.bt.limits import MAX_ENTRY_CHARS, MAX_ENTRY_ITEMS, MAX_SCRIPT_STRING_CHARS, MAX_TREE_NODES


def doc(body: str) -> str:
    return f'<root BTCPP_format="4"><BehaviorTree ID="Main">{body}</BehaviorTree></root>'


def tick_until_error(tree, limit: int = 100) -> tuple[int, BaseException]:
    for tick in range(1, limit + 1):
        try:
            tree.tick_once()
        except BTError as error:
            return tick, error
    raise AssertionError(f"the tree ran {limit} ticks without passing a limit")


@pytest.mark.parametrize("code", ["s := s .. s", "s := s + s", "s += s"])
def test_a_script_doubling_a_string_every_tick_fails_at_the_limit(code: str) -> None:
    bb = Blackboard.create()
    bb.set("s", "x")
    tree = BehaviorTreeFactory().create_tree_from_text(
        doc(f'<KeepRunningUntilFailure><Script code="{code}"/></KeepRunningUntilFailure>'), bb
    )
    ticks, error = tick_until_error(tree)
    assert "MAX_SCRIPT_STRING_CHARS" in str(error) and f"{MAX_SCRIPT_STRING_CHARS:,}" in str(error), error
    assert ticks <= 22
    assert len(bb.get("s")) <= MAX_SCRIPT_STRING_CHARS


def test_strings_up_to_the_limit_still_work() -> None:
    bb = Blackboard.create()
    bb.set("s", "x" * (MAX_SCRIPT_STRING_CHARS // 2))
    tree = BehaviorTreeFactory().create_tree_from_text(doc('<Script code="s := s .. s"/>'), bb)
    assert tree.tick_once() is NodeStatus.SUCCESS
    assert len(bb.get("s")) == MAX_SCRIPT_STRING_CHARS


class Grow(SyncActionNode):
    """Writes a list one item longer on every tick (a behavior that grows a vector without end)."""

    size = MAX_ENTRY_ITEMS - 2

    @classmethod
    def provided_ports(cls):
        return [output_port("out", list[int])]

    def tick(self) -> NodeStatus:
        Grow.size += 1
        self.set_output("out", [0] * Grow.size)
        return NodeStatus.SUCCESS


def test_a_behavior_growing_a_vector_without_end_fails_at_the_entry_limit() -> None:
    factory = BehaviorTreeFactory()
    factory.register_node_type(Grow)
    tree = factory.create_tree_from_text(
        doc('<KeepRunningUntilFailure><Grow out="{v}"/></KeepRunningUntilFailure>')
    )
    ticks, error = tick_until_error(tree)
    assert ticks == 3
    assert "blackboard entry [v]" in str(error) and "MAX_ENTRY_ITEMS" in str(error), error
    assert len(tree.root_blackboard.get("v")) == MAX_ENTRY_ITEMS


def test_blackboard_refuses_oversized_strings_and_containers() -> None:
    bb = Blackboard.create()
    with pytest.raises(BTError, match="MAX_ENTRY_CHARS"):
        bb.set("big", "x" * (MAX_ENTRY_CHARS + 1))
    with pytest.raises(BTError, match="MAX_ENTRY_ITEMS"):
        bb.set("@big", list(range(MAX_ENTRY_ITEMS + 1)))
    assert "big" not in bb
    bb.set("ok", b"x" * MAX_ENTRY_CHARS)


def _sequence_of(children: int) -> str:
    return doc("<Sequence>" + "<AlwaysSuccess/>" * children + "</Sequence>")


def test_a_tree_at_the_node_limit_loads_and_ticks() -> None:
    tree = BehaviorTreeFactory().create_tree_from_text(_sequence_of(MAX_TREE_NODES - 1))
    assert len(tree) == MAX_TREE_NODES
    assert max(node.uid for node in tree.nodes()) == MAX_TREE_NODES
    assert tree.tick_once() is NodeStatus.SUCCESS


def test_a_tree_past_the_node_limit_is_refused_at_load() -> None:
    with pytest.raises(BTError, match="more than 65,535 nodes") as refused:
        BehaviorTreeFactory().create_tree_from_text(_sequence_of(MAX_TREE_NODES))
    assert "MAX_TREE_NODES" in str(refused.value)


def test_subtree_instances_count_towards_the_node_limit() -> None:
    # 300 instances of a 300-node SubTree: 90,301 nodes
    sub = "<Sequence>" + "<AlwaysSuccess/>" * 299 + "</Sequence>"
    calls = "".join(f'<SubTree ID="Sub" name="s{i}"/>' for i in range(300))
    xml = (
        '<root BTCPP_format="4" main_tree_to_execute="Main">'
        f'<BehaviorTree ID="Main"><Sequence>{calls}</Sequence></BehaviorTree>'
        f'<BehaviorTree ID="Sub">{sub}</BehaviorTree></root>'
    )
    with pytest.raises(BTError, match="more than 65,535 nodes"):
        BehaviorTreeFactory().create_tree_from_text(xml)
