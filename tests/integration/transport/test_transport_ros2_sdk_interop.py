"""Interop with an independent rmw_zenoh implementation: the ``zenoh-ros2-sdk`` package (ROBOTIS).

The SDK keeps one global zenoh session per process, so it runs in a subprocess against the test's
router, with the interface definitions given inline (it would otherwise clone them from GitHub).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import threading
from collections.abc import Callable

import pytest

from kinema.transport import Node, Session

pytest.importorskip("zenoh_ros2_sdk", reason="zenoh-ros2-sdk is not installed (pip install 'kinema[test]')")

_SDK_SIDE = textwrap.dedent(
    """
    import json, sys, threading
    from zenoh_ros2_sdk import ROS2ServiceClient, ROS2ServiceServer, ROS2Subscriber
    host, port = sys.argv[1].removeprefix("tcp/").rsplit(":", 1)
    where = dict(router_ip=host, router_port=int(port))
    out = {}
    got = threading.Event()
    def on_chatter(message):
        out["chatter"] = message.data
        got.set()
    ROS2Subscriber("/chatter", "std_msgs/msg/String", on_chatter, msg_definition="string data\\n", **where)
    ROS2ServiceServer("/sdk_add_two_ints", "example_interfaces/srv/AddTwoInts",
                      callback=lambda request: type("R", (), {"sum": request.a * 1000 + request.b})(),
                      request_definition="int64 a\\nint64 b\\n", response_definition="int64 sum\\n", **where)
    client = ROS2ServiceClient("/add_two_ints", "example_interfaces/srv/AddTwoInts",
                               request_definition="int64 a\\nint64 b\\n", response_definition="int64 sum\\n",
                               timeout=10, **where)
    out["hash"] = client.type_hash
    out["sum"] = client.call(a=5, b=37).sum
    print("ready", flush=True)
    out["chatter_received"] = got.wait(20)
    print(json.dumps(out), flush=True)
    sys.stdin.readline()
    """
)


def test_zenoh_ros2_sdk_calls_kinema_and_kinema_calls_it(
    connect: Callable[[], Session], router_endpoint: str
) -> None:
    node = Node(connect(), "objective_server")
    node.create_service("example_interfaces/srv/AddTwoInts", "/add_two_ints", lambda r: {"sum": r.a + r.b})
    publisher = node.create_publisher("std_msgs/msg/String", "/chatter")
    sdk = subprocess.Popen(
        [sys.executable, "-c", _SDK_SIDE, router_endpoint],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "HOME": "/nonexistent-kinema-test-home"},
    )
    stop = threading.Event()

    def keep_publishing() -> None:
        # The SDK subscriber may join after any single message; publish until it reports.
        while not stop.wait(0.1):
            publisher.publish({"data": "hello sdk"})

    talker = threading.Thread(target=keep_publishing, daemon=True)
    try:
        assert sdk.stdout is not None and sdk.stdin is not None
        assert sdk.stdout.readline().strip() == "ready"
        client = node.create_client("example_interfaces/srv/AddTwoInts", "/sdk_add_two_ints")
        assert client.call({"a": 4, "b": 2}, timeout=10).sum == 4002
        talker.start()
        result = json.loads(sdk.stdout.readline())
        assert result["sum"] == 42
        assert result["hash"] == "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
        assert result["chatter_received"] and result["chatter"] == "hello sdk"
        sdk.stdin.write("\n")
        sdk.stdin.flush()
    finally:
        stop.set()
        sdk.kill()
        sdk.wait(10)
