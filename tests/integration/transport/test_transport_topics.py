"""Publish/subscribe: delivery, order, latched (transient local) topics, message info."""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable
from typing import Any

from kinema.transport import MessageInfo, Node, Session, msg

STRING = "std_msgs/msg/String"


def _collector() -> tuple[queue.Queue[Any], Callable[[Any], None]]:
    received: queue.Queue[Any] = queue.Queue()
    return received, received.put


def _drain(received: queue.Queue[Any], count: int, timeout: float = 5.0) -> list[Any]:
    return [received.get(timeout=timeout) for _ in range(count)]


def _wait_matched(node: Node, topic: str) -> None:
    assert node.session.graph_cache().wait_for(
        lambda g: bool(g.subscriptions(topic)) and bool(g.publishers(topic)), 5
    )


def test_messages_arrive_in_order_across_sessions(connect: Callable[[], Session]) -> None:
    received, callback = _collector()
    subscriber = Node(connect(), "listener")
    subscriber.create_subscription(STRING, "/chatter", lambda m: callback(m.data))
    talker = Node(connect(), "talker")
    publisher = talker.create_publisher(STRING, "chatter")
    _wait_matched(talker, "/chatter")
    for index in range(20):
        publisher.publish(msg(STRING, data=f"hello {index}"))
    assert _drain(received, 20) == [f"hello {index}" for index in range(20)]


def test_nested_message_round_trips(connect: Callable[[], Session]) -> None:
    received, callback = _collector()
    node = Node(connect(), "joints")
    node.create_subscription("sensor_msgs/msg/JointState", "/joint_states", callback)
    publisher = node.create_publisher("sensor_msgs/msg/JointState", "/joint_states")
    _wait_matched(node, "/joint_states")
    publisher.publish({"header": {"frame_id": "world"}, "name": ["a", "b"], "position": [0.5, -1.25]})
    (state,) = _drain(received, 1)
    assert state.header.frame_id == "world"
    assert state.name == ["a", "b"]
    assert state.position.tolist() == [0.5, -1.25]


def test_latched_topic_reaches_a_late_subscriber(connect: Callable[[], Session]) -> None:
    publisher = Node(connect(), "snapshot").create_publisher(STRING, "/blackboard", latched=True)
    publisher.publish({"data": "first"})
    publisher.publish({"data": "latest"})
    received, callback = _collector()
    Node(connect(), "late").create_subscription(
        STRING, "/blackboard", lambda m: callback(m.data), latched=True
    )
    assert _drain(received, 1) == ["latest"]
    publisher.publish({"data": "after"})
    assert _drain(received, 1) == ["after"]


def test_plain_subscriber_does_not_get_history(connect: Callable[[], Session]) -> None:
    talker = Node(connect(), "snapshot")
    publisher = talker.create_publisher(STRING, "/volatile")
    publisher.publish({"data": "old"})
    received, callback = _collector()
    node = Node(connect(), "late")
    node.create_subscription(STRING, "/volatile", lambda m: callback(m.data))
    _wait_matched(talker, "/volatile")  # the publisher's side must know the subscriber, not only the reverse
    publisher.publish({"data": "new"})
    assert _drain(received, 1) == ["new"]
    assert received.empty()


def test_message_info_carries_sequence_numbers_and_publisher_gid(connect: Callable[[], Session]) -> None:
    infos: list[MessageInfo] = []
    done = threading.Event()

    def on_message(message: Any, info: MessageInfo) -> None:
        infos.append(info)
        if len(infos) == 3:
            done.set()

    node = Node(connect(), "info")
    node.create_subscription(STRING, "/numbered", on_message, with_info=True)
    publisher = node.create_publisher(STRING, "/numbered")
    _wait_matched(node, "/numbered")
    for _ in range(3):
        publisher.publish({"data": "x"})
    assert done.wait(5)
    assert [info.sequence_number for info in infos] == [1, 2, 3]
    assert {info.publisher_gid for info in infos} == {publisher.gid}


def test_a_failing_callback_does_not_stop_the_subscription(connect: Callable[[], Session]) -> None:
    received, callback = _collector()

    def picky(message: Any) -> None:
        if message.data == "bad":
            raise RuntimeError("cannot handle this one")
        callback(message.data)

    node = Node(connect(), "picky")
    node.create_subscription(STRING, "/mixed", picky)
    publisher = node.create_publisher(STRING, "/mixed")
    _wait_matched(node, "/mixed")
    for text in ("good", "bad", "fine"):
        publisher.publish({"data": text})
    assert _drain(received, 2) == ["good", "fine"]
