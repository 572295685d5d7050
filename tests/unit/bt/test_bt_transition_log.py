"""A tree's transition log reports exactly the changes a status observer callback sees."""

from __future__ import annotations

import pytest

from kinema.bt import BehaviorTreeFactory, NodeStatus
from kinema.bt.errors import BTLogicError

XML = """
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="top">
      <ReactiveSequence>
        <ScriptCondition code="n &gt;= 0"/>
        <Fallback><AlwaysFailure name="first try"/><AlwaysSuccess/></Fallback>
        <Script code="n += 1"/>
      </ReactiveSequence>
      <SubTree ID="Leaf" n="{n}"/>
      <Inverter><AlwaysSuccess name="flipped"/></Inverter>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Leaf"><ForceSuccess><AlwaysFailure/></ForceSuccess></BehaviorTree>
</root>
"""

RUNNING_XML = """
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence><AlwaysSuccess/><Sleep msec="100000"/></Sequence>
  </BehaviorTree>
</root>
"""


def _tree(xml: str):
    factory = BehaviorTreeFactory()
    tree = factory.create_tree_from_text(xml)
    tree.root_blackboard.set("n", 0)
    return tree


def test_log_matches_observer_callbacks_over_ticks_and_a_halt() -> None:
    tree = _tree(XML)
    seen: list[tuple[str, NodeStatus, NodeStatus]] = []
    tree.add_status_observer(lambda _t, node, prev, new: seen.append((node.full_path, prev, new)))
    log = tree.record_transitions()
    for _ in range(3):
        assert tree.tick_once() is NodeStatus.FAILURE
    logged = [(node.full_path, prev, new) for node, prev, new, _stamp in log.take()]
    assert logged == seen, f"log {logged}\nobserver {seen}"
    assert len(logged) > 30
    assert log.take() == []

    running = _tree(RUNNING_XML)
    seen.clear()
    running.add_status_observer(lambda _t, node, prev, new: seen.append((node.full_path, prev, new)))
    log = running.record_transitions()
    assert running.tick_once() is NodeStatus.RUNNING
    running.halt_tree()
    taken = log.take()
    assert [(node.full_path, prev, new) for node, prev, new, _ in taken] == seen
    assert seen[-1][2] is NodeStatus.IDLE, seen
    stamps = [stamp for *_, stamp in taken]
    assert stamps == sorted(stamps), stamps


def test_one_log_per_tree_and_close_stops_it() -> None:
    tree = _tree(XML)
    log = tree.record_transitions()
    with pytest.raises(BTLogicError, match="already has a transition log"):
        tree.record_transitions()
    tree.tick_once()
    log.close()
    tree.tick_once()
    assert len(log.take()) > 0  # what was recorded before close stays readable
    assert log.take() == []
    again = tree.record_transitions()
    tree.tick_once()
    assert len(again.take()) > 0


def test_callbacks_and_the_log_come_and_go_independently() -> None:
    # One call per change serves the log, the callbacks or both: each reader sees exactly its own span.
    tree = _tree(XML)
    reference = _tree(XML)
    every: list[tuple[str, NodeStatus, NodeStatus]] = []
    reference.add_status_observer(lambda _t, node, prev, new: every.append((node.full_path, prev, new)))
    per_tick = []
    for _ in range(4):
        before = len(every)
        reference.tick_once()
        per_tick.append(every[before:])

    seen: list[tuple[str, NodeStatus, NodeStatus]] = []
    handle = tree.add_status_observer(lambda _t, node, prev, new: seen.append((node.full_path, prev, new)))
    tree.tick_once()  # callback only
    log = tree.record_transitions()
    tree.tick_once()  # both
    tree.remove_status_observer(handle)
    tree.tick_once()  # log only
    log.close()
    tree.tick_once()  # neither
    assert seen == per_tick[0] + per_tick[1]
    assert [(node.full_path, prev, new) for node, prev, new, _ in log.take()] == per_tick[1] + per_tick[2]
    assert all(not node._watched and node._log is None for node in tree.nodes())
