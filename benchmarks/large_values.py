"""A large value on the blackboard: how fast a cancel is served, how steady the heartbeat stays.

The agent runs in this process (its objective server, blackboard stream, run recorder and heartbeat,
on a router of its own on a free loopback port). A looping objective first writes a value to the
blackboard, then sleeps in 20 ms steps until cancelled; while it runs, blackboard snapshots are taken,
streamed and recorded at 10 Hz. For each value size it times ``server.cancel()`` (until the run has its
result) and the longest gap between two heartbeats seen by a subscriber in the same process:

* ``small``: a 10-character string: the peer;
* ``1.9 MB``: the string that once spent 22 s in ``yaml.safe_dump`` on the tick thread.

Target: a cancel within one tick period + 100 ms; no heartbeat gap beyond 0.5 s (they come at 10 Hz).
Run: ``python benchmarks/large_values.py [--runs N] [--smoke]`` (``--smoke``: one short run of each, as
the test suite does).
"""

from __future__ import annotations

import argparse
import itertools
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from kinema.behaviors import NodeStatus, SyncBehavior, input_port, output_port
from kinema.behaviors.context import BehaviorContext
from kinema.runtime import names
from kinema.runtime.agent import Agent
from kinema.runtime.objective_server import FactoryTreeSource, ObjectiveRequest, ObjectiveServer
from kinema.runtime.objective_status import ObjectiveStatus
from kinema.runtime.recordings import RunRecorder
from kinema.testing.harness import registry_of
from kinema.transport import Node, free_endpoint, host_router

SIZES = {"small": 10, "1.9 MB": 1_900_000}


class PutValue(SyncBehavior):
    """Writes a string of ``size`` characters to ``value``."""

    @classmethod
    def provided_ports(cls) -> list[Any]:
        return [input_port("size", int, 10), output_port("value", str, "{value}")]

    def tick(self) -> NodeStatus:
        self.set_output("value", "x" * int(self.get_input("size")))
        return NodeStatus.SUCCESS


def _xml(size: int) -> str:
    return (
        '<root BTCPP_format="4"><BehaviorTree ID="Holds a value"><Sequence>'
        f'<PutValue size="{size}"/>'
        "<KeepRunningUntilFailure><Sleep msec='20'/></KeepRunningUntilFailure>"
        "</Sequence></BehaviorTree></root>"
    )


class Heartbeats:
    """Arrival times of the heartbeat, from a subscriber of its own."""

    def __init__(self, node: Node) -> None:
        self.times: list[float] = []
        self._lock = threading.Lock()
        node.create_subscription(names.HEARTBEAT_TYPE, names.HEARTBEAT, self._on_beat)

    def _on_beat(self, _message: Any) -> None:
        with self._lock:
            self.times.append(time.monotonic())

    def longest_gap(self, since: float, until: float) -> float:
        with self._lock:
            seen = [t for t in self.times if since <= t <= until]
        return max((b - a for a, b in itertools.pairwise(seen)), default=float("nan"))


def measure(server: ObjectiveServer, beats: Heartbeats, size: int, hold_s: float) -> tuple[float, float]:
    """(cancel latency, longest heartbeat gap) in ms for one run holding a value of ``size``."""
    run = server.submit(ObjectiveRequest(objective_xml=_xml(size)))
    deadline = time.monotonic() + 30
    while server.status[0] is not ObjectiveStatus.RUNNING:
        if time.monotonic() > deadline:
            raise RuntimeError(f"the objective never ran: {server.status}")
        time.sleep(0.001)
    started = time.monotonic()
    time.sleep(hold_s)  # snapshots are taken, streamed and recorded meanwhile
    begin = time.perf_counter()
    server.cancel()
    result = run.wait(60)
    cancel_ms = (time.perf_counter() - begin) * 1000
    assert result is not None and result.cancelled, result
    return cancel_ms, beats.longest_gap(started, time.monotonic()) * 1000


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=5, help="runs per value size")
    parser.add_argument("--smoke", action="store_true", help="one short run of each size (the test suite)")
    args = parser.parse_args()
    runs, hold_s = (1, 0.5) if args.smoke else (args.runs, 2.0)
    factory = registry_of([PutValue]).create_factory(BehaviorContext.offline())
    with tempfile.TemporaryDirectory() as folder, host_router(free_endpoint()) as session:
        recorder = RunRecorder(Path(folder))
        server = ObjectiveServer(FactoryTreeSource(factory), listeners=[recorder])
        agent = Agent(session, server)
        beats = Heartbeats(Node(session, "heartbeat_watch"))
        with agent:
            budget = (server.tick_period + 0.1) * 1000
            print(f"tick period {server.tick_period * 1000:.0f} ms; targets: cancel within {budget:.0f} ms,")
            print("heartbeat gaps under 500 ms\n")
            print(f"{'value':<8} {'cancel worst':>13} {'heartbeat gap worst':>20}  cancel vs peer")
            peer = None
            for name, size in SIZES.items():
                samples = [measure(server, beats, size, hold_s) for _ in range(runs)]
                cancel = max(s[0] for s in samples)
                gap = max(s[1] for s in samples)
                peer = peer or cancel
                print(f"{name:<8} {cancel:>10.1f} ms {gap:>17.1f} ms  {cancel / peer:.1f}x")
        recorder.close()


if __name__ == "__main__":
    main()
