"""Hot reload latency: from a behavior file saved to the new class active in the registry.

Measures, on one machine in one run:

* save → new class active, through the watcher (native file-system events, and polling), including
  the debounce that merges an editor's burst of events into one reload;
* the reload itself (fresh import + registration + validation + swap), without the watcher;
* the peer: what a restart costs instead — a new Python process that loads the same plugins.

Run: ``python benchmarks/hot_reload.py [--rounds N]``. Target: save → active under 500 ms.
"""

from __future__ import annotations

import argparse
import queue
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

SOURCE = """
from kinema.behaviors import NodeStatus, SyncBehavior, output_port


class Answer(SyncBehavior):
    @classmethod
    def provided_ports(cls):
        return [output_port("out", int, "{{out}}")]

    def tick(self):
        self.set_output("out", {value})
        return NodeStatus.SUCCESS
"""


def _write_package(workspace: Path) -> Path:
    folder = workspace / "src" / "bench_pkg"
    (folder / "bench_pkg").mkdir(parents=True)
    (folder / "pyproject.toml").write_text(
        '[project]\nname = "bench_pkg"\nversion = "0.1.0"\n'
        '[project.entry-points."kinema.behaviors"]\n"bench_pkg::BenchPkgBehaviorsLoader" = "bench_pkg"\n'
    )
    (folder / "bench_pkg" / "__init__.py").write_text(
        "from kinema.plugins import hookimpl\nfrom .answer import Answer\n\n\n"
        "@hookimpl\ndef register_behaviors(register):\n    register(Answer)\n"
    )
    module = folder / "bench_pkg" / "answer.py"
    module.write_text(textwrap.dedent(SOURCE.format(value=0)))
    return module


def _active_value(host: object) -> int:
    registry = host.registry  # type: ignore[attr-defined]
    tree = registry.create_factory().create_tree_from_text(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Answer out="{out}"/></BehaviorTree></root>'
    )
    tree.tick_once()
    return int(tree.root_blackboard.get("out"))


def _percentiles(samples: list[float]) -> str:
    ordered = sorted(samples)
    p95 = ordered[min(len(ordered) - 1, round(0.95 * (len(ordered) - 1)))]
    return (
        f"p50 {statistics.median(ordered) * 1000:7.1f} ms   p95 {p95 * 1000:7.1f} ms   "
        f"max {ordered[-1] * 1000:7.1f} ms"
    )


def measure_watched(workspace: Path, module: Path, rounds: int, polling: bool, start: int) -> list[float]:
    from kinema.plugins import BehaviorHost, ReloadKind

    host = BehaviorHost(["bench_pkg::BenchPkgBehaviorsLoader"], workspace)
    assert host.load().ok
    events: queue.Queue = queue.Queue()
    host.subscribe(events.put)
    host.watch(polling=polling)
    samples = []
    try:
        for value in range(start, start + rounds):
            time.sleep(0.15)  # a person does not save twice within the debounce window
            saved = time.perf_counter()
            module.write_text(textwrap.dedent(SOURCE.format(value=value)))
            while True:
                event = events.get(timeout=10)
                if event.kind is ReloadKind.BEHAVIORS_RELOADED:
                    break
            active = time.perf_counter()
            assert _active_value(host) == value, "the new class is not the active one"
            samples.append(active - saved)
    finally:
        host.stop_watching()
    return samples


def measure_direct(workspace: Path, module: Path, rounds: int, start: int) -> list[float]:
    from kinema.plugins import BehaviorHost

    host = BehaviorHost(["bench_pkg::BenchPkgBehaviorsLoader"], workspace)
    assert host.load().ok
    samples = []
    for value in range(start, start + rounds):
        module.write_text(textwrap.dedent(SOURCE.format(value=value)))
        began = time.perf_counter()
        (event,) = host.reload_package(module.parent.parent)
        samples.append(time.perf_counter() - began)
        assert event.ok and _active_value(host) == value
    return samples


def measure_restart(workspace: Path, rounds: int) -> list[float]:
    code = (
        "from kinema.plugins import BehaviorHost\n"
        f"host = BehaviorHost(['bench_pkg::BenchPkgBehaviorsLoader'], {str(workspace)!r})\n"
        "assert host.load().ok and 'Answer' in host.registry\n"
    )
    samples = []
    for _ in range(rounds):
        began = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True)
        samples.append(time.perf_counter() - began)
    return samples


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=20, help="saves per measurement (default 20)")
    parser.add_argument("--smoke", action="store_true", help="two saves of each kind (the test suite)")
    args = parser.parse_args()
    if args.smoke:
        args.rounds = 2
    with tempfile.TemporaryDirectory(prefix="kinema-bench-") as scratch:
        workspace = Path(scratch)
        module = _write_package(workspace)
        native = measure_watched(workspace, module, args.rounds, polling=False, start=1)
        polling = measure_watched(workspace, module, args.rounds, polling=True, start=1000)
        direct = measure_direct(workspace, module, args.rounds, start=2000)
        restart = measure_restart(workspace, max(3, args.rounds // 4))
    print(f"hot reload, {args.rounds} saves each (target: save -> active < 500 ms)")
    print(f"  save -> active, native events  {_percentiles(native)}")
    print(f"  save -> active, polling        {_percentiles(polling)}")
    print(f"  reload only (import+validate)  {_percentiles(direct)}")
    print(f"  peer: restart a process        {_percentiles(restart)}")
    ratio = statistics.median(restart) / statistics.median(native)
    print(f"  restart / hot reload (p50)     {ratio:7.1f}x")
    verdict = "meets" if statistics.median(native) < 0.5 else "MISSES"
    print(f"  native p50 {verdict} the 500 ms target")


if __name__ == "__main__":
    main()
