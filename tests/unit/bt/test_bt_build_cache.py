"""Building the same XML again reuses its parsed and compiled form, never the nodes or blackboards."""

from __future__ import annotations

import gc

import pytest

from kinema.bt import BehaviorTreeFactory, NodeStatus
from kinema.bt.errors import BTError
from kinema.bt.xmlparser import TreeDefinition

XML = """
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <Script code="count += 1"/>
      <SubTree ID="Leaf" value="{count}"/>
      <SubTree ID="Leaf" name="second" value="{count}"/>
      <Probe/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Leaf">
    <Sequence><ScriptCondition code="value &gt; 0"/><AlwaysSuccess _onSuccess="seen := true"/></Sequence>
  </BehaviorTree>
</root>
"""


def _factory() -> BehaviorTreeFactory:
    factory = BehaviorTreeFactory()
    factory.register_simple_action("Probe", lambda node: NodeStatus.SUCCESS)
    return factory


def _shape(tree) -> list[tuple[int, str, str]]:
    return [(node.uid, node.full_path, node.registration_id) for node in tree.nodes()]


def test_rebuilt_trees_are_independent_and_identical_in_shape() -> None:
    factory = _factory()
    first = factory.create_tree_from_text(XML)
    second = factory.create_tree_from_text(XML)
    fresh = _factory().create_tree_from_text(XML)
    assert _shape(first) == _shape(second) == _shape(fresh)
    assert not set(map(id, first.nodes())) & set(map(id, second.nodes()))
    assert all(a.config is not b.config for a, b in zip(first.nodes(), second.nodes(), strict=True))
    first.root_blackboard.set("count", 0)
    second.root_blackboard.set("count", 41)
    assert first.tick_once() is NodeStatus.SUCCESS
    assert first.tick_once() is NodeStatus.SUCCESS
    assert second.tick_once() is NodeStatus.SUCCESS
    assert first.root_blackboard.get("count") == 2
    assert second.root_blackboard.get("count") == 42
    scopes = {s.instance_name: s.blackboard for s in second.subtrees}
    assert scopes["second"].get("seen") == 1  # a script's true (BT.CPP stores it as a number)


def test_a_registry_change_is_seen_by_the_next_build() -> None:
    factory = BehaviorTreeFactory()
    with pytest.raises(BTError, match="Probe"):
        factory.create_tree_from_text(XML)
    factory.register_simple_action("Probe", lambda node: NodeStatus.FAILURE)
    tree = factory.create_tree_from_text(XML)
    tree.root_blackboard.set("count", 0)
    assert tree.tick_once() is NodeStatus.FAILURE
    factory.unregister("Probe")
    factory.register_simple_action("Probe", lambda node: NodeStatus.SUCCESS)
    tree = factory.create_tree_from_text(XML)
    tree.root_blackboard.set("count", 0)
    assert tree.tick_once() is NodeStatus.SUCCESS


def test_a_dropped_factory_takes_its_loaded_documents_with_it() -> None:
    # The cache of loaded documents belongs to the factory: a runtime that makes a factory per
    # reload does not keep every version of every objective it ever loaded.
    def alive() -> int:
        gc.collect()
        return sum(1 for obj in gc.get_objects() if isinstance(obj, TreeDefinition))

    before = alive()
    factory = _factory()
    factory.create_tree_from_text(XML)
    assert alive() == before + 2  # Main and Leaf
    for _ in range(3):
        _factory().create_tree_from_text(XML)
    assert alive() == before + 2
    del factory
    assert alive() == before
