"""What the agent turns into and out of messages: overrides, blackboard values, result codes."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest

from kinema.errors import ObjectiveError
from kinema.runtime import names
from kinema.runtime.agent import overrides_from_messages, render_value, result_message
from kinema.runtime.overrides import ParameterOverride
from kinema.runtime.result import ObjectiveResult
from kinema.transport.messages import load_interfaces


def _parameter(name: str, kind: int, **values: Any) -> SimpleNamespace:
    fields = {
        "string_value": "",
        "pose_value": None,
        "double_value": 0.0,
        "int_value": 0,
        "bool_value": False,
        "joint_state_value": None,
        "behavior_namespaces": [],
    }
    fields.update(values)
    return SimpleNamespace(description=SimpleNamespace(name=name, type=kind), **fields)


def test_behavior_parameters_become_overrides() -> None:
    parameters = [
        _parameter("a", 0, string_value="[1, 2]", behavior_namespaces=["sub"]),
        _parameter("b", 2, double_value=0.5),
        _parameter("c", 3, int_value=7),
        _parameter("d", 4, bool_value=True),
    ]
    assert overrides_from_messages(parameters) == (
        ParameterOverride("a", "[1, 2]", ("sub",)),
        ParameterOverride("b", 0.5, (), from_yaml=False),
        ParameterOverride("c", 7, (), from_yaml=False),
        ParameterOverride("d", True, (), from_yaml=False),
    )


@pytest.mark.parametrize(
    ("parameter", "reason"), [(_parameter("", 0), "empty name"), (_parameter("x", 9), "has type 9")]
)
def test_malformed_parameters_are_refused(parameter: SimpleNamespace, reason: str) -> None:
    with pytest.raises(ObjectiveError, match=reason):
        overrides_from_messages([parameter])


@pytest.mark.parametrize(
    ("value", "text"),
    [(42, "42"), (1.5, "1.5"), ("Look at Table", "Look at Table"), ([1, 2], "[1, 2]"), ({"a": 1}, "{a: 1}")],
)
def test_blackboard_values_render_as_yaml_flow(value: Any, text: str) -> None:
    assert render_value(value) == text


def test_remembered_renderings_keep_equal_values_of_other_types_apart() -> None:
    """1 == True == 1.0 and 0.0 == -0.0, but they render differently; so do a string and its quoted twin."""
    from kinema.runtime.blackboard_text import _render

    values = [1, True, 1.0, 0, False, 0.0, -0.0, None, "yes", "1", "1", 1, True, "x" * 3000, "x" * 3000]
    for _ in range(2):
        assert [render_value(value) for value in values] == [_render(value) for value in values]
    assert [render_value(value) for value in (1, True, "yes")] == ["1", "true", "'yes'"]


def test_long_values_are_cut() -> None:
    rendered = render_value(list(range(5000)))
    assert len(rendered) <= 2000 and "more" in rendered


def test_results_become_moveit_error_codes() -> None:
    message = result_message(ObjectiveResult.failure("node 'x' returned FAILURE", "Pick"))
    assert message == {"val": 99999, "message": "node 'x' returned FAILURE", "source": "objective_server"}


def test_a_heartbeat_never_reports_a_status_older_than_the_one_published_before_it() -> None:
    """A beat prepared while a run was active and sent after it ended made the TUI see a new run start
    (and wipe the failed node it had just marked). The last beat sent must show how the run ended."""
    import threading

    from kinema.runtime.agent import _Streams
    from kinema.runtime.objective_status import ObjectiveStatus

    beats: list[str] = []

    class Publisher:
        def __init__(self, topic: str) -> None:
            self.topic = topic

        def publish(self, message: Any) -> None:
            if "heartbeat" in self.topic:
                beats.append(str(message.objective_status))

        def publish_raw(self, payload: bytes) -> None:
            self.publish(load_interfaces().deserialize(payload, names.HEARTBEAT_TYPE))

    node = SimpleNamespace(create_publisher=lambda _type, topic, **_: Publisher(topic))
    in_health, release = threading.Event(), threading.Event()

    class Server:
        stall = False

        def health(self) -> Any:
            if Server.stall:  # the periodic beat stalls here once (preempted, under load)
                Server.stall = False
                in_health.set()
                release.wait(10)
            return SimpleNamespace(tick_thread_alive=True, replacements=0, warnings=())

    streams = _Streams(node, None, Server())  # type: ignore[arg-type]
    streams.on_status(ObjectiveStatus.RUNNING, "Add Numbers")
    Server.stall = True
    beats.clear()
    periodic = threading.Thread(target=streams.publish_heartbeat)
    periodic.start()
    assert in_health.wait(10)
    streams.on_status(ObjectiveStatus.FAILURE, "Add Numbers")  # the run ends meanwhile
    release.set()
    periodic.join(10)
    assert beats and beats[-1] == str(ObjectiveStatus.FAILURE), beats


def test_a_large_tick_is_published_as_several_node_status_messages_in_order() -> None:
    from kinema.bt import BehaviorTreeFactory
    from kinema.runtime.agent import NODE_STATUS_CHUNK, _Streams
    from kinema.runtime.node_status import NodeStatusRecorder
    from kinema.transport.messages import _registry

    registry = _registry(None)
    sent: list[tuple[str, Any]] = []

    class Publisher:
        def __init__(self, type_name: str, topic: str) -> None:
            self.type_name = type_name
            self.topic = topic

        def publish(self, message: Any) -> None:
            sent.append((self.topic, message))

        def publish_raw(self, payload: bytes) -> None:
            sent.append((self.topic, registry.deserialize(payload, self.type_name)))

    leaves = NODE_STATUS_CHUNK + NODE_STATUS_CHUNK // 4  # two changes each: three messages
    xml = (
        '<root BTCPP_format="4"><BehaviorTree ID="Big"><Sequence>'
        + "<AlwaysSuccess/>" * leaves
        + "</Sequence></BehaviorTree></root>"
    )
    tree = BehaviorTreeFactory().create_tree_from_text(xml)
    recorder = NodeStatusRecorder()
    recorder.attach(tree)
    tree.tick_once()
    batch = recorder.take()
    assert batch is not None and len(batch) > 2 * NODE_STATUS_CHUNK
    node = SimpleNamespace(create_publisher=lambda type_name, topic, **_: Publisher(type_name, topic))
    streams = _Streams(node, None, SimpleNamespace())  # type: ignore[arg-type]
    streams.on_node_status("Big", batch)
    topics = [topic for topic, _ in sent]
    assert topics == ["/objective_server/node_table"] + ["/objective_server/node_status"] * 3, topics
    table = sent[0][1]
    assert len(table.uids) == leaves + 1 and table.table_id == batch.table.id
    parts = [message for _, message in sent[1:]]
    assert [len(part.codes) for part in parts] == [
        NODE_STATUS_CHUNK,
        NODE_STATUS_CHUNK,
        len(batch) - 2 * NODE_STATUS_CHUNK,
    ]
    assert [int(code) for part in parts for code in part.codes] == batch.codes
    # the table goes out once per run
    sent.clear()
    tree.tick_once()
    streams.on_node_status("Big", recorder.take())  # type: ignore[arg-type]
    assert [topic for topic, _ in sent] == ["/objective_server/node_status"] * 3


def test_loading_and_running_beats_wait_for_the_first_node_changes_the_end_or_the_periodic_beat() -> None:
    """A run that ends in its first tick answers its client before any heartbeat of it is published;
    every status change still gets its heartbeat, in order, and a long build shows within a beat."""
    from kinema.runtime.agent import _Streams
    from kinema.runtime.objective_status import ObjectiveStatus

    beats: list[str] = []

    class Publisher:
        def __init__(self, topic: str) -> None:
            self.topic = topic

        def publish(self, message: Any) -> None:
            if "heartbeat" in self.topic:
                beats.append(str(message.objective_status))

        def publish_raw(self, payload: bytes) -> None:
            self.publish(load_interfaces().deserialize(payload, names.HEARTBEAT_TYPE))

    node = SimpleNamespace(create_publisher=lambda _type, topic, **_: Publisher(topic))
    report = SimpleNamespace(tick_thread_alive=True, replacements=0, warnings=())
    server = SimpleNamespace(health=lambda: report)
    streams = _Streams(node, None, server)  # type: ignore[arg-type]
    streams.on_status(ObjectiveStatus.LOADING, "Quick")
    streams.on_status(ObjectiveStatus.RUNNING, "Quick")
    assert beats == []
    streams.on_status(ObjectiveStatus.SUCCESS, "Quick")
    assert beats == ["Loading", "Running", "Success"]

    beats.clear()
    streams.on_status(ObjectiveStatus.LOADING, "Slow to build")
    streams.publish_heartbeat()  # the periodic beat, 10 Hz
    assert beats == ["Loading"]
    streams.publish_heartbeat()
    assert beats == ["Loading", "Loading"]


@pytest.mark.parametrize("name", ["", "a", "ab", "abc", "Pick \u00e9 and place", "x" * 257])
@pytest.mark.parametrize("status", ["Idle", "Running", "Cancelled", ""])
def test_the_heartbeat_laid_out_directly_is_what_the_generic_serializer_writes(
    name: str, status: str
) -> None:
    from kinema.runtime.heartbeat_cdr import HeartbeatEncoder, generic_serializer

    generic = generic_serializer(load_interfaces(), names.HEARTBEAT_TYPE)
    encoder = HeartbeatEncoder(generic)
    stamps = ((1_700_000_000, 999_999_999), (42, 7))
    assert encoder.encode(*stamps, name, status) == generic(*stamps, name, status)


def test_only_a_run_still_running_a_beat_later_gets_a_running_line(caplog: pytest.LogCaptureFixture) -> None:
    """One line per quick run (its result), not two: the "Running" line is a file write on the tick
    thread per run; a run that lasts gets it from the periodic beat (or its next tick)."""
    import logging

    from kinema.runtime.agent import _Streams
    from kinema.runtime.objective_status import ObjectiveStatus

    class Publisher:
        def publish(self, message: Any) -> None: ...

        def publish_raw(self, payload: bytes) -> None: ...

    node = SimpleNamespace(create_publisher=lambda *_args, **_kwargs: Publisher())
    report = SimpleNamespace(tick_thread_alive=True, replacements=0, warnings=())
    streams = _Streams(node, None, SimpleNamespace(health=lambda: report))  # type: ignore[arg-type]
    caplog.set_level(logging.INFO, logger="kinema.agent")
    for status in (ObjectiveStatus.LOADING, ObjectiveStatus.RUNNING, ObjectiveStatus.SUCCESS):
        streams.on_status(status, "Quick")
    streams.on_run_finished(None, ObjectiveResult.success("Quick"))  # type: ignore[arg-type]
    streams.publish_heartbeat()
    assert [r.getMessage() for r in caplog.records if "Running" in r.getMessage()] == []

    streams.on_status(ObjectiveStatus.LOADING, "Slow")
    streams.on_status(ObjectiveStatus.RUNNING, "Slow")
    streams.publish_heartbeat()
    streams.publish_heartbeat()
    assert [r.getMessage() for r in caplog.records if "Running" in r.getMessage()] == [
        "objective 'Slow': Running"
    ]


def test_a_runs_last_blackboard_is_published_before_its_client_is_answered_and_names_its_objective() -> None:
    """The last snapshot was left to the worker thread, so a client that read the latched blackboard right
    after its result could get the run before's (a loaded CI machine did). Settled, it is out at once; and
    an objective with the same (here empty) entries as the one before still gets a snapshot naming it."""
    from kinema.runtime.agent import _Streams

    published: list[tuple[str, list[str]]] = []

    class Publisher:
        def __init__(self, topic: str) -> None:
            self.topic = topic

        def publish(self, message: Any) -> None:
            if "blackboard" in self.topic:
                published.append((message.objective_name, [entry.value_yaml for entry in message.entries]))

        def publish_raw(self, payload: bytes) -> None:
            pass

    node = SimpleNamespace(create_publisher=lambda _type, topic, **_: Publisher(topic))
    streams = _Streams(node, None, SimpleNamespace())  # type: ignore[arg-type]
    try:
        streams.on_blackboard("Quick", [("Quick", "answer", "int", 42)])
        streams.settle_blackboard()
        assert published == [("Quick", ["42"])]  # on this thread, before settle returned
        streams.on_blackboard("Empty", [])
        streams.settle_blackboard()
        streams.on_blackboard("Also Empty", [])
        streams.settle_blackboard()
        streams.on_blackboard("Also Empty", [])  # the same again: nothing to publish
        streams.settle_blackboard()
        assert published == [("Quick", ["42"]), ("Empty", []), ("Also Empty", [])]
    finally:
        streams.close()
