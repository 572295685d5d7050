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
    tree.add_status_observer(recorder)
    assert tree.tick_once() is NodeStatus.FAILURE
    changes = recorder.take()
    assert changes == seen, f"recorder {changes}\nplain observer {seen}"
    assert all(type(change) is NodeStatusChange for change in changes)
    assert all(type(change.status) is int and type(change.previous) is int for change in changes)
    assert len(changes) > 8
    assert recorder.take() == []
    # the leaves that failed (the Inverter fails too but is no leaf): the failure message names the last one
    assert recorder.failures == [("first try", "AlwaysFailure")], recorder.failures
