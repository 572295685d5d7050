"""The objective server's status observer: every transition, column-wise, decoded to what an observer sees."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from kinema.bt import BehaviorTreeFactory, NodeStatus
from kinema.runtime.node_status import NodeStatusBatch, NodeStatusChange, NodeStatusRecorder
from kinema.sdk.streams import NodeStatusDecoder
from kinema.transport.messages import msg

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


def _plain_observer(tree: Any) -> list[NodeStatusChange]:
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

    tree.add_status_observer(plain)
    return seen


def test_recorder_reports_what_a_plain_observer_sees() -> None:
    tree = BehaviorTreeFactory().create_tree_from_text(XML)
    seen = _plain_observer(tree)
    recorder = NodeStatusRecorder()
    recorder.attach(tree)  # as the objective server does: through the tree's transition log
    assert tree.tick_once() is NodeStatus.FAILURE
    batch = recorder.take()
    assert isinstance(batch, NodeStatusBatch)
    changes = list(batch)
    # The log stamps each change with the time of its root tick, not of the change itself.
    assert [c[1:] for c in changes] == [c[1:] for c in seen], f"recorder {changes}\nplain observer {seen}"
    assert all(abs(c.timestamp - s.timestamp) < 1.0 for c, s in zip(changes, seen, strict=True))
    assert all(type(change.status) is int and type(change.previous) is int for change in changes)
    assert len(changes) > 8
    assert recorder.take() is None
    # the leaves that failed (the Inverter fails too but is no leaf): the failure message names the last one
    assert recorder.last_failure == ("first try", "AlwaysFailure"), recorder.last_failure


def test_the_columns_and_the_split_parts_hold_the_same_changes_as_the_objects() -> None:
    tree = BehaviorTreeFactory().create_tree_from_text(XML)
    recorder = NodeStatusRecorder()
    recorder.attach(tree)
    for _ in range(3):
        tree.tick_once()
    batch = recorder.take()
    assert batch is not None and len(batch.stamps) == 3, batch.stamps  # three ticks, three stamps
    changes = list(batch)
    times, uids, previous, statuses = batch.columns()
    assert times.tolist() == [c.timestamp for c in changes]
    assert uids.tolist() == [c.uid for c in changes]
    assert previous.tolist() == [c.previous for c in changes]
    assert statuses.tolist() == [c.status for c in changes]
    for most in (1, 4, 7, len(batch) - 1):
        parts = batch.split(most)
        assert all(0 < len(part) <= most for part in parts)
        assert [c for part in parts for c in part] == changes, most


def test_the_last_failed_leaf_is_found_in_a_large_tick() -> None:
    # Large enough for the numpy search: 300 leaves succeed, then one fails, then 200 more succeed.
    body = "<AlwaysSuccess/>" * 300 + '<ForceSuccess><AlwaysFailure name="deep"/></ForceSuccess>'
    body += "<AlwaysSuccess/>" * 200
    xml = f'<root BTCPP_format="4"><BehaviorTree ID="Main"><Sequence>{body}</Sequence></BehaviorTree></root>'
    tree = BehaviorTreeFactory().create_tree_from_text(xml)
    recorder = NodeStatusRecorder()
    recorder.attach(tree)
    assert tree.tick_once() is NodeStatus.SUCCESS
    batch = recorder.take()
    assert batch is not None and len(batch) > 1000
    assert recorder.last_failure == ("deep", "AlwaysFailure")


def test_a_subscriber_decodes_the_wire_messages_to_the_same_changes() -> None:
    from kinema.runtime import names
    from kinema.transport.messages import _registry

    registry = _registry(None)
    tree = BehaviorTreeFactory().create_tree_from_text(XML)
    recorder = NodeStatusRecorder()
    recorder.attach(tree)
    tree.tick_once()
    tree.tick_once()
    batch = recorder.take()
    assert batch is not None
    table = batch.table
    # What the agent publishes, through CDR and back.
    table_message = msg(
        names.NODE_TABLE_TYPE,
        objective_name="Demo",
        table_id=table.id,
        uids=table.uid_array,
        node_paths=table.paths,
        node_ids=table.node_ids,
        node_names=table.names,
    )
    import numpy as np

    codes_messages = [
        msg(
            names.NODE_STATUS_TYPE,
            objective_name="Demo",
            table_id=table.id,
            stamps=[{"sec": int(s), "nanosec": round((s % 1) * 1e9)} for s in part.stamps],
            starts=np.asarray(part.starts, dtype=np.uint32),
            codes=part.code_array(),
        )
        for part in batch.split(5)
    ]

    def wire(message: Any, type_name: str) -> Any:
        return registry.deserialize(registry.serialize(message, type_name), type_name)

    decoder = NodeStatusDecoder()
    # The first two parts arrive before the (latched) table: they wait for it, in order.
    assert decoder.on_codes(wire(codes_messages[0], names.NODE_STATUS_TYPE)) is None
    assert decoder.on_codes(wire(codes_messages[1], names.NODE_STATUS_TYPE)) is None
    decoded = decoder.on_table(wire(table_message, names.NODE_TABLE_TYPE))
    assert len(decoded) == 2
    for message in codes_messages[2:]:
        part = decoder.on_codes(wire(message, names.NODE_STATUS_TYPE))
        assert part is not None
        decoded.append(part)
    got = [change for part in decoded for change in part.changes]
    assert all(part.objective_name == "Demo" for part in decoded)
    want = list(batch)
    assert [(c.uid, c.node_path, c.node_id, c.node_name, c.previous_status, c.status) for c in got] == [
        (c.uid, c.node_path, c.node_id, c.node_name, c.previous, c.status) for c in want
    ]
    assert all(abs(g.stamp - w.timestamp) < 1e-6 for g, w in zip(got, want, strict=True))


def _one_tick_as_messages() -> tuple[NodeStatusBatch, Any, Any]:
    """One tick of XML's tree: its batch, and the node table and status codes messages a runtime sends."""
    tree = BehaviorTreeFactory().create_tree_from_text(XML)
    recorder = NodeStatusRecorder()
    recorder.attach(tree)
    tree.tick_once()
    batch = recorder.take()
    assert batch is not None
    table = batch.table
    table_message = SimpleNamespace(
        objective_name="Demo",
        table_id=table.id,
        uids=table.uids,
        node_paths=table.paths,
        node_ids=table.node_ids,
        node_names=table.names,
    )
    codes_message = SimpleNamespace(
        objective_name="Demo",
        table_id=table.id,
        stamps=[SimpleNamespace(sec=1, nanosec=0)],
        starts=[0],
        codes=batch.codes,
    )
    return batch, table_message, codes_message


def test_a_subscriber_whose_table_was_dropped_reads_the_latched_copy_again() -> None:
    import threading
    import time

    from kinema.runtime import names
    from kinema.sdk.client import NodeStatusSubscription

    batch, table_message, codes_message = _one_tick_as_messages()
    subscribed: list[tuple[str, Any]] = []
    closed: list[str] = []

    class Node:
        # The live table message is lost; a new latched subscription reads the publisher's cached copy.
        def create_subscription(self, _type: str, topic: str, callback: Any, latched: bool = False) -> Any:
            subscribed.append((topic, callback))
            if topic == names.NODE_TABLE and sum(t == names.NODE_TABLE for t, _ in subscribed) > 1:
                threading.Thread(target=callback, args=(table_message,)).start()
            return SimpleNamespace(close=lambda: closed.append(topic))

    got: list[Any] = []
    subscription = NodeStatusSubscription(Node(), got.append)
    on_codes = next(callback for topic, callback in subscribed if topic == names.NODE_STATUS)
    on_codes(codes_message)  # no table yet: it waits, and the table is read again
    deadline = time.monotonic() + 10
    # the table can arrive before the old subscription is closed: wait for both
    while not (got and closed) and time.monotonic() < deadline:
        time.sleep(0.01)
    assert got and [c.node_path for c in got[0].changes] == [c.node_path for c in batch]
    assert [t for t, _ in subscribed].count(names.NODE_TABLE) == 2
    assert closed == [names.NODE_TABLE]  # the first table subscription was replaced
    subscription.close()


def test_a_subscriber_keeps_reading_the_latched_table_while_changes_wait_for_it() -> None:
    # A run's last changes may be the only ones naming its table: when the first re-read is lost too, the
    # subscriber must try again on its own (waiting for more changes would wait forever).
    import threading
    import time

    from kinema.runtime import names
    from kinema.sdk.client import NodeStatusSubscription

    batch, table_message, codes_message = _one_tick_as_messages()
    subscribed: list[tuple[str, Any]] = []

    class Node:
        # The live table and the first re-read are lost; the second re-read gets the latched copy.
        def create_subscription(self, _type: str, topic: str, callback: Any, latched: bool = False) -> Any:
            subscribed.append((topic, callback))
            if topic == names.NODE_TABLE and sum(t == names.NODE_TABLE for t, _ in subscribed) == 3:
                threading.Thread(target=callback, args=(table_message,)).start()
            return SimpleNamespace(close=lambda: None)

    got: list[Any] = []
    subscription = NodeStatusSubscription(Node(), got.append)
    subscription.REFETCH_AFTER_S = 0.05
    on_codes = next(callback for topic, callback in subscribed if topic == names.NODE_STATUS)
    on_codes(codes_message)  # the only changes of the run
    deadline = time.monotonic() + 30
    while not got and time.monotonic() < deadline:
        time.sleep(0.01)
    assert got and [c.node_path for c in got[0].changes] == [c.node_path for c in batch]
    assert [t for t, _ in subscribed].count(names.NODE_TABLE) == 3
    subscription.close()
