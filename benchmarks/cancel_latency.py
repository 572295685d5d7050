"""How long a cancel or a preempting request takes to end the running objective, whatever the tree does.

The objective server runs in this process (no transport: the figure is the server's own). For each kind
of running tree it times ``server.cancel()`` (until the run has its result) and a preemption (``submit``
of a one-node objective, until that one succeeded):

* ``sleep loop``: ``KeepRunningUntilFailure`` of a 20 ms ``Sleep`` (a well-behaved tree): the peer;
* ``endless Repeat``: ``<Repeat num_cycles="-1"><AlwaysSuccess/></Repeat>``, which re-ticks itself
  synchronously forever (before issue 15 it was never cancelled);
* ``stuck tick``: a behavior whose ``tick`` blocks (the tick thread is abandoned and replaced).

Target: every kind ends within one tick period + 100 ms (110 ms at 100 Hz).
Run: ``python benchmarks/cancel_latency.py [--runs N]``.
"""

from __future__ import annotations

import argparse
import threading
import time

from latency import MILLISECOND_NS, percentiles

from kinema.behaviors import NodeStatus, SyncBehavior
from kinema.behaviors.context import BehaviorContext
from kinema.runtime.objective_server import FactoryTreeSource, ObjectiveRequest, ObjectiveServer
from kinema.runtime.objective_status import ObjectiveStatus
from kinema.testing.harness import registry_of

RELEASE = threading.Event()


class BlockingTick(SyncBehavior):
    """A tick that blocks until the benchmark ends."""

    def tick(self) -> NodeStatus:
        RELEASE.wait(600)
        return NodeStatus.SUCCESS


TREES = {
    "sleep loop": "<KeepRunningUntilFailure><Sleep msec='20'/></KeepRunningUntilFailure>",
    "endless Repeat": "<Repeat num_cycles='-1'><AlwaysSuccess/></Repeat>",
    "stuck tick": "<BlockingTick/>",
}
QUICK = '<root BTCPP_format="4"><BehaviorTree ID="Quick"><AlwaysSuccess/></BehaviorTree></root>'


def _xml(body: str) -> str:
    return f'<root BTCPP_format="4"><BehaviorTree ID="T">{body}</BehaviorTree></root>'


def _wait_running(server: ObjectiveServer) -> None:
    deadline = time.monotonic() + 10
    while server.status[0] is not ObjectiveStatus.RUNNING:
        if time.monotonic() > deadline:
            raise RuntimeError(f"the objective never ran: {server.status}")
        time.sleep(0.001)
    time.sleep(0.03)  # well inside the run


def measure(server: ObjectiveServer, body: str, runs: int) -> tuple[list[int], list[int]]:
    cancels, preemptions = [], []
    for _ in range(runs):
        run = server.submit(ObjectiveRequest(objective_xml=_xml(body)))
        _wait_running(server)
        start = time.perf_counter_ns()
        server.cancel()
        result = run.wait(10)
        cancels.append(time.perf_counter_ns() - start)
        assert result is not None and result.cancelled, result
        run = server.submit(ObjectiveRequest(objective_xml=_xml(body)))
        _wait_running(server)
        start = time.perf_counter_ns()
        quick = server.submit(ObjectiveRequest(objective_xml=QUICK)).wait(10)
        preemptions.append(time.perf_counter_ns() - start)
        assert quick is not None and quick.succeeded, quick
        assert run.wait(10) is not None
    return cancels, preemptions


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=20, help="cancels and preemptions per kind of tree")
    parser.add_argument("--smoke", action="store_true", help="two runs of each kind (the test suite)")
    args = parser.parse_args()
    if args.smoke:
        args.runs = 2
    factory = registry_of([BlockingTick]).create_factory(BehaviorContext.offline())
    with ObjectiveServer(FactoryTreeSource(factory)) as server:
        budget = (server.tick_period + 0.1) * 1000
        print(f"tick period {server.tick_period * 1000:.0f} ms; target: within {budget:.0f} ms\n")
        print(f"{'running tree':<16} {'cancel p50':>11} {'p99':>8} {'preempt p50':>12} {'p99':>8}  vs peer")
        peer = None
        for name, body in TREES.items():
            cancels, preemptions = measure(server, body, args.runs)
            c50, c99 = percentiles(cancels, MILLISECOND_NS)
            p50, p99 = percentiles(preemptions, MILLISECOND_NS)
            peer = peer or (c50, p50)
            ratio = f"{c50 / peer[0]:.1f}x / {p50 / peer[1]:.1f}x"
            print(f"{name:<16} {c50:>8.1f} ms {c99:>5.1f} ms {p50:>9.1f} ms {p99:>5.1f} ms  {ratio}")
        print(f"\nabandoned tick threads: {server.health().replacements}")
    RELEASE.set()


if __name__ == "__main__":
    main()
