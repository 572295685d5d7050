"""Sessions: two routers linked together, joining or hosting, environment, prompt exit."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from collections.abc import Callable
from pathlib import Path

import pytest

from kinema.errors import TransportError
from kinema.transport import (
    Node,
    host_or_join,
    host_router,
    open_session,
    resolve_domain_id,
    resolve_endpoints,
)


def test_service_call_across_two_linked_routers(endpoints: Callable[[], str]) -> None:
    first_endpoint, second_endpoint = endpoints(), endpoints()
    with (
        host_router(first_endpoint) as first,
        host_router(second_endpoint, connect=[first_endpoint]) as second,
    ):
        with open_session(first_endpoint) as server_session, open_session(second_endpoint) as client_session:
            Node(server_session, "far_server").create_service(
                "example_interfaces/srv/AddTwoInts", "/add_two_ints", lambda r: {"sum": r.a + r.b}
            )
            client = Node(client_session, "near_client").create_client(
                "example_interfaces/srv/AddTwoInts", "/add_two_ints"
            )
            assert client.call({"a": 40, "b": 2}, timeout=10).sum == 42
        assert first.connected_routers() or first.connected_peers()
        assert second.connected_routers() or second.connected_peers()


def test_host_or_join_joins_an_existing_router(endpoints: Callable[[], str]) -> None:
    endpoint = endpoints()
    with host_or_join(endpoint) as hosting:
        assert hosting.is_router
        with host_or_join(endpoint) as joining:
            assert not joining.is_router
            assert hosting.zid in joining.connected_routers()


def test_open_session_fails_fast_without_a_router(endpoints: Callable[[], str]) -> None:
    with pytest.raises(TransportError, match=r"no Kinema router answers at tcp/127\.0\.0\.1"):
        open_session(endpoints(), connect_timeout=0.2)


def test_a_tls_link_that_gets_nowhere_says_what_may_be_wrong_with_its_certificates(
    endpoints: Callable[[], str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Every TLS failure said only "start one with `kinema run`", with a router running there.
    port = endpoints().rsplit(":", 1)[1]
    with pytest.raises(
        TransportError, match=r"it refused this machine's certificate: check that KINEMA_ZENOH"
    ):
        open_session(f"tls/127.0.0.1:{port}", connect_timeout=0.2)
    config = tmp_path / "laptop.json5"
    config.write_text(
        '{ mode: "client", connect: { endpoints: ["tls/127.0.0.1:' + port + '"] }, transport: { link: { tls: '
        '{ root_ca_certificate: "/nowhere/ca.pem", connect_certificate: "/nowhere/laptop.pem", '
        'connect_private_key: "/nowhere/laptop.key", enable_mtls: true } } } }'
    )
    monkeypatch.setenv("KINEMA_ZENOH_CONFIG", str(config))
    monkeypatch.delenv("KINEMA_ZENOH_CONNECT", raising=False)
    with pytest.raises(TransportError) as error:
        open_session(connect_timeout=0.2)
    assert "the TLS files of KINEMA_ZENOH_CONFIG are not there: /nowhere/ca.pem, /nowhere/laptop.pem" in str(
        error.value
    )
    # zenoh's own words keep out the place in its Rust sources.
    monkeypatch.setenv("KINEMA_ZENOH_CONFIG", str(tmp_path / "absent.json5"))
    with pytest.raises(TransportError) as error:
        open_session(connect_timeout=0.2)
    assert ".rs:" not in str(error.value) and "absent.json5: cannot load zenoh config" in str(error.value)


def test_with_a_client_config_the_default_endpoint_is_the_config_s(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # kinema ui showed "connected tcp/127.0.0.1:7447" while its session went to the config's TLS endpoint.
    from kinema.transport.session import default_endpoints
    from kinema.tui.sdk_connection import SdkConnection

    config = tmp_path / "laptop.json5"
    config.write_text('{ mode: "client", connect: { endpoints: ["tls/192.0.2.7:7448"] } }')
    monkeypatch.setenv("KINEMA_ZENOH_CONFIG", str(config))
    monkeypatch.delenv("KINEMA_ZENOH_CONNECT", raising=False)
    assert default_endpoints() == ["tls/192.0.2.7:7448"]
    assert SdkConnection().endpoint == "tls/192.0.2.7:7448"
    monkeypatch.setenv("KINEMA_ZENOH_CONNECT", "tcp/127.0.0.1:9000")
    assert default_endpoints() == ["tcp/127.0.0.1:9000"]


def test_environment_selects_endpoint_and_domain(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("KINEMA_ZENOH_CONNECT", "tcp/10.0.0.5:7447, tcp/10.0.0.6:7447")
    monkeypatch.setenv("ROS_DOMAIN_ID", "7")
    assert resolve_endpoints(None) == ["tcp/10.0.0.5:7447", "tcp/10.0.0.6:7447"]
    assert resolve_endpoints("tcp/127.0.0.1:9000") == ["tcp/127.0.0.1:9000"]
    assert resolve_domain_id(None) == 7
    assert resolve_domain_id(3) == 3
    monkeypatch.setenv("ROS_DOMAIN_ID", "seven")
    with pytest.raises(TransportError, match="ROS_DOMAIN_ID"):
        resolve_domain_id(None)


def test_domains_do_not_see_each_other(router_endpoint: str, router: object) -> None:
    with (
        open_session(router_endpoint, domain_id=3) as three,
        open_session(router_endpoint, domain_id=4) as four,
    ):
        Node(three, "adder").create_service(
            "example_interfaces/srv/AddTwoInts", "/add_two_ints", lambda r: {"sum": r.a + r.b}
        )
        with pytest.raises(TransportError, match="no server"):
            Node(four, "caller").create_client("example_interfaces/srv/AddTwoInts", "/add_two_ints").call(
                timeout=0.3
            )


_FORGETFUL = textwrap.dedent(
    """
    import sys
    from kinema.transport import Node, host_router
    session = host_router(sys.argv[1])
    node = Node(session, "forgetful")
    node.create_subscription("std_msgs/msg/String", "/chatter", print)
    node.create_service("example_interfaces/srv/AddTwoInts", "/add", lambda r: {"sum": 1})
    node.create_action_server("example_interfaces/action/Fibonacci", "/fib", lambda h: {})
    print(node.create_client("example_interfaces/srv/AddTwoInts", "/add").call(timeout=5).sum)
    # no session.close(): the interpreter must still exit
    """
)


def test_process_exits_without_closing_its_session(endpoints: Callable[[], str]) -> None:
    done = subprocess.run(
        [sys.executable, "-c", _FORGETFUL, endpoints()], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "1"


def test_standalone_session_serves_in_process() -> None:
    with open_session([]) as session:
        node = Node(session, "solo")
        node.create_service("example_interfaces/srv/AddTwoInts", "/add", lambda r: {"sum": r.a + r.b})
        node.create_action_server(
            "example_interfaces/action/Fibonacci", "/fib", lambda h: {"sequence": [1, 1]}
        )
        assert node.create_client("example_interfaces/srv/AddTwoInts", "/add").call({"a": 1, "b": 2}).sum == 3
        handle = node.create_action_client("example_interfaces/action/Fibonacci", "/fib").send_goal(
            {"order": 2}
        )
        assert handle.result(timeout=5).result.sequence.tolist() == [1, 1]
    assert session.closed


_STUCK_HANDLER = textwrap.dedent(
    """
    import sys, threading
    from kinema.transport import Node, open_session
    session = open_session([])
    node = Node(session, "stuck")
    entered = threading.Event()
    def forever(request):
        entered.set()
        threading.Event().wait()  # a handler that never returns (an Objective that never ends)
    node.create_service("example_interfaces/srv/AddTwoInts", "/stuck", forever, max_concurrent=2)
    future = node.create_client("example_interfaces/srv/AddTwoInts", "/stuck").call_async({}, timeout=0.5)
    entered.wait(5)
    print("in handler", flush=True)
    """
)


def test_process_exits_while_a_concurrent_handler_is_stuck() -> None:
    done = subprocess.run([sys.executable, "-c", _STUCK_HANDLER], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "in handler"


def test_free_endpoint_never_hands_out_a_port_twice(monkeypatch: pytest.MonkeyPatch) -> None:
    """The OS may offer a just-probed port again before its taker listens: the next caller must not get it."""
    import socket

    from kinema.transport import session

    offered = iter([40001, 40001, 40002, 40001, 40003])

    class Probe:
        def __init__(self, *args: object) -> None:
            self.port = 0

        def __enter__(self) -> Probe:
            return self

        def __exit__(self, *exc: object) -> None:
            return None

        def bind(self, address: tuple[str, int]) -> None:
            self.port = next(offered)

        def getsockname(self) -> tuple[str, int]:
            return ("127.0.0.1", self.port)

    monkeypatch.setattr(session, "_handed_out", set())
    monkeypatch.setattr(socket, "socket", Probe)
    got = [session.free_endpoint() for _ in range(3)]
    assert got == ["tcp/127.0.0.1:40001", "tcp/127.0.0.1:40002", "tcp/127.0.0.1:40003"]
