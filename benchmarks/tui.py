"""Speed of the terminal UI: time to first paint, and input latency while the blackboard streams.

1. **First paint.** ``kinema ui`` (the real app, attached to an endpoint where no runtime answers yet) and
   ``kinema ui --demo`` run in a pseudo-terminal; the clock stops when the screen's first frame (the
   navigation bar) arrives, and for the demo again when the objective list and tree are shown. The
   peer, measured in the same run the same way, is a bare Textual app showing one line, so the ratio says
   what Kinema adds on top of Textual's own start. Target: under 1.5 s.
2. **Input latency under load.** The app runs (headless, rendering included) on the Blackboard screen while
   a thread publishes 1,000 blackboard keys 10 times per second, every value changing each time. Every
   50 ms another thread posts a probe message into the app's queue, where key presses wait too; the
   latency is the time until the app handled it. The peer is a bare Textual app whose stock DataTable shows
   the same stream cell by cell (the usual way to keep a table live). Target: p99 under 100 ms. The numbers
   include garbage-collection pauses and whatever else the machine runs: note the load average printed.

Run: ``python benchmarks/tui.py [--runs N] [--seconds S]``.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import pty
import select
import statistics
import subprocess
import sys
import threading
import time

N_KEYS = 1000
RATE_HZ = 10.0
PROBE_PERIOD_S = 0.05
BARE_APP = (
    "from textual.app import App\n"
    "from textual.widgets import Static\n"
    "class Bare(App):\n"
    "    def compose(self):\n"
    "        yield Static('Objectives ready')\n"
    "Bare().run()\n"
)


# -- first paint ------------------------------------------------------------------------------------


def time_to_output(argv: list[str], markers: list[bytes], timeout: float = 30.0) -> list[float]:
    """Run ``argv`` in a pseudo-terminal; seconds until each marker first appeared in its output."""
    main_fd, child_fd = pty.openpty()
    os.set_blocking(main_fd, False)
    env = {**os.environ, "TERM": "xterm-256color", "COLUMNS": "120", "LINES": "34"}
    started = time.perf_counter()
    process = subprocess.Popen(
        argv, stdin=child_fd, stdout=child_fd, stderr=child_fd, env=env, close_fds=True
    )
    os.close(child_fd)
    seen = b""
    found: list[float] = []
    try:
        while len(found) < len(markers) and time.perf_counter() - started < timeout:
            ready, _, _ = select.select([main_fd], [], [], 0.05)
            if ready:
                try:
                    seen += os.read(main_fd, 65536)
                except OSError:
                    break
                # Textual draws words whole, but colour codes may sit between them: compare text only.
                text = _strip_escapes(seen)
                while len(found) < len(markers) and markers[len(found)] in text:
                    found.append(time.perf_counter() - started)
    finally:
        process.terminate()
        try:
            process.wait(5)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
        os.close(main_fd)
    if len(found) < len(markers):
        raise RuntimeError(f"{argv} never showed {markers[len(found)]!r}")
    return found


def _strip_escapes(data: bytes) -> bytes:
    import re

    return re.sub(rb"\x1b\[[0-9;?]*[A-Za-z]|\x1b[()][A-Za-z0-9]|\x1b\][^\x07]*\x07", b"", data)


def first_paint(runs: int) -> None:
    # The real app (`kinema ui`), attached to an endpoint where no runtime answers yet: what a user sees
    # first whether or not the runtime is up (the screen is drawn before the connection is made).
    from kinema.transport import free_endpoint

    real = [sys.executable, "-m", "kinema.cli.main", "ui", "--connect", free_endpoint()]
    demo = [sys.executable, "-m", "kinema.cli.main", "ui", "--demo"]
    bare = [sys.executable, "-c", BARE_APP]
    paint, demo_paint, ready, peer = [], [], [], []
    for _ in range(runs):
        paint.append(time_to_output(real, [b"Objectives"])[0])
        first, shown = time_to_output(demo, [b"Objectives", b"MoveToWaypoint"])
        demo_paint.append(first)
        ready.append(shown)
        peer.append(time_to_output(bare, [b"Objectives ready"])[0])
    print(f"First paint (pseudo-terminal, median of {runs} runs, interleaved)")
    print(f"  kinema ui          first frame  {statistics.median(paint) * 1000:7.0f} ms   (target < 1500 ms)")
    print(f"  kinema ui --demo   first frame  {statistics.median(demo_paint) * 1000:7.0f} ms")
    print(f"  kinema ui --demo   tree shown   {statistics.median(ready) * 1000:7.0f} ms")
    print(f"  bare Textual app   first frame  {statistics.median(peer) * 1000:7.0f} ms")
    ratio = statistics.median(paint) / statistics.median(peer)
    print(f"  ratio kinema ui / bare Textual  {ratio:7.2f}x   (target 2x)")


# -- input latency under a blackboard stream -----------------------------------------------------------


def input_latency(seconds: float, stock_table: bool) -> list[float]:
    """Probe latencies (seconds) while 1,000 keys stream at 10 Hz.

    ``stock_table`` measures the peer instead: a bare Textual app whose stock ``DataTable`` shows the same
    stream, updating each changed cell with ``update_cell`` (the usual way to keep a table live).
    """
    from textual.app import App, ComposeResult
    from textual.message import Message
    from textual.widgets import DataTable

    from kinema.tui.app import KinemaApp
    from kinema.tui.connection import BlackboardEntry, BlackboardSnapshot, RuntimeEvent
    from kinema.tui.fake_connection import FakeConnection
    from kinema.tui.widgets.blackboard_table import BlackboardTable

    sent: dict[int, float] = {}
    latencies: list[float] = []

    class Probe(Message):
        """Stands for a key press: it waits in the same queue as input events."""

        def __init__(self, index: int) -> None:
            super().__init__()
            self.index = index

    class ProbedApp(KinemaApp):
        def on_probe(self, message: Probe) -> None:
            latencies.append(time.perf_counter() - sent.pop(message.index))

    class StockTableApp(App[None]):
        def compose(self) -> ComposeResult:
            yield DataTable(id="table")

        def on_mount(self) -> None:
            table = self.query_one(DataTable)
            for column in ("Scope", "Key", "Type", "Value"):
                table.add_column(column, key=column)

        def take(self, snapshot: BlackboardSnapshot) -> None:
            table = self.query_one(DataTable)
            for entry in snapshot.entries:
                key = f"{entry.scope}/{entry.key}"
                if key in table.rows:
                    table.update_cell(key, "Value", entry.value)
                else:
                    table.add_row(entry.scope, entry.key, entry.type_name, entry.value, key=key)

        def on_probe(self, message: Probe) -> None:
            latencies.append(time.perf_counter() - sent.pop(message.index))

    fake = FakeConnection.demo()
    app: App[None]
    if stock_table:
        peer = StockTableApp()

        def deliver(event: RuntimeEvent) -> None:
            if isinstance(event, BlackboardSnapshot):
                peer.call_from_thread(peer.take, event)

        fake.listener = deliver
        app = peer
    else:
        app = ProbedApp(fake, initial_mode="blackboard")
    stop = threading.Event()

    def stream() -> None:
        tick = 0
        next_at = time.perf_counter()
        while not stop.is_set():
            tick += 1
            entries = tuple(
                BlackboardEntry(
                    "Stream" if i % 10 else "Stream/Sub::2", f"key_{i:04d}", "int", str(tick * 1000 + i)
                )
                for i in range(N_KEYS)
            )
            fake.emit(BlackboardSnapshot("Stream", float(tick), entries))
            next_at += 1.0 / RATE_HZ
            stop.wait(max(0.0, next_at - time.perf_counter()))

    def probe() -> None:
        index = 0
        while not stop.wait(PROBE_PERIOD_S):
            index = (index + 1) % 10
            if index in sent:
                continue  # the previous probe with this number is still queued
            sent[index] = time.perf_counter()
            app.post_message(Probe(index))

    async def main() -> None:
        async with app.run_test(size=(120, 40)) as pilot:
            await pilot.pause(0.5)
            threads = [
                threading.Thread(target=stream, daemon=True),
                threading.Thread(target=probe, daemon=True),
            ]
            for thread in threads:
                thread.start()
            await asyncio.sleep(seconds)
            stop.set()
            for thread in threads:
                # Joined off the event loop: the peer's stream thread waits on the loop (call_from_thread).
                await asyncio.to_thread(thread.join)
            await pilot.pause(0.3)
            if not stock_table:
                shown = app.screen.query_one(BlackboardTable).keys
                assert len(shown) == N_KEYS, len(shown)

    asyncio.run(main())
    return latencies


def latency(seconds: float) -> None:
    ours = input_latency(seconds, stock_table=False)
    naive = input_latency(seconds, stock_table=True)

    def describe(values: list[float]) -> str:
        ordered = sorted(values)
        p50 = ordered[len(ordered) // 2] * 1000
        p99 = ordered[min(len(ordered) - 1, int(len(ordered) * 0.99))] * 1000
        worst = ordered[-1] * 1000
        return f"p50 {p50:6.1f} ms   p99 {p99:6.1f} ms   max {worst:6.1f} ms   ({len(values)} probes)"

    print(f"Input latency while {N_KEYS} blackboard keys stream at {RATE_HZ:g} Hz ({seconds:g} s each)")
    print(f"  Kinema (Blackboard screen)   {describe(ours)}   (target p99 < 100 ms)")
    print(f"  stock DataTable, bare app    {describe(naive)}")
    p99_ours = sorted(ours)[min(len(ours) - 1, int(len(ours) * 0.99))]
    p99_naive = sorted(naive)[min(len(naive) - 1, int(len(naive) * 0.99))]
    print(f"  p99 ratio stock / Kinema     {p99_naive / p99_ours:6.1f}x")


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--runs", type=int, default=5, help="first-paint runs (median is printed)")
    parser.add_argument("--seconds", type=float, default=10.0, help="seconds of streaming per latency run")
    parser.add_argument(
        "--smoke", action="store_true", help="one first-paint run, a short latency run (the test suite)"
    )
    args = parser.parse_args()
    if args.smoke:
        args.runs, args.seconds = 1, 1.0
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"{os.cpu_count()} CPUs, load average {load:.1f}")
    first_paint(args.runs)
    print()
    latency(args.seconds)


if __name__ == "__main__":
    main()
