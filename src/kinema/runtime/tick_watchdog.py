"""The tick threads' watchdog: behavior code that does not return never wedges the objective server.

The server runs behavior code on a :class:`TickWorker` thread with its state lock released. The
:class:`TickWatchdog` looks at that thread every :data:`WATCHDOG_PERIOD_S`:

- behavior code running longer than the report threshold is named ("behavior 'Block' (Root/block) has
  been in tick for 3.0 s", :mod:`kinema.runtime.watchdog`), logged every :data:`WATCHDOG_LOG_EVERY_S`
  and shown in the server's health;
- while a request (a cancel, a newer objective, a stop) has waited for that thread longer than the
  abandon threshold, the server is told to abandon the thread (:meth:`WatchedServer.abandon`): it ends
  the run and serves the requests on a fresh thread. An abandoned thread raises :class:`Abandoned`
  when it comes back from behavior code, and its tree is disarmed and halted by
  :func:`release_stuck_tree`;
- a tick thread that died without replacing itself is replaced (:meth:`WatchedServer.replace_dead_worker`);
- a coroutine blocking the event loop that async behaviors share is reported and that loop retired;
- code that holds the interpreter (C code that does not release the GIL) stops every Python thread, this
  watchdog included, so it cannot look while it happens: :class:`StallDumps` keeps faulthandler's timer
  armed, whose own C thread needs no interpreter and writes every thread's stack when the watchdog has
  not re-armed it in time. The watchdog reads that afterwards and reports where the tick thread sat.
  (faulthandler has one such timer per process: a program embedding the server should not use
  ``faulthandler.dump_traceback_later`` itself while a server runs.)

It also words the warnings the server's health report carries about all of the above.
"""

from __future__ import annotations

import faulthandler
import logging
import os
import re
import sys
import tempfile
import threading
import time
from typing import TYPE_CHECKING, Any, Protocol

from kinema.bt.status import NodeStatus
from kinema.runtime.watchdog import StuckCode, stuck_code

if TYPE_CHECKING:
    from kinema.bt import Tree

log = logging.getLogger("kinema.objective_server")

WATCHDOG_PERIOD_S = 0.02
# The halt of an abandoned tree waits this long for its thread to come back from behavior code first.
HALT_WAITS_FOR_ABANDONED_S = 0.5
# A stuck behavior is logged again this often while it stays stuck.
WATCHDOG_LOG_EVERY_S = 10.0

# What each warning adds is what the user can do about it: the warnings reach `kinema run`'s terminal, the
# UI's status bar and log, and `kinema objective status`.
LOOP_BLOCKED = (
    "so no other async behavior could run meanwhile (they now run on a new loop): its code should await "
    "(asyncio.sleep, not time.sleep); cancelling the objective (ctrl+x, kinema objective cancel) stops it"
)
STUCK_ADVICE = "the objective cannot stop until it returns: cancel it (ctrl+x, kinema objective cancel)"
ABANDONED_ADVICE = "restart the runtime (kinema down, then kinema run) to free it"
# faulthandler's timer fires when no watchdog re-armed it for this long. Its C thread then reads every
# thread's stack without the interpreter's lock: safe while C code holds that lock (what the dump is for),
# but it can crash the process when the threads are running and the watchdog merely was not scheduled,
# as on a loaded machine that starves threads for a second or more (an agent died of it at load 85).
# So a stall is reported after 5 s, not after the report threshold of stuck behavior code (1 s).
STALL_REPORT_S = 5.0
# faulthandler's timer is re-armed every this many watchdog rounds (arming costs about 0.1 ms).
STALL_ARM_EVERY = 5
# A stall report stays in the health warnings this long.
STALL_SHOWN_S = 30.0
# Frames of the tick thread's stack a stall report names (innermost first).
STALL_FRAMES = 4
# A tick thread with one of these server frames on its stack was running behavior code.
RUNNING_BEHAVIORS = r"objective_server\.py\", line \d+ in (_tick|_load|_halt_quietly|_take_requests)$"


class StallDumps:
    """faulthandler's timer, kept armed by the watchdogs of this process (one timer, one file).

    When no watchdog re-armed it for the threshold, something held the interpreter (or the process was
    stopped): faulthandler's C thread, which needs no interpreter lock, wrote every thread's stack to the
    file. :meth:`arm` collects such a dump before arming again; each watchdog reads the new ones.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._fd: int | None = None
        self.dumps: list[tuple[int, float, str]] = []  # (sequence number, when read, text)
        self._sequence = 0
        self._watchers = 0

    def register(self) -> None:
        with self._lock:
            self._watchers += 1

    def unregister(self) -> None:
        """A watchdog stopped; the last one disarms the timer (an idle process is not a stalled one)."""
        with self._lock:
            self._watchers -= 1
            if self._watchers <= 0:
                self._watchers = 0
                faulthandler.cancel_dump_traceback_later()
                if self._fd is not None:
                    os.ftruncate(self._fd, 0)
                    os.lseek(self._fd, 0, os.SEEK_SET)

    def arm(self, seconds: float) -> None:
        with self._lock:
            if self._fd is None:
                handle, path = tempfile.mkstemp(prefix="kinema-stall-", suffix=".txt")
                os.unlink(path)
                self._fd = handle
            faulthandler.cancel_dump_traceback_later()  # waits for a dump being written
            size = os.lseek(self._fd, 0, os.SEEK_END)
            if size:
                text = os.pread(self._fd, size, 0).decode("utf-8", "replace")
                os.ftruncate(self._fd, 0)
                os.lseek(self._fd, 0, os.SEEK_SET)
                self._sequence += 1
                self.dumps = [*self.dumps[-7:], (self._sequence, time.monotonic(), text)]
            faulthandler.dump_traceback_later(seconds, repeat=False, file=self._fd, exit=False)

    def since(self, sequence: int) -> list[tuple[int, float, str]]:
        with self._lock:
            return [dump for dump in self.dumps if dump[0] > sequence]


STALLS = StallDumps()


def stack_in_dump(dump: str, ident: int | None) -> list[str]:
    """The frames (innermost first) a faulthandler dump shows for thread ``ident``."""
    if ident is None:
        return []
    wanted = f"0x{ident:016x}"
    frames: list[str] = []
    inside = False
    for line in dump.splitlines():
        if line.startswith(("Thread 0x", "Current thread 0x")):
            inside = wanted in line
            continue
        if inside and line.strip().startswith("File "):
            frames.append(line.strip())
        elif inside and not line.strip():
            break
    return frames


class Abandoned(BaseException):
    """Raised in a tick thread returning from behavior code after the watchdog abandoned it."""


class TickWorker:
    """One tick thread. ``busy_since`` is set while it runs behavior code (the server lock released)."""

    def __init__(self, generation: int) -> None:
        self.generation = generation
        self.thread: threading.Thread | None = None
        self.abandoned = False
        self.abandoned_at = 0.0
        self.busy_since: float | None = None
        self.busy_stage = ""
        self.stuck: StuckCode | None = None
        self.stuck_since = 0.0
        self.logged_at = 0.0
        # Set while the thread is outside behavior code (set again before it waits for the state lock).
        self.returned = threading.Event()
        self.returned.set()

    @property
    def name(self) -> str:
        return "kinema-tick" if self.generation == 1 else f"kinema-tick-{self.generation}"

    def alive(self) -> bool:
        return self.thread is not None and self.thread.is_alive()


class WatchedServer(Protocol):
    """What the watchdog needs of the objective server."""

    def watched_worker(self) -> TickWorker | None:
        """The tick thread serving requests now."""

    def waiting_since(self) -> float | None:
        """When the oldest request the tick thread has yet to serve was posted (None: none waits)."""

    def abandon(self, worker: TickWorker, busy_since: float) -> None:
        """Give up on ``worker``, stuck in behavior code since ``busy_since``; a fresh thread serves."""

    def replace_dead_worker(self, worker: TickWorker) -> None:
        """``worker`` died without a successor: start one (or finish stopping)."""


class TickWatchdog:
    """The watchdog thread of one objective server (see the module docstring).

    Args:
        server: the server watched.
        stopped: set when the server has stopped; the watchdog then ends.
        report_after_s: behavior code running longer than this in one call is reported.
        abandon_after_s: how long a request waits for a thread stuck in behavior code before the
            thread is abandoned.
        stall_after_s: how long the interpreter must be held before faulthandler dumps the stacks.
    """

    def __init__(
        self,
        server: WatchedServer,
        stopped: threading.Event,
        *,
        report_after_s: float,
        abandon_after_s: float,
        stall_after_s: float = STALL_REPORT_S,
    ) -> None:
        self._server = server
        self.stall_after_s = stall_after_s
        self._stopped = stopped
        self.report_after_s = report_after_s
        self.abandon_after_s = abandon_after_s
        # What blocked each retired event loop of async behaviors (by thread id).
        self._loop_codes: dict[int | None, StuckCode] = {}
        self._rounds = 0
        self._stall_seen = STALLS.since(-1)[-1][0] if STALLS.since(-1) else 0
        self._stalls: list[tuple[float, str]] = []  # (when, sentence)
        self._thread = threading.Thread(target=self._watch, name="kinema-tick-watchdog", daemon=True)

    def start(self) -> None:
        STALLS.register()
        STALLS.arm(self.stall_after_s)  # armed before the first tick, not a round later
        self._thread.start()

    def join(self, timeout: float | None = None) -> None:
        self._thread.join(timeout)

    def _watch(self) -> None:
        try:
            self._watch_loop()
        finally:
            STALLS.unregister()

    def _watch_loop(self) -> None:
        while not self._stopped.wait(WATCHDOG_PERIOD_S):
            try:
                if self._rounds % STALL_ARM_EVERY == 0:
                    STALLS.arm(self.stall_after_s)
                self._rounds += 1
                self._watch_stalls()
                self._watch_once()
            except Exception:
                log.exception("the tick watchdog raised")

    def _watch_stalls(self) -> None:
        """Report where the tick thread sat while something held the interpreter (see StallDumps)."""
        for sequence, when, dump in STALLS.since(self._stall_seen):
            self._stall_seen = sequence
            worker = self._server.watched_worker()
            ident = worker.thread.ident if worker is not None and worker.thread is not None else None
            frames = stack_in_dump(dump, ident)
            if not any(re.search(RUNNING_BEHAVIORS, frame) for frame in frames):
                continue  # the tick thread was waiting, not running behavior code: not its stall
            where = " ← ".join(frames[:STALL_FRAMES])
            thread = worker.name if worker else "?"
            sentence = (
                f"Kinema stood still for more than {self.stall_after_s:g} s: the interpreter was held (C "
                f"code that does not release Python's lock?) while tick thread {thread} sat in: {where}; "
                "slow C work belongs in an AsyncBehavior's do_work, off the tick"
            )
            log.error("watchdog: %s", sentence)
            self._stalls = [*self._stalls[-3:], (when, sentence)]

    def _watch_event_loop(self) -> None:
        """A coroutine that blocks the async behaviors' event loop: report it, move on to a fresh loop."""
        runner = work_runner()
        blocked = runner.blocked_loop() if runner is not None else None
        if blocked is None or blocked[0] < self.report_after_s:
            return
        seconds, ident = blocked
        code = stuck_code(ident, "a coroutine")
        self._loop_codes[ident] = code
        runner.retire_blocked_loop()
        log.error("watchdog: %s, %s", code.describe(seconds), LOOP_BLOCKED)

    def _watch_once(self) -> None:
        self._watch_event_loop()
        now = time.monotonic()
        worker = self._server.watched_worker()
        if worker is None:
            return
        busy_since = worker.busy_since
        if busy_since is not None and worker.thread is not None:
            if now - busy_since >= self.report_after_s:
                stuck = stuck_code(worker.thread.ident, worker.busy_stage)
                if worker.busy_since == busy_since:
                    worker.stuck = stuck
                    if now - worker.logged_at >= WATCHDOG_LOG_EVERY_S:
                        worker.logged_at = now
                        log.warning("watchdog: %s", stuck.describe(now - busy_since))
            waiting = self._server.waiting_since()
            if waiting is not None and now - max(waiting, busy_since) >= self.abandon_after_s:
                self._server.abandon(worker, busy_since)
            return
        if not worker.alive() and not self._stopped.is_set():
            # Died without reaching its own handler (or before it could start a successor).
            self._server.replace_dead_worker(worker)

    def warnings(self, worker: TickWorker | None, abandoned: list[TickWorker]) -> list[str]:
        """One sentence per problem seen now: stuck code, abandoned threads, ignored halts, blocked loops."""
        now = time.monotonic()
        warnings: list[str] = []
        if worker is not None and worker.stuck is not None and worker.busy_since is not None:
            warnings.append(f"{worker.stuck.describe(now - worker.busy_since)}; {STUCK_ADVICE}")
        for old in list(abandoned):
            stuck = old.stuck or StuckCode("", "", old.busy_stage)
            since = old.stuck_since
            warnings.append(
                f"abandoned tick thread {old.name}: {stuck.describe(now - since)} "
                f"(abandoned {now - old.abandoned_at:.1f} s ago); {ABANDONED_ADVICE}"
            )
        warnings.extend(sentence for when, sentence in self._stalls if now - when < STALL_SHOWN_S)
        warnings.extend(halted_work_warnings(self.report_after_s))
        runner = work_runner()
        if runner is not None:
            for seconds, ident in runner.retired_loops():
                code = self._loop_codes.get(ident) or StuckCode("", "", "a coroutine")
                warnings.append(f"{code.describe(seconds)}, {LOOP_BLOCKED}")
        return warnings


def release_stuck_tree(tree: Tree, worker: TickWorker) -> None:
    """Disarm a tree whose thread was abandoned and halt it on a thread of its own.

    Every node of it fails at once from now on, so the stuck call, if it returns, cannot start
    anything new (a motion, a goal) after the cancel; the halt stops what its other nodes run. It
    waits a moment for the abandoned thread to come back, so that a tick that was only slow (a
    loaded machine) is never halted while it still runs.
    """

    def refuse(_node: Any) -> NodeStatus:
        return NodeStatus.FAILURE

    for node in tree.nodes():
        node.set_pre_tick_callback(refuse)

    def halt() -> None:
        worker.returned.wait(HALT_WAITS_FOR_ABANDONED_S)
        try:
            tree.halt_tree()
        except BaseException:
            log.exception("halting the tree of an abandoned tick thread raised")

    threading.Thread(target=halt, name="kinema-halt-abandoned", daemon=True).start()


def work_runner() -> Any:
    """The runner of AsyncBehavior work, or None while no behavior ever ran work off the tick thread."""
    module = sys.modules.get("kinema.behaviors.work_runner")
    return module.RUNNER if module is not None else None


def halted_work_warnings(after_s: float) -> list[str]:
    """Behaviors whose ``do_work`` still runs ``after_s`` after they were halted."""
    runner = work_runner()
    if runner is None:
        return []
    return [
        f"behavior '{behavior}' ({path}) has ignored a halt for {seconds:.1f} s: its do_work still runs "
        "(it should return when cancelled); restart the runtime if it never ends"
        for behavior, path, seconds in runner.halted_still_running()
        if seconds >= after_s
    ]
