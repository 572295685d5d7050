"""SDK helpers that need no runtime: override encoding, XML names, message conversions, streams."""

from __future__ import annotations

import threading
from types import SimpleNamespace
from typing import Any

import pytest

from kinema.errors import TransportError
from kinema.runtime.objective_status import ObjectiveStatus
from kinema.sdk import BlackboardSnapshot, LogEntry, MessageStream, ParameterOverride, ServerStatus
from kinema.sdk.client import _xml_name, parameter_messages
from kinema.sdk.quick import QuickClient


@pytest.mark.parametrize(
    ("value", "type_code", "field", "sent"),
    [
        ("Look at Table", 0, "string_value", "Look at Table"),
        (True, 4, "bool_value", True),
        (3, 3, "int_value", 3),
        (2.5, 2, "double_value", 2.5),
        ([1, 2], 0, "string_value", "[1, 2]"),
        ({"x": 1.0}, 0, "string_value", "{x: 1.0}"),
    ],
)
def test_override_values_are_typed_or_sent_as_yaml(value: Any, type_code: int, field: str, sent: Any) -> None:
    (message,) = parameter_messages({"p": value})
    assert message["description"] == {"name": "p", "type": type_code}
    assert message[field] == sent
    assert message["behavior_namespaces"] == []


def test_override_objects_keep_their_namespaces() -> None:
    (message,) = parameter_messages([ParameterOverride("waypoint_name", "Home", ("move_to_waypoint",))])
    assert message["behavior_namespaces"] == ["move_to_waypoint"]


@pytest.mark.parametrize(
    ("xml", "name"),
    [
        ('<root main_tree_to_execute="Pick"><BehaviorTree ID="A"/><BehaviorTree ID="B"/></root>', "Pick"),
        ("<root><BehaviorTree ID='Only'/></root>", "Only"),
        ("<root><BehaviorTree ID='A'/><BehaviorTree ID='B'/></root>", "<objective XML>"),
        ("garbage", "<objective XML>"),
    ],
)
def test_xml_objectives_are_named_like_the_agent_names_them(xml: str, name: str) -> None:
    assert _xml_name(xml) == name


def _stamp(seconds: int) -> SimpleNamespace:
    return SimpleNamespace(sec=seconds, nanosec=500_000_000)


def test_messages_become_typed_values() -> None:
    heartbeat = SimpleNamespace(
        objective_status="Running",
        objective_name="Pick",
        process_timestamp=_stamp(10),
        ros_timestamp=_stamp(2),
    )
    assert ServerStatus.from_message(heartbeat) == ServerStatus(ObjectiveStatus.RUNNING, "Pick", 10.5, 2.5)
    odd = SimpleNamespace(
        objective_status="Dancing", objective_name="", process_timestamp=_stamp(0), ros_timestamp=_stamp(0)
    )
    assert ServerStatus.from_message(odd).status is ObjectiveStatus.UNKNOWN
    entry = SimpleNamespace(scope="Pick", key="n", type_name="int", value_yaml="3")
    snapshot = BlackboardSnapshot.from_message(
        SimpleNamespace(objective_name="Pick", stamp=_stamp(1), entries=[entry])
    )
    assert snapshot.as_dict() == {"Pick": {"n": "3"}}
    assert LogEntry.from_message(SimpleNamespace(log_level=1, message="boom")) == LogEntry("error", "boom")


class FakeSubscription:
    def __init__(self) -> None:
        self.closed = False

    def close(self) -> None:
        self.closed = True


def test_a_stream_yields_until_closed_and_unsubscribes() -> None:
    subscription = FakeSubscription()
    pushed: list[Any] = []

    def subscribe(callback: Any) -> FakeSubscription:
        pushed.append(callback)
        return subscription

    stream: MessageStream[int] = MessageStream(subscribe, lambda message: message * 2)
    pushed[0](1)
    pushed[0](2)
    assert [next(stream), next(stream)] == [2, 4]
    threading.Timer(0.05, stream.close).start()
    assert list(stream) == []
    assert subscription.closed


def test_a_stream_ends_after_its_timeout_of_silence() -> None:
    stream: MessageStream[int] = MessageStream(lambda _cb: FakeSubscription(), lambda m: m, timeout=0.05)
    assert list(stream) == []


def test_a_slow_consumer_drops_the_oldest_messages() -> None:
    callbacks: list[Any] = []
    stream: MessageStream[int] = MessageStream(
        lambda cb: callbacks.append(cb) or FakeSubscription(), lambda m: m, maxsize=3
    )
    for value in range(10):
        callbacks[0](value)
    stream.close()
    assert list(stream) == [7, 8, 9]


def test_the_quick_client_says_when_no_router_answers() -> None:
    from kinema.transport import free_endpoint

    with pytest.raises(TransportError, match="no Kinema router answers at tcp/"):
        QuickClient(free_endpoint(), timeout=0.3)
