"""Services between sessions and inside one session: replies, errors, timeouts, concurrency."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import pytest

from kinema.errors import TransportError
from kinema.transport import Node, Responder, Session, msg

ADD = "example_interfaces/srv/AddTwoInts"


def _adder(node: Node, name: str = "/add_two_ints") -> None:
    node.create_service(ADD, name, lambda request: {"sum": request.a + request.b})


def test_call_across_sessions_returns_the_servers_answer(connect: Callable[[], Session]) -> None:
    _adder(Node(connect(), "server"))
    client = Node(connect(), "caller").create_client(ADD, "/add_two_ints")
    response = client.call(msg("example_interfaces/srv/AddTwoInts_Request", a=5, b=37), timeout=5)
    assert response.sum == 42
    assert client.call({"a": -3, "b": 1}, timeout=5).sum == -2


def test_server_and_client_in_the_same_session(connect: Callable[[], Session]) -> None:
    node = Node(connect(), "both")
    _adder(node)
    assert node.create_client(ADD, "add_two_ints").call({"a": 1, "b": 2}, timeout=5).sum == 3


def test_a_client_made_from_a_typed_interface_returns_its_response_class(
    connect: Callable[[], Session],
) -> None:
    from kinema.interfaces.typed import AddTwoInts

    _adder(Node(connect(), "server"))
    client = Node(connect(), "caller").create_client(AddTwoInts, "/add_two_ints")
    response = client.call(AddTwoInts.Request(a=40, b=2), timeout=5)
    assert isinstance(response, AddTwoInts.Response) and response.sum == 42
    with pytest.raises(TransportError, match="ServiceDefinition class"):
        Node(connect(), "wrong").create_client(AddTwoInts.Request, "/add_two_ints")  # type: ignore[call-overload]


def test_router_session_serves_and_calls_like_a_peer(router: Session, connect: Callable[[], Session]) -> None:
    _adder(Node(router, "in_router"))
    assert Node(connect(), "caller").create_client(ADD, "/add_two_ints").call({"a": 2, "b": 2}).sum == 4


def test_handler_exception_becomes_an_error_with_its_message(connect: Callable[[], Session]) -> None:
    def broken(request: object) -> object:
        raise ValueError("the adder is out of order")

    Node(connect(), "server").create_service(ADD, "/broken", broken)
    client = Node(connect(), "caller").create_client(ADD, "/broken")
    with pytest.raises(TransportError, match="ValueError: the adder is out of order"):
        client.call({"a": 1, "b": 1}, timeout=5)


def test_handler_returning_a_wrong_response_is_reported(connect: Callable[[], Session]) -> None:
    Node(connect(), "server").create_service(ADD, "/wrong", lambda request: {"total": 3})
    client = Node(connect(), "caller").create_client(ADD, "/wrong")
    with pytest.raises(TransportError, match="has no field 'total'"):
        client.call({}, timeout=5)


def test_no_server_fails_after_the_timeout(connect: Callable[[], Session]) -> None:
    client = Node(connect(), "caller").create_client(ADD, "/nobody_home")
    started = time.monotonic()
    with pytest.raises(TransportError, match="no server for service /nobody_home"):
        client.call({"a": 1, "b": 2}, timeout=0.3)
    assert time.monotonic() - started < 3.0


def test_call_waits_for_a_server_that_starts_late(connect: Callable[[], Session]) -> None:
    client = Node(connect(), "caller").create_client(ADD, "/late")
    server_node = Node(connect(), "server")
    starter = threading.Timer(0.3, _adder, args=(server_node, "/late"))
    starter.start()
    try:
        assert client.call({"a": 20, "b": 22}, timeout=5).sum == 42
    finally:
        starter.join()


def test_wait_for_service_sees_the_server_on_the_graph(connect: Callable[[], Session]) -> None:
    client = Node(connect(), "caller").create_client(ADD, "/graph_add")
    assert not client.wait_for_service(0.1)
    _adder(Node(connect(), "server"), "/graph_add")
    assert client.wait_for_service(5)


def test_concurrent_server_handles_requests_in_parallel(connect: Callable[[], Session]) -> None:
    inside = threading.Barrier(2, timeout=5)

    def rendezvous(request: object) -> dict[str, int]:
        inside.wait()  # both requests must be in the handler at the same time
        return {"sum": 1}

    Node(connect(), "server").create_service(ADD, "/parallel", rendezvous, max_concurrent=2)
    client = Node(connect(), "caller").create_client(ADD, "/parallel")
    futures = [client.call_async({}, timeout=5) for _ in range(2)]
    assert [future.result(timeout=10).sum for future in futures] == [1, 1]


def test_deferred_server_answers_from_another_thread(connect: Callable[[], Session]) -> None:
    def later(request: object, responder: Responder) -> None:
        threading.Timer(0.1, responder.reply, args=({"sum": 7},)).start()

    Node(connect(), "server").create_service(ADD, "/deferred", later, deferred=True)
    assert Node(connect(), "caller").create_client(ADD, "/deferred").call({}, timeout=5).sum == 7


def test_closed_node_stops_serving(connect: Callable[[], Session]) -> None:
    server = Node(connect(), "server")
    _adder(server, "/closing")
    client = Node(connect(), "caller").create_client(ADD, "/closing")
    assert client.call({"a": 1, "b": 1}, timeout=5).sum == 2
    server.close()
    with pytest.raises(TransportError, match="no server"):
        client.call({"a": 1, "b": 1}, timeout=0.3)


def test_unknown_service_type_names_the_alternatives(connect: Callable[[], Session]) -> None:
    with pytest.raises(TransportError, match="did you mean 'example_interfaces/srv/AddTwoInts'"):
        Node(connect(), "n").create_client("example_interfaces/srv/AddTwoInt", "/x")


def test_a_server_with_another_definition_is_pointed_out(connect: Callable[[], Session]) -> None:
    # Same name, another type: what a ROS side built from different .srv text looks like.
    Node(connect(), "server").create_service(
        "controller_manager_msgs/srv/ListControllers", "/mismatched", lambda request: {}
    )
    client = Node(connect(), "caller").create_client(ADD, "/mismatched")
    with pytest.raises(TransportError, match="a server with another type or interface definition is there"):
        client.call({}, timeout=0.5)


def test_a_slow_server_is_reported_as_slow(connect: Callable[[], Session]) -> None:
    release = threading.Event()

    def slow(request: object) -> dict[str, int]:
        release.wait(5)
        return {"sum": 0}

    Node(connect(), "server").create_service(ADD, "/slow", slow)
    client = Node(connect(), "caller").create_client(ADD, "/slow")
    assert client.wait_for_service(5)
    try:
        with pytest.raises(TransportError, match=r"service /slow did not answer within 0\.3 s"):
            client.call({}, timeout=0.3)
    finally:
        release.set()
