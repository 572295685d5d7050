"""Nothing grows with use: the agent's threads, descriptors and memory over many start/cancel cycles.

Starts ``kinema run --headless`` (lab_sim: the agent and the MuJoCo driver) on a free loopback port with
private user folders, then runs cycles of: start "3 Waypoints Pick and Place" (a moving objective), let
it run a moment (0.2 to 0.8 s, varying), cancel it, wait for its result. Every ``--every`` cycles it
prints the agent process's threads, open descriptors and resident memory, each beside its value after the
first cycles (the peer: the same process before the soak), so a leak shows as a growing difference. At
the end it prints the RSS slope fitted over the second half of the samples (kB per cycle: what still
grows once allocator fragmentation has levelled off), and the agent's RSS after 20 runs beside the import
floor measured in the same run (a fresh ``python -c "import mujoco, pinocchio, zenoh"``).

Target: after 500 cycles threads and descriptors within a handful of the start, RSS flat; the agent
within 2x of the import floor. To see what grows, run with ``KINEMA_DEBUG_MEMORY=0`` (or ``=8`` for
tracemalloc with 8 frames) in the environment and send the agent ``SIGUSR2`` now and then: each signal
writes a memory report to its ``agent.log`` (:mod:`kinema.process.memory_probe`).
Run: ``python benchmarks/soak.py [--cycles 500] [--every 50] [--smoke]`` (``--smoke``: 6 cycles, as the
test suite does).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

from headless_cell import headless_lab_sim

from kinema.sdk import ObjectiveStatus, QuickClient

OBJECTIVE = "3 Waypoints Pick and Place"
# The runs after which the agent's RSS is compared with the import floor (fewer in a shorter soak).
FLOOR_RUNS = 20
FLOOR_SCRIPT = (
    "import mujoco, pinocchio, zenoh\n"
    "print(next(l.split()[1] for l in open('/proc/self/status') if l.startswith('VmRSS:')))"
)


def _agent_pid(supervisor: int) -> int:
    for child in Path(f"/proc/{supervisor}/task/{supervisor}/children").read_text().split():
        if "kinema.runtime.agent_process" in Path(f"/proc/{child}/cmdline").read_text():
            return int(child)
    raise RuntimeError("kinema run has no agent child")


def _sample(pid: int) -> tuple[int, int, int]:
    """(threads, open descriptors, RSS in kB) of process ``pid``."""
    fields = dict(
        line.split(":", 1) for line in Path(f"/proc/{pid}/status").read_text().splitlines() if ":" in line
    )
    threads = int(fields["Threads"])
    rss = int(fields["VmRSS"].split()[0])
    return threads, len(os.listdir(f"/proc/{pid}/fd")), rss


def _import_floor_kb() -> int:
    """RSS (kB) of a fresh Python that imported mujoco, pinocchio and zenoh: what any agent must hold."""
    done = subprocess.run([sys.executable, "-c", FLOOR_SCRIPT], capture_output=True, text=True, check=True)
    return int(done.stdout.strip())


def _slope_kb_per_cycle(samples: list[tuple[int, int]]) -> float:
    """Least-squares slope of RSS (kB) over cycles."""
    n = len(samples)
    mean_x = sum(x for x, _ in samples) / n
    mean_y = sum(y for _, y in samples) / n
    var = sum((x - mean_x) ** 2 for x, _ in samples)
    return sum((x - mean_x) * (y - mean_y) for x, y in samples) / var if var else 0.0


def _cycle(quick: QuickClient, hold_s: float) -> None:
    run = quick.start(OBJECTIVE)
    deadline = time.monotonic() + 60
    while quick.status() != (ObjectiveStatus.RUNNING, OBJECTIVE):
        if time.monotonic() > deadline:
            raise RuntimeError(f"{OBJECTIVE!r} never ran: {quick.status()}")
        time.sleep(0.01)
    time.sleep(hold_s)
    run.cancel()
    result = run.result()
    if result.succeeded:
        raise RuntimeError(f"a cancelled run succeeded: {result}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cycles", type=int, default=500)
    parser.add_argument("--every", type=int, default=50, help="print a sample every this many cycles")
    parser.add_argument("--smoke", action="store_true", help="6 cycles, a sample every 3 (the test suite)")
    args = parser.parse_args()
    cycles, every, warmup = (6, 3, 1) if args.smoke else (args.cycles, args.every, 5)
    with headless_lab_sim("kinema-soak-") as cell:
        agent = _agent_pid(cell.supervisor.pid)
        with QuickClient(cell.endpoint, timeout=30) as quick:
            for number in range(warmup):
                _cycle(quick, 0.2 + 0.1 * (number % 7))
            base = _sample(agent)
            print(
                f"agent pid {agent}; after {warmup} warm-up cycles: threads {base[0]}, fds {base[1]}, "
                f"RSS {base[2] / 1024:.1f} MB\n"
            )
            print(f"{'cycle':>6} {'threads':>8} {'(+)':>5} {'fds':>6} {'(+)':>5} {'RSS MB':>8} {'ratio':>6}")
            started = time.monotonic()
            samples: list[tuple[int, int]] = []
            floor_runs = min(FLOOR_RUNS, warmup + cycles)
            at_floor_runs = base[2]
            for number in range(1, cycles + 1):
                _cycle(quick, 0.2 + 0.1 * (number % 7))
                if warmup + number == floor_runs:
                    at_floor_runs = _sample(agent)[2]
                if number % every == 0 or number == cycles:
                    threads, fds, rss = _sample(agent)
                    samples.append((number, rss))
                    print(
                        f"{number:>6} {threads:>8} {threads - base[0]:>+5} {fds:>6} {fds - base[1]:>+5} "
                        f"{rss / 1024:>8.1f} {rss / base[2]:>6.2f}",
                        flush=True,
                    )
            print(f"\n{cycles} cycles in {time.monotonic() - started:.0f} s")
            later = samples[len(samples) // 2 :]
            if len(later) >= 2:
                print(
                    f"RSS slope over cycles {later[0][0]}-{later[-1][0]}: "
                    f"{_slope_kb_per_cycle(later):+.2f} kB/cycle"
                )
            floor = _import_floor_kb()
            print(
                f"agent RSS after {floor_runs} runs {at_floor_runs / 1024:.1f} MB; import floor "
                f"(mujoco, pinocchio, zenoh) {floor / 1024:.1f} MB; ratio agent / floor "
                f"{at_floor_runs / floor:.2f}x"
            )


if __name__ == "__main__":
    main()
