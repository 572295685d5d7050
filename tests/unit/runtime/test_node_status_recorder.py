"""The objective server's status observer reports every transition with the node's fields."""

from __future__ import annotations

from typing import Any

from kinema.bt import BehaviorTreeFactory, NodeStatus
from kinema.runtime.objective_server import NodeStatusChange, NodeStatusRecorder

XML = """
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="top">
      <Fallback><AlwaysFailure name="first try"/><AlwaysSuccess/></Fallback>
      <Inverter><AlwaysSuccess name="flipped"/></Inverter>
    </Sequence>
  </BehaviorTree>
</root>
"""


def test_recorder_reports_what_a_plain_observer_sees() -> None:
    tree = BehaviorTreeFactory().create_tree_from_text(XML)
    seen: list[NodeStatusChange] = []

    def plain(timestamp: float, node: Any, previous: Any, status: Any) -> None:
        seen.append(
            NodeStatusChange(
                timestamp,
                node.uid,
                node.full_path,
                node.registration_id,
                node.name,
                int(previous),
                int(status),
            )
        )

    recorder = NodeStatusRecorder()
    tree.add_status_observer(plain)
    recorder.attach(tree)  # as the objective server does: through the tree's transition log
    assert tree.tick_once() is NodeStatus.FAILURE
    changes = recorder.take()
    # The log stamps each change with the time of its root tick, not of the change itself.
    assert [c[1:] for c in changes] == [c[1:] for c in seen], f"recorder {changes}\nplain observer {seen}"
    assert all(abs(c.timestamp - s.timestamp) < 1.0 for c, s in zip(changes, seen, strict=True))
    assert all(type(change) is NodeStatusChange for change in changes)
    assert all(type(change.status) is int and type(change.previous) is int for change in changes)
    assert len(changes) > 8
    assert recorder.take() == []
    # the leaves that failed (the Inverter fails too but is no leaf): the failure message names the last one
    assert recorder.failures == [("first try", "AlwaysFailure")], recorder.failures


def test_recorder_as_a_plain_observer_still_works() -> None:
    tree = BehaviorTreeFactory().create_tree_from_text(XML)
    recorder = NodeStatusRecorder()
    tree.add_status_observer(recorder)
    assert tree.tick_once() is NodeStatus.FAILURE
    assert len(recorder.take()) > 8
    assert recorder.failures == [("first try", "AlwaysFailure")], recorder.failures
