"""Over the transport: cancel and preemption win against a tree that re-ticks itself and against behavior
code that never returns; the watchdog's report reaches the health topic beside the heartbeat and the log."""

from __future__ import annotations

import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from kinema.behaviors import NodeStatus, SyncBehavior
from kinema.behaviors.context import BehaviorContext
from kinema.runtime import names
from kinema.runtime.agent import Agent
from kinema.runtime.objective_server import FactoryTreeSource, ObjectiveServer
from kinema.sdk import ObjectiveClient, ObjectiveStatus
from kinema.testing.harness import registry_of

SPIN = """<root BTCPP_format="4" main_tree_to_execute="Spin">
  <BehaviorTree ID="Spin"><Repeat num_cycles="-1"><AlwaysSuccess/></Repeat></BehaviorTree>
</root>"""
STUCK = """<root BTCPP_format="4" main_tree_to_execute="Stuck">
  <BehaviorTree ID="Stuck">
    <Sequence name="main"><BlockingTick name="reads a socket"/></Sequence>
  </BehaviorTree>
</root>"""
QUICK = """<root BTCPP_format="4" main_tree_to_execute="Quick">
  <BehaviorTree ID="Quick"><AlwaysSuccess/></BehaviorTree>
</root>"""
# A served cancel takes a tick period + 100 ms (benchmarks/cancel_latency.py); before the fix it never came.
LATE = 3.0
RELEASE = threading.Event()


class BlockingTick(SyncBehavior):
    """A tick that waits on something that never comes (until the test ends)."""

    def tick(self) -> NodeStatus:
        RELEASE.wait(60)
        return NodeStatus.SUCCESS


def _wait(condition: Callable[[], bool], what: str, timeout: float = 15.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.01)


def _running(client: ObjectiveClient, name: str) -> Callable[[], bool]:
    def check() -> bool:
        status = client.status()
        return status.status is ObjectiveStatus.RUNNING and status.objective_name == name

    return check


def test_an_endless_repeat_sent_to_do_objective_is_cancelled(client: ObjectiveClient) -> None:
    handle = client.start(xml=SPIN)
    _wait(_running(client, "Spin"), "the Repeat to run")
    started = time.monotonic()
    assert handle.cancel(), "the agent refused the cancel"
    result = handle.result(10)
    assert result.cancelled, result
    assert time.monotonic() - started < LATE
    # /cancel_objective works as well, and a new objective preempts the loop.
    handle = client.start(xml=SPIN)
    _wait(_running(client, "Spin"), "the Repeat to run again")
    assert client.cancel()
    assert handle.result(10).cancelled
    looping = client.start(xml=SPIN)
    _wait(_running(client, "Spin"), "the Repeat to run a third time")
    assert client.execute("Quick", timeout=10).succeeded
    assert looping.result(10).cancelled


@pytest.fixture
def stuck_runtime() -> Iterator[tuple[ObjectiveClient, ObjectiveServer, list[str], list[str], str]]:
    """An agent in this process whose library knows BlockingTick, on a private network."""
    from kinema.transport import Node, free_endpoint, host_router, open_session

    RELEASE.clear()
    endpoint = free_endpoint()
    router = host_router(endpoint)
    session = open_session(endpoint)
    factory = registry_of([BlockingTick]).create_factory(BehaviorContext.offline())
    server = ObjectiveServer(FactoryTreeSource(factory), watchdog_report_s=0.3)
    agent = Agent(session, server)
    agent.start()
    client = ObjectiveClient(session=session, timeout=10)
    warnings: list[str] = []
    logs: list[str] = []
    listener = Node(session, "watchdog_listener")

    def on_health(message: Any) -> None:
        warnings.extend(str(w) for w in message.warnings)

    listener.create_subscription(names.HEALTH_TYPE, names.HEALTH, on_health, latched=True)
    listener.create_subscription(names.LOG_TYPE, names.LOG, lambda m: logs.append(str(m.message)))
    try:
        client.wait_for_runtime()
        yield client, server, warnings, logs, endpoint
    finally:
        RELEASE.set()
        client.close()
        listener.close()
        agent.close()
        session.close()
        router.close()


def test_a_stuck_behavior_is_reported_and_cancel_still_ends_the_objective(stuck_runtime: Any) -> None:
    client, server, warnings, logs, endpoint = stuck_runtime
    handle = client.start(xml=STUCK)
    expected = "behavior 'BlockingTick' (reads a socket) has been in tick for"
    _wait(lambda: any(expected in w for w in warnings), f"the watchdog's report on {names.HEALTH}")
    _wait(lambda: any("watchdog: behavior 'BlockingTick'" in line for line in logs), "the report in the log")
    # `kinema objective status` says so too.
    shown = subprocess.run(
        [sys.executable, "-m", "kinema", "objective", "status", "--connect", endpoint],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert shown.returncode == 0, shown.stderr
    assert "Running: Stuck" in shown.stdout, shown.stdout
    assert f"warning: {expected}" in shown.stdout, shown.stdout
    # And the TUI's connection hands the warning to the status bar with the heartbeats.
    from kinema.tui.connection import Heartbeat
    from kinema.tui.sdk_connection import SdkConnection

    beats: list[Heartbeat] = []
    connection = SdkConnection(endpoint)
    connection.open(lambda event: beats.append(event) if isinstance(event, Heartbeat) else None)
    try:
        _wait(lambda: any(expected in w for b in beats for w in b.warnings), "a heartbeat with the warning")
    finally:
        connection.close()
    started = time.monotonic()
    assert handle.cancel(), "the agent refused the cancel"
    result = handle.result(10)
    assert time.monotonic() - started < LATE
    assert result.cancelled, result
    assert "behavior 'BlockingTick' (reads a socket)" in result.error_message, result.error_message
    # The next objective runs, on a fresh tick thread; the abandoned one stays reported.
    assert client.do_xml(QUICK, timeout=10).succeeded
    assert server.health().replacements == 1
    assert any(w.startswith("abandoned tick thread") for w in server.health().warnings)


def test_a_new_objective_preempts_a_stuck_behavior(stuck_runtime: Any) -> None:
    client, _server, _warnings, _logs, _endpoint = stuck_runtime
    handle = client.start(xml=STUCK)
    _wait(_running(client, "Stuck"), "the stuck objective to run")
    assert client.do_xml(QUICK, timeout=10).succeeded
    result = handle.result(10)
    assert result.cancelled and "newer objective" in result.error_message, result
