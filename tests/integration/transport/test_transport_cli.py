"""`kinema topic|service|action|node` against servers started by the test."""

from __future__ import annotations

import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator

import pytest

from kinema.cli.main import main
from kinema.transport import Node, ServerGoalHandle, Session


@pytest.fixture
def demo(connect: Callable[[], Session]) -> Iterator[Node]:
    """A node with an adder service, a talker topic and a Fibonacci action."""
    node = Node(connect(), "demo_server")
    node.create_service("example_interfaces/srv/AddTwoInts", "/add_two_ints", lambda r: {"sum": r.a + r.b})
    publisher = node.create_publisher("std_msgs/msg/String", "/chatter")

    def fibonacci(handle: ServerGoalHandle) -> dict[str, list[int]]:
        # Paced like a real server: feedback and result travel on different channels, so feedback sent
        # in the same instant as the result may reach the client after it (as with ROS 2).
        sequence = [0, 1][: handle.goal.order]
        while len(sequence) < handle.goal.order:
            sequence.append(sequence[-1] + sequence[-2])
            handle.publish_feedback({"sequence": sequence})
            time.sleep(0.05)
        return {"sequence": sequence}

    node.create_action_server("example_interfaces/action/Fibonacci", "/fibonacci", fibonacci)
    node.create_action_server(
        "example_interfaces/action/Fibonacci",
        "/refusing",
        lambda handle: None,
        goal_callback=lambda goal: False,
    )
    stop = threading.Event()

    def talk() -> None:
        count = 0
        while not stop.wait(0.02):
            publisher.publish({"data": f"hello {count}"})
            count += 1

    talker = threading.Thread(target=talk, daemon=True)
    talker.start()
    yield node
    stop.set()
    talker.join()


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_list_verbs_show_names_and_types(
    demo: Node, router_endpoint: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert demo.session.graph_cache().wait_for(lambda g: "/refusing" in g.actions(), 5)
    code, out, _ = _run(capsys, "node", "list", "--connect", router_endpoint)
    assert code == 0 and "/demo_server" in out.splitlines()
    assert not any("_kinema_cli_" in line for line in out.splitlines())
    code, out, _ = _run(capsys, "topic", "list", "-t", "--connect", router_endpoint)
    assert "/chatter [std_msgs/msg/String]" in out.splitlines()
    code, out, _ = _run(capsys, "service", "list", "-t", "--connect", router_endpoint)
    assert "/add_two_ints [example_interfaces/srv/AddTwoInts]" in out.splitlines()
    assert not any("_action" in line for line in out.splitlines())
    code, out, _ = _run(capsys, "service", "list", "-v", "--connect", router_endpoint)
    assert code == 0
    assert (
        "/add_two_ints  server  /demo_server  example_interfaces/srv/AddTwoInts  "
        "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
    ) in out.splitlines()
    code, out, _ = _run(capsys, "action", "list", "-t", "--connect", router_endpoint)
    assert out.splitlines() == [
        "/fibonacci [example_interfaces/action/Fibonacci]",
        "/refusing [example_interfaces/action/Fibonacci]",
    ]


def test_service_call_with_yaml_flow(
    demo: Node, router_endpoint: str, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, _ = _run(
        capsys,
        "service",
        "call",
        "/add_two_ints",
        "example_interfaces/srv/AddTwoInts",
        "{a: 2, b: 40}",
        "--connect",
        router_endpoint,
    )
    assert code == 0
    assert out.splitlines()[-1] == "sum: 42"
    code, out, _ = _run(
        capsys, "service", "call", "/add_two_ints", "{a: 1, b: 1}", "--flow", "-e", router_endpoint
    )
    assert code == 0 and out.splitlines()[-1] == "{sum: 2}"


def test_topic_echo_and_pub(demo: Node, router_endpoint: str, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(capsys, "topic", "echo", "/chatter", "-n", "2", "--connect", router_endpoint)
    assert code == 0
    documents = [doc for doc in out.split("---") if doc.strip()]
    assert len(documents) == 2 and all(doc.strip().startswith("data: hello ") for doc in documents)

    received: list[str] = []
    demo.create_subscription("std_msgs/msg/String", "/from_cli", lambda m: received.append(m.data))
    code, out, _ = _run(
        capsys,
        "topic",
        "pub",
        "/from_cli",
        "std_msgs/msg/String",
        "{data: typed}",
        "--once",
        "-w",
        "1",  # wait for the subscription to match: one message published before would be lost
        "--timeout",
        "30",
        "-e",
        router_endpoint,
    )
    assert code == 0
    deadline = time.monotonic() + 30
    while not received and time.monotonic() < deadline:
        time.sleep(0.01)
    assert received == ["typed"]


def test_topic_hz_reports_a_rate(
    demo: Node, router_endpoint: str, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, _ = _run(capsys, "topic", "hz", "/chatter", "--duration", "1.2", "-e", router_endpoint)
    assert code == 0
    rate = float(out.splitlines()[0].split(":")[1])
    assert rate > 0


def test_action_send_goal(demo: Node, router_endpoint: str, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(
        capsys,
        "action",
        "send_goal",
        "/fibonacci",
        "example_interfaces/action/Fibonacci",
        "{order: 5}",
        "--feedback",
        "-e",
        router_endpoint,
    )
    assert code == 0
    assert "Goal accepted with ID:" in out
    assert "Feedback:" in out
    assert out.rstrip().endswith("Goal finished with status: SUCCEEDED")
    code, _, err = _run(
        capsys,
        "action",
        "send_goal",
        "/refusing",
        "example_interfaces/action/Fibonacci",
        "{order: 1}",
        "-e",
        router_endpoint,
    )
    assert code == 1 and "goal rejected by /refusing" in err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["service", "call", "/absent", "example_interfaces/srv/AddTwoInts", "{a: 1}"],
            "no server for service /absent",
        ),
        (
            ["service", "call", "/add_two_ints", "example_interfaces/srv/AddTwoInts", "{z: 1}"],
            "has no field 'z'",
        ),
        (["topic", "echo", "/silence", "-n", "1"], "no topic /silence on the network"),
        (
            ["action", "send_goal", "/absent", "example_interfaces/action/Fibonacci", "{}"],
            "no action server /absent",
        ),
        (["service", "call", "/x", "example_interfaces/srv/Nope", "{}"], "unknown service type"),
    ],
)
def test_failures_are_one_line_and_non_zero(
    demo: Node, router_endpoint: str, capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    code, _, err = _run(capsys, *argv, "--timeout", "0.3", "--connect", router_endpoint)
    assert code == 1
    assert err.count("\n") == 1 and err.startswith("error: ") and message in err


def test_no_router_is_a_one_line_error(endpoints: Callable[[], str]) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "kinema", "node", "list", "--connect", endpoints(), "--timeout", "0.3"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 1
    assert done.stderr.startswith("error: no Kinema router answers at tcp/127.0.0.1:")
    assert done.stderr.count("\n") == 1
