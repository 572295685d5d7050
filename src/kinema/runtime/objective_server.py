"""The objective server: one objective at a time, ticked at a fixed rate by one thread.

Everything that wants to change what runs (an SDK call, ``/do_objective``, ``/cancel_objective``, a
hot reload) sends the tick thread a request; only the tick thread builds, ticks and halts the Tree
(DESIGN invariant 1). A cancel or a newer request wakes the tick thread at once, so running behaviors
are halted well within one tick period (invariant 2).

Cancel always wins, whatever the tree does:

- a tree that re-ticks itself synchronously (``<Repeat num_cycles="-1"><AlwaysSuccess/></Repeat>``)
  is interrupted between two iterations when a request arrives or a tick period is used up; the
  iteration it owes runs at the next tick, so a tree nobody cancels ticks exactly as in BT.CPP;
- behavior code that does not return (a blocking ``tick``, a ``halt`` that waits) is caught by the
  watchdog: after :data:`WATCHDOG_REPORT_S` it reports "behavior X (node path) has been in tick for N s"
  in the log and in :meth:`ObjectiveServer.health`; a cancel or a newer request pending for
  :data:`ABANDON_AFTER_S` makes it abandon the stuck tick thread: the run ends cancelled, the stuck tree
  is disarmed (its nodes fail at once if the stuck call returns into it) and halted on a thread of its
  own, and a fresh tick thread serves the next request. The abandoned thread is reported until it
  returns, then it exits;
- any exception from behavior code, ``SystemExit`` and ``KeyboardInterrupt`` included, fails the run;
  if the tick thread dies nonetheless, the health report says so and a fresh one serves the next request.

The tick thread owns the server's state (the tree, the run) except while it is inside behavior code;
the watchdog (:mod:`kinema.runtime.tick_watchdog`) takes the state over only then, under the same lock.

The server knows nothing about the transport: :mod:`kinema.runtime.agent` serves it over zenoh and a
:class:`ServerListener` receives what the streams publish (status, node status changes, blackboard
snapshots, finished runs), always on the tick thread.
"""

from __future__ import annotations

import copy
import itertools
import logging
import threading
import time
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Protocol

from kinema.bt.errors import TreeNotFoundError
from kinema.bt.status import NodeStatus
from kinema.errors import KinemaError, ObjectiveError, did_you_mean
from kinema.runtime.node_status import NodeStatusBatch, NodeStatusRecorder
from kinema.runtime.objective_status import ObjectiveStatus
from kinema.runtime.overrides import ParameterOverride, apply_overrides, model_defaults
from kinema.runtime.result import ObjectiveResult
from kinema.runtime.tick_watchdog import (
    STALL_REPORT_S,
    WATCHDOG_PERIOD_S,
    Abandoned,
    TickWatchdog,
    TickWorker,
    release_stuck_tree,
)
from kinema.runtime.watchdog import StuckCode, stuck_code

if TYPE_CHECKING:
    from lxml import etree

    from kinema.bt import BehaviorTreeFactory, Tree
    from kinema.bt.xmlparser import SubtreeModel

log = logging.getLogger("kinema.objective_server")

DEFAULT_TICK_RATE_HZ = 100.0
# An objective sent as a string larger than this is refused before parsing: a tree this large is a
# mistake or an attack, and parsing it would stall the tick thread.
MAX_OBJECTIVE_XML_BYTES = 2 * 1024 * 1024
# How long the status stays Success/Failure/Cancelled after a run before it returns to Idle, so that
# pollers of the heartbeat see how the run ended.
RESULT_HOLD_S = 2.0
# Blackboard snapshots are taken at most this often while a tree runs.
BLACKBOARD_SNAPSHOT_PERIOD_S = 0.1
# Behavior code (a tick, a halt, a tree's constructors) running longer than this is reported.
WATCHDOG_REPORT_S = 1.0
# A cancel, a newer request or a stop waiting this long for a tick thread stuck in behavior code makes the
# server abandon that thread. With the watchdog's period, cancel wins within a tick period plus 100 ms.
ABANDON_AFTER_S = 0.07
# A tree that re-ticks itself for a whole tick period pauses this long before the tick it owes, so that
# it cannot starve the transport and a simulator running in the same process.
RETICK_PAUSE_S = 0.005
# Where errors in an objective sent as an XML string say they are.
_XML_NAME = "<objective XML>"


@dataclass(frozen=True)
class ObjectiveRequest:
    """What to run: a named objective of the library, or an XML string (the name wins if both are set).

    Attributes:
        objective_name: an objective (BehaviorTree ID) of the loaded library.
        objective_xml: a complete BT.CPP v4 document; its main tree runs.
        overrides: parameter overrides applied before the first tick (all or nothing).
        origin: who asked (``execute_objective``, ``do_objective``, ...), for logs.
    """

    objective_name: str = ""
    objective_xml: str = ""
    overrides: Sequence[ParameterOverride] = ()
    origin: str = ""

    @property
    def label(self) -> str:
        """A short name for logs and status before the tree is built."""
        if self.objective_name:
            return self.objective_name
        return "<objective XML>" if self.objective_xml else "<empty request>"


class ServerListener(Protocol):
    """Receives what happens in the server. Every method runs on the tick thread and must not block."""

    def on_status(self, status: ObjectiveStatus, objective_name: str) -> None:
        """The server's status changed (Idle, Loading, Running, Success, Failure, Cancelled)."""

    def on_node_status(self, objective_name: str, changes: NodeStatusBatch) -> None:
        """Nodes changed status during one tick (iterate the batch for NodeStatusChange objects)."""

    def on_blackboard(self, objective_name: str, entries: list[tuple[str, str, str, Any]]) -> None:
        """A blackboard snapshot: ``(scope, key, type_name, value)`` for every entry (throttled)."""

    def on_run_finished(self, run: ObjectiveRun, result: ObjectiveResult) -> None:
        """A run ended (succeeded, failed, was cancelled or preempted)."""


class TreeListener(ServerListener, Protocol):
    """A listener that also sees each run's Tree (Groot2, recordings): it reads, never ticks or halts it.

    The node transitions it gets are the ``on_node_status`` batches every listener gets: one status
    observer on the tree feeds them all.
    """

    def on_tree_loaded(self, objective_name: str, tree: Tree) -> None:
        """A new run's tree was built and its overrides applied; it has not been ticked yet."""


class ObjectiveRun:
    """A submitted request and, once it ends, its result. Thread-safe; returned by ``submit``."""

    def __init__(self, run_id: int, request: ObjectiveRequest, server: ObjectiveServer) -> None:
        self.id = run_id
        self.request = request
        self.objective_name = request.label
        # The objective's declared ports that nothing set (no default, no override): a failure that
        # names one of them gets a hint saying which parameter to give.
        self.unset_parameters: tuple[str, ...] = ()
        # Set when the tree uses behaviors whose latest files failed to load (older code runs): said at
        # the start and repeated in a failure's message.
        self.stale_note = ""
        self._server = server
        self._done = threading.Event()
        self._result: ObjectiveResult | None = None
        self._callbacks: list[Callable[[ObjectiveResult], None]] = []
        # Called once its first tick returned without ending it (add_running_callback).
        self._running_callbacks: list[Callable[[], None]] = []
        self._ticked = False
        self._lock = threading.Lock()
        # Set when a cancel of this run was accepted: from then on it can no longer end as SUCCESS (a
        # tick stuck in C code that holds the interpreter may still complete after the cancel came).
        self.cancel_reason: str | None = None
        self._settled = False

    @property
    def done(self) -> bool:
        """True once the run ended (its result is known)."""
        return self._result is not None

    @property
    def result(self) -> ObjectiveResult | None:
        """The result, or None while the run is pending or running."""
        return self._result

    def wait(self, timeout: float | None = None) -> ObjectiveResult | None:
        """Block until the run ends; returns its result, or None on timeout."""
        self._done.wait(timeout)
        return self._result

    def cancel(self) -> bool:
        """Ask the server to cancel this run; False when it already ended."""
        return self._server.cancel(self)

    def request_cancel(self, reason: str) -> bool:
        """Accept a cancel of this run unless its outcome is already settled; True when accepted.

        An accepted cancel is honored even if the tree completes in the tick it came during: the run
        then ends cancelled (PREEMPTED), never SUCCESS.
        """
        with self._lock:
            if self._settled:
                return False
            if self.cancel_reason is None:
                self.cancel_reason = reason
            return True

    def _settle(self, result: ObjectiveResult) -> ObjectiveResult:
        """Fix the outcome (the tick thread, as the run ends): an accepted cancel turns SUCCESS into it."""
        with self._lock:
            self._settled = True
            if not result.succeeded or self.cancel_reason is None:
                return result
            reason = self.cancel_reason
        log.warning(
            "objective %r completed after a cancel was accepted (%s); it ends cancelled",
            self.objective_name,
            reason,
        )
        return ObjectiveResult.preempted(
            f"{reason} (accepted while its last tick ran: the tree completed, the cancel wins)",
            self.objective_name,
        )

    def add_done_callback(self, callback: Callable[[ObjectiveResult], None]) -> None:
        """Call ``callback(result)`` when the run ends (at once if it already has).

        The callback runs on the tick thread and must not block.
        """
        with self._lock:
            if self._result is None:
                self._callbacks.append(callback)
                return
            result = self._result
        callback(result)

    def add_running_callback(self, callback: Callable[[], None]) -> None:
        """Call ``callback()`` once the run's first tick returned without ending it (at once if that
        happened already); never for a run that ends before or in its first tick.

        The callback runs on the tick thread and must not block.
        """
        with self._lock:
            if not self._ticked:
                self._running_callbacks.append(callback)
                return
            if self._result is not None:
                return
        callback()

    def _first_tick_returned(self) -> None:
        """The run's first tick returned RUNNING (the tick thread)."""
        with self._lock:
            if self._ticked:
                return
            self._ticked = True
            callbacks, self._running_callbacks = self._running_callbacks, []
        for callback in callbacks:
            try:
                callback()
            except Exception:
                log.exception("a running callback of objective run %d raised", self.id)

    def release_xml(self) -> None:
        """Let go of the request's objective XML (up to MAX_OBJECTIVE_XML_BYTES, or a larger refused
        one): it is not needed once the tree is built or the run ended, and the tick thread may keep
        the run referenced while it waits for the next request."""
        if self.request.objective_xml:
            self.request = replace(self.request, objective_xml="")

    def _finish(self, result: ObjectiveResult) -> bool:
        answered = self._answer(result)
        self._release()
        return answered

    def _answer(self, result: ObjectiveResult) -> bool:
        """Fix the result and call the done callbacks (they answer the run's clients); False when the run
        already had a result. :meth:`wait` returns only after :meth:`_release`."""
        self.release_xml()
        with self._lock:
            if self._result is not None:
                return False
            self._result = result
            callbacks, self._callbacks = self._callbacks, []
        for callback in callbacks:
            try:
                callback(result)
            except Exception:
                log.exception("a done callback of objective run %d raised", self.id)
        return True

    def _release(self) -> None:
        """Let :meth:`wait` return: the listeners have been told how the run ended."""
        self._done.set()

    def __repr__(self) -> str:
        return f"ObjectiveRun({self.id}, {self.objective_name!r}, result={self._result})"


@dataclass
class _Cancel:
    run: ObjectiveRun | None  # None: whatever runs now
    reason: str
    ack: threading.Event = field(default_factory=threading.Event)
    cancelled: bool = False
    # An abort: something the run needs died (a driver); it ends as FAILURE, never as a cancel.
    failure: bool = False


@dataclass
class _Call:
    fn: Callable[[], Any]
    done: threading.Event = field(default_factory=threading.Event)
    value: Any = None
    error: BaseException | None = None


class TreeSource(Protocol):
    """Builds trees: the factory the behaviors are registered in, plus the objective names it knows."""

    def factory(self) -> BehaviorTreeFactory:
        """The factory to build the next tree with (it may change between runs: hot reload)."""

    def objective_names(self) -> list[str]:
        """The objective (BehaviorTree) IDs that can be run by name."""


class FactoryTreeSource:
    """A :class:`TreeSource` over one factory whose registered trees are the runnable objectives."""

    def __init__(self, factory: BehaviorTreeFactory) -> None:
        self._factory = factory

    def factory(self) -> BehaviorTreeFactory:
        return self._factory

    def objective_names(self) -> list[str]:
        return list(self._factory.registered_behavior_trees())

    def replace(self, factory: BehaviorTreeFactory) -> None:
        """Use ``factory`` from the next run on (call it through ``ObjectiveServer.call_soon``)."""
        self._factory = factory


@dataclass(frozen=True)
class ServerHealth:
    """What the watchdog sees, published beside the heartbeat.

    Attributes:
        tick_thread_alive: False while no tick thread serves requests (a dead one not yet replaced).
        replacements: tick threads replaced since the start (abandoned while stuck, or died).
        warnings: one sentence per problem seen now: behavior code stuck in a tick or halt, halted work
            still running, abandoned threads still stuck, the last death of a tick thread.
    """

    tick_thread_alive: bool = True
    replacements: int = 0
    warnings: tuple[str, ...] = ()


_CALL_STAGE = "a hot-reload request"


class ObjectiveServer:
    """Runs one objective at a time on its own tick thread.

    Args:
        source: where trees come from (a factory and the names of the runnable objectives).
        tick_rate_hz: ticks per second while an objective runs (100 Hz, as MoveIt Pro's server).
        listeners: receive status, node status changes, blackboard snapshots and results.
        blackboard_period_s: the minimum time between two blackboard snapshots (0 disables them).
        result_hold_s: how long a run's final status is shown before the server reports Idle again.
        watchdog_report_s: behavior code running longer than this in one call is reported.
        abandon_after_s: how long a cancel or newer request waits for a tick thread stuck in behavior
            code before the thread is abandoned.
        stall_report_s: how long the interpreter must be held (C code keeping the GIL) before the stacks
            are dumped and the stall reported (see tick_watchdog.STALL_REPORT_S).
    """

    def __init__(
        self,
        source: TreeSource,
        *,
        tick_rate_hz: float = DEFAULT_TICK_RATE_HZ,
        listeners: Sequence[ServerListener] = (),
        blackboard_period_s: float = BLACKBOARD_SNAPSHOT_PERIOD_S,
        result_hold_s: float = RESULT_HOLD_S,
        watchdog_report_s: float = WATCHDOG_REPORT_S,
        abandon_after_s: float = ABANDON_AFTER_S,
        stall_report_s: float = STALL_REPORT_S,
    ) -> None:
        if tick_rate_hz <= 0:
            raise KinemaError(f"the tick rate must be positive, got {tick_rate_hz} Hz")
        self._source = source
        self._period = 1.0 / tick_rate_hz
        self._listeners = list(listeners)
        self._blackboard_period = blackboard_period_s
        self._watchdog_report = watchdog_report_s
        self._abandon_after = abandon_after_s
        self._stall_report = stall_report_s
        self._ids = itertools.count(1)
        self._inbox: deque[ObjectiveRun | _Cancel | _Call] = deque()
        self._wake = threading.Condition()
        self._woken = False
        self._tick_now = False
        self._stopping = False
        self._stop_reason = "the objective server stopped"
        # Set by every request: a tree re-ticking itself stops between two iterations to serve it.
        self._interrupt = False
        # When the oldest request that a stuck tick thread would have to serve was posted.
        self._waiting_since: float | None = None
        # The tick thread holds this lock while it touches the state below; it releases it only while it
        # runs behavior code, which is when the watchdog may take the state over.
        self._state_lock = threading.RLock()
        self._worker: TickWorker | None = None
        self._generations = itertools.count(1)
        self._abandoned: list[TickWorker] = []
        self._replacements = 0
        self._last_death = ""
        self._stopped = threading.Event()
        self._watchdog: TickWatchdog | None = None
        # Owned by the tick thread:
        self._tree: Tree | None = None
        self._run: ObjectiveRun | None = None
        # Set when the current run's tick thread was abandoned in its behavior code.
        self._run_stuck: TickWorker | None = None
        # Requests taken from the inbox and not yet done; the watchdog queues them again for the thread
        # that replaces an abandoned one.
        self._in_hand: list[ObjectiveRun | _Cancel | _Call] = []
        self._in_hand_start: ObjectiveRun | None = None
        self._recorder = NodeStatusRecorder()
        self._last_snapshot = 0.0
        self._failure_notes: dict[str, str] = {}
        self._notes_lock = threading.Lock()
        # Read by any thread (a consistent pair, replaced atomically):
        self._status: tuple[ObjectiveStatus, str] = (ObjectiveStatus.IDLE, "")
        self._result_hold = result_hold_s
        self._ended_at: float | None = None

    # -- lifecycle --------------------------------------------------------------------------------

    def start(self) -> None:
        """Start the tick thread and its watchdog."""
        if self._watchdog is not None:
            return
        self._stopped.clear()
        with self._state_lock:
            self._start_worker()
        self._watchdog = TickWatchdog(
            self,
            self._stopped,
            report_after_s=self._watchdog_report,
            abandon_after_s=self._abandon_after,
            stall_after_s=self._stall_report,
        )
        self._watchdog.start()

    def stop(self, timeout: float = 5.0, *, reason: str = "the objective server stopped") -> None:
        """Halt the running objective and stop the tick thread.

        The running objective ends as FAILURE with ``reason``: a stopping runtime is not a cancel its
        client asked for (queued requests are refused with it too).
        """
        if self._watchdog is None:
            return
        with self._wake:
            self._stop_reason = reason
            self._stopping = True
            self._interrupt = True
            self._woken = True
            if self._waiting_since is None:
                self._waiting_since = time.monotonic()
            self._wake.notify_all()
        self._stopped.wait(timeout)
        self._watchdog.join(timeout)
        self._watchdog = None

    def __enter__(self) -> ObjectiveServer:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def add_listener(self, listener: ServerListener) -> None:
        """Register a listener (before :meth:`start`)."""
        self._listeners.append(listener)

    @property
    def tick_period(self) -> float:
        """Seconds between two ticks."""
        return self._period

    @property
    def _thread(self) -> threading.Thread | None:
        worker = self._worker
        return worker.thread if worker is not None else None

    # -- requests (any thread) ------------------------------------------------------------------

    @property
    def status(self) -> tuple[ObjectiveStatus, str]:
        """``(status, objective_name)`` right now."""
        return self._status

    def health(self) -> ServerHealth:
        """What the watchdog sees now (safe from any thread)."""
        worker = self._worker
        alive = worker is not None and worker.alive()
        watchdog = self._watchdog
        warnings = watchdog.warnings(worker, self._abandoned) if watchdog is not None else []
        if self._last_death:
            warnings.append(self._last_death)
        if not alive and self._watchdog is not None and not self._stopping:
            warnings.append("no tick thread is running; a new one starts within a moment")
        return ServerHealth(alive, self._replacements, tuple(warnings))

    def submit(
        self, request: ObjectiveRequest, before_start: Callable[[ObjectiveRun], None] | None = None
    ) -> ObjectiveRun:
        """Queue ``request``; the running objective (if any) is preempted when the tick thread takes it.

        Args:
            request: what to run.
            before_start: called with the new run before the tick thread can see it, so whatever it
                registers (a listener for the run's toasts, say) is in place before the first tick.
        """
        run = ObjectiveRun(next(self._ids), request, self)
        if before_start is not None:
            before_start(run)
        self._post(run)
        return run

    def cancel(
        self, run: ObjectiveRun | None = None, *, reason: str = "cancelled", timeout: float = 5.0
    ) -> bool:
        """Cancel ``run`` (or whatever runs now) and wait until it is halted.

        Returns:
            True if something was cancelled; False when idle, or ``run`` had already ended.
        """
        if run is not None and run.done:
            return False
        target = run if run is not None else self._run
        if target is not None:
            target.request_cancel(reason)
        request = _Cancel(run, reason)
        self._post(request)
        if threading.current_thread() is self._thread:
            return True
        request.ack.wait(timeout)
        return request.cancelled

    def abort(self, reason: str, *, timeout: float = 5.0) -> bool:
        """End whatever runs as FAILURE with ``reason`` (something it needs died: a driver, a link).

        Returns:
            True if something was running (it is halted when this returns, up to ``timeout``).
        """
        request = _Cancel(None, reason, failure=True)
        self._post(request)
        if threading.current_thread() is self._thread:
            return True
        request.ack.wait(timeout)
        return request.cancelled

    def call_soon(self, fn: Callable[[], Any], *, timeout: float | None = 10.0) -> Any:
        """Run ``fn`` on the tick thread between two ticks and return its result (hot reload uses it).

        Raises:
            whatever ``fn`` raised; KinemaError when the tick thread did not get to it within ``timeout``.
        """
        if threading.current_thread() is self._thread or self._watchdog is None:
            return fn()
        call = _Call(fn)
        self._post(call)
        if not call.done.wait(timeout):
            raise KinemaError(f"the objective server's tick thread did not run a request within {timeout} s")
        if call.error is not None:
            raise call.error
        return call.value

    def _post(self, item: ObjectiveRun | _Cancel | _Call) -> None:
        with self._wake:
            self._inbox.append(item)
            self._woken = True
            self._interrupt = True
            if self._waiting_since is None and not isinstance(item, _Call):
                self._waiting_since = time.monotonic()
            self._wake.notify_all()

    def _wake_up(self) -> None:
        # A tree's wake-up signal (a behavior finished its work off-thread): tick again at once.
        with self._wake:
            self._woken = True
            self._tick_now = True
            self._wake.notify_all()

    def note_failure(self, node_path: str, message: str) -> None:
        """Remember why a node is failing (a behavior's ``publish_failure``), for the run's error message.

        Safe from any thread; notes are cleared when the next objective loads.
        """
        with self._notes_lock:
            self._failure_notes[node_path] = message

    # -- tick threads and the watchdog ------------------------------------------------------------

    def _start_worker(self) -> None:
        """Start a tick thread (the state lock held)."""
        worker = TickWorker(next(self._generations))
        worker.thread = threading.Thread(target=self._serve, args=(worker,), name=worker.name, daemon=True)
        self._worker = worker
        worker.thread.start()

    @contextmanager
    def _behavior_code(self, worker: TickWorker, stage: str) -> Iterator[None]:
        """Run behavior code with the state lock released, so that the watchdog can take over."""
        worker.busy_stage = stage
        worker.busy_since = time.monotonic()
        worker.returned.clear()
        self._state_lock.release()
        try:
            yield
        finally:
            worker.returned.set()
            self._state_lock.acquire()
            worker.busy_since = None
            worker.stuck = None
            if worker.abandoned:
                raise Abandoned

    def _serve(self, worker: TickWorker) -> None:
        self._state_lock.acquire()
        try:
            self._loop(worker)
        except Abandoned:
            seconds = time.monotonic() - worker.abandoned_at
            log.warning(
                "abandoned tick thread %s returned %.1f s after it was abandoned", worker.name, seconds
            )
        except BaseException as error:  # the tick thread must never vanish silently
            self._tick_thread_died(worker, error)
        finally:
            if worker in self._abandoned:
                self._abandoned.remove(worker)
            self._state_lock.release()

    def _tick_thread_died(self, worker: TickWorker, error: BaseException) -> None:
        where = _location_of(error)
        self._last_death = (
            f"the tick thread {worker.name} died: {type(error).__name__}: {error}{where}; "
            "a new one serves the next objective"
        )
        log.critical("%s", self._last_death, exc_info=error)
        if self._worker is worker:
            self._replacements += 1
            run, tree = self._run, self._tree
            if tree is not None:
                # Whatever its nodes run (a motion) must still stop.
                release_stuck_tree(tree, worker)
            if run is not None:
                message = f"objective {run.objective_name!r} stopped: {self._last_death}"
                self._end(run, ObjectiveResult.failure(message, run.objective_name), ObjectiveStatus.FAILURE)
            # A new thread takes over the requests at once (the watchdog would, a moment later).
            if not self._stopping:
                self._start_worker()
            else:
                self._stopped.set()

    # What the watchdog (kinema.runtime.tick_watchdog) reads and asks of the server.

    def watched_worker(self) -> TickWorker | None:
        """The tick thread serving requests now."""
        return self._worker

    def waiting_since(self) -> float | None:
        """When the oldest request the tick thread has yet to serve was posted."""
        return self._waiting_since

    def replace_dead_worker(self, worker: TickWorker) -> None:
        """A tick thread died without reaching its own handler (or before it could start a successor)."""
        with self._state_lock:
            if self._worker is worker and not worker.alive():
                self._replacements += 1
                if not self._last_death:
                    self._last_death = f"the tick thread {worker.name} died; a new one took over"
                log.critical("%s", self._last_death)
                if self._stopping:
                    self._stopped.set()
                else:
                    self._start_worker()

    def abandon(self, worker: TickWorker, busy_since: float) -> None:
        """Give up on a tick thread stuck in behavior code: a fresh one serves the pending requests."""
        if not self._state_lock.acquire(timeout=WATCHDOG_PERIOD_S):
            return
        try:
            if self._worker is not worker or worker.busy_since != busy_since:
                return  # it came back meanwhile
            assert worker.thread is not None
            stuck = stuck_code(worker.thread.ident, worker.busy_stage)
            worker.stuck = stuck
            worker.stuck_since = busy_since
            worker.abandoned = True
            worker.abandoned_at = time.monotonic()
            self._abandoned.append(worker)
            self._replacements += 1
            log.error(
                "watchdog: %s; abandoning tick thread %s to serve a cancel or a newer request",
                stuck.describe(worker.abandoned_at - busy_since),
                worker.name,
            )
            if self._run is not None:
                self._run_stuck = worker
            pending: list[ObjectiveRun | _Cancel | _Call] = []
            if self._in_hand_start is not None:
                pending.append(self._in_hand_start)
            for item in self._in_hand:
                if isinstance(item, _Call) and item is self._in_hand[0] and worker.busy_stage == _CALL_STAGE:
                    item.error = KinemaError(f"the tick thread was abandoned in it: {stuck.describe(0.0)}")
                    item.done.set()
                else:
                    pending.append(item)
            self._in_hand, self._in_hand_start = [], None
            with self._wake:
                self._inbox.extendleft(reversed(pending))
                self._woken = True
                self._wake.notify_all()
            self._start_worker()
        finally:
            self._state_lock.release()

    # -- tick thread ------------------------------------------------------------------------------

    def _loop(self, worker: TickWorker) -> None:
        next_tick = time.monotonic()
        while True:
            with self._wake:
                if self._tree is not None and self._tree.retick_due:
                    # A tree that re-ticks itself used up a whole tick: before the tick it owes, give
                    # the process's other threads (the transport, a simulator) the interpreter for a
                    # moment, unless a request already waits.
                    timeout: float | None = 0.0
                    if not self._inbox and not self._stopping:
                        self._pause(RETICK_PAUSE_S)
                elif self._tree is not None:
                    timeout = max(0.0, next_tick - time.monotonic())
                elif self._ended_at is not None:
                    timeout = max(0.0, self._ended_at + self._result_hold - time.monotonic())
                else:
                    timeout = None
                if not self._woken and not self._stopping and (timeout is None or timeout > 0):
                    self._pause(timeout)
                self._woken = False
                self._interrupt = False
                tick_now, self._tick_now = self._tick_now, False
                stopping = self._stopping
                inbox = list(self._inbox)
                self._inbox.clear()
                # Taken: the requests are being served now (a halt they need counts again as waiting).
                if not stopping:
                    self._waiting_since = None
            if stopping:
                self._finish_current(worker, ObjectiveResult.failure, self._stop_reason)
                for item in inbox:
                    self._reject(item, self._stop_reason)
                self._stopped.set()
                return
            start = self._take_requests(worker, inbox)
            if start is not None:
                self._load(worker, start)
                next_tick = time.monotonic()
            if self._run_stuck is not None and self._run is not None:
                # A stuck run that no request ended (a cancel of another run): it can never tick again.
                self._finish_current(worker, ObjectiveResult.preempted, "its tick thread was abandoned")
            if (
                self._tree is None
                and self._ended_at is not None
                and time.monotonic() >= self._ended_at + self._result_hold
            ):
                self._ended_at = None
                self._set_status(ObjectiveStatus.IDLE, self._status[1])
            tree = self._tree
            if tree is not None and (tick_now or tree.retick_due or time.monotonic() >= next_tick - 1e-4):
                next_tick += self._period
                now = time.monotonic()
                if next_tick < now:
                    # Fell behind (a slow tick): do not try to catch up with a burst of ticks.
                    next_tick = now + self._period
                self._tick(worker)

    def _pause(self, seconds: float | None) -> None:
        """Wait on the request condition (its lock held) without the state lock; a request ends it.

        The state lock is taken back before the condition's (never wait for it holding the other).
        """
        self._state_lock.release()
        try:
            self._wake.wait(seconds)
        finally:
            self._wake.release()
            self._state_lock.acquire()
            self._wake.acquire()

    def _reject(self, item: ObjectiveRun | _Cancel | _Call, reason: str) -> None:
        if isinstance(item, ObjectiveRun):
            item._finish(ObjectiveResult.failure(reason, item.objective_name))
        elif isinstance(item, _Cancel):
            item.ack.set()
        else:
            item.error = KinemaError(reason)
            item.done.set()

    def _take_requests(
        self, worker: TickWorker, inbox: list[ObjectiveRun | _Cancel | _Call]
    ) -> ObjectiveRun | None:
        """Apply queued requests in order; returns the newest start request still wanted.

        Of a burst of start requests only the last one is built: each earlier one is preempted by the
        next without ever being loaded, which keeps a flood of requests cheap.
        """
        start: ObjectiveRun | None = None
        for index, item in enumerate(inbox):
            self._in_hand, self._in_hand_start = inbox[index:], start
            if isinstance(item, ObjectiveRun):
                if start is not None:
                    start._finish(
                        ObjectiveResult.preempted(
                            "preempted by a newer objective request", start.objective_name
                        )
                    )
                start = item
            elif isinstance(item, _Cancel):
                make = ObjectiveResult.failure if item.failure else ObjectiveResult.preempted
                if start is not None and (item.run is None or item.run is start) and not item.failure:
                    start._finish(make(item.reason, start.objective_name))
                    start = None
                    item.cancelled = True
                if self._run is not None and (item.run is None or item.run is self._run):
                    self._finish_current(worker, make, item.reason)
                    item.cancelled = True
                item.ack.set()
            else:
                try:
                    with self._behavior_code(worker, _CALL_STAGE):
                        item.value = item.fn()
                except Abandoned:
                    raise
                except BaseException as error:
                    item.error = error
                item.done.set()
        self._in_hand, self._in_hand_start = [], start
        return start

    def _set_status(self, status: ObjectiveStatus, name: str) -> None:
        if self._status == (status, name):
            return
        self._status = (status, name)
        self._tell_status(status, name)

    def _tell_status(self, status: ObjectiveStatus, name: str) -> None:
        for listener in self._listeners:
            try:
                listener.on_status(status, name)
            except Exception:
                log.exception("a status listener raised")

    def _load(self, worker: TickWorker, run: ObjectiveRun) -> None:
        """Build the tree of ``run`` (preempting what runs now) and apply its overrides."""
        if self._run is not None:
            self._finish_current(worker, ObjectiveResult.preempted, "preempted by a newer objective request")
        self._run = run
        self._in_hand_start = None
        self._set_status(ObjectiveStatus.LOADING, run.objective_name)
        try:
            with self._behavior_code(worker, "building the tree"):
                tree, name, model = self._build(run.request)
                run.objective_name = name
                defaults = model_defaults(model)
                declared = tuple(model.ports) if model is not None else ()
                apply_overrides(
                    tree, run.request.overrides, objective_name=name, defaults=defaults, parameters=declared
                )
                given = {o.name for o in (*defaults, *run.request.overrides)}
                run.unset_parameters = tuple(p for p in declared if p not in given)
        except Abandoned:
            raise
        except KinemaError as error:
            self._end(run, ObjectiveResult.failure(str(error), run.objective_name), ObjectiveStatus.FAILURE)
            return
        except BaseException as error:  # a behavior's constructor raised: report it, keep serving
            log.exception("building objective %r failed", run.objective_name)
            message = (
                f"building objective {run.objective_name!r} failed: {type(error).__name__}: {error}"
                f"{_location_of(error)}"
            )
            self._end(run, ObjectiveResult.failure(message, run.objective_name), ObjectiveStatus.FAILURE)
            return
        run.release_xml()
        stale_note = getattr(self._source, "stale_note", None)
        run.stale_note = stale_note(tree) if stale_note is not None else ""
        self._tree = tree
        self._recorder.detach()
        self._recorder = NodeStatusRecorder()
        with self._notes_lock:
            self._failure_notes = {}
        self._last_snapshot = 0.0
        self._recorder.attach(tree)
        tree.wake_up.listener = self._wake_up
        for listener in self._listeners:
            loaded = getattr(listener, "on_tree_loaded", None)
            if loaded is not None:
                try:
                    loaded(name, tree)
                except Exception:
                    log.exception("a tree listener raised")
            stale = getattr(listener, "on_stale_code", None)
            if stale is not None and run.stale_note:
                try:
                    stale(run, run.stale_note)
                except Exception:
                    log.exception("a listener raised on a stale-code note")
        self._set_status(ObjectiveStatus.RUNNING, name)

    def _build(self, request: ObjectiveRequest) -> tuple[Tree, str, SubtreeModel | None]:
        """The tree of ``request``, its objective's name, and the model of its ports (None if undeclared).

        A SubTree whose objective is in the library but did not load fails the build with that objective's
        own reason, not with "Can't find a tree".
        """
        try:
            return self._build_tree(request)
        except TreeNotFoundError as error:
            explain = getattr(self._source, "load_error", None)
            reason = explain(error.tree_id) if explain is not None else None
            if not reason:
                raise
            name = request.objective_name or main_tree_id(request.objective_xml)
            raise ObjectiveError(
                f"objective {name!r} cannot run: its SubTree {error.tree_id!r} did not load: {reason}",
                location=error.location,
            ) from None

    def _build_tree(self, request: ObjectiveRequest) -> tuple[Tree, str, SubtreeModel | None]:
        factory = self._source.factory()
        if request.objective_name:
            names = self._source.objective_names()
            reread = getattr(self._source, "invalidate_objectives", None)
            if request.objective_name not in names and reread is not None:
                # A file saved a moment ago: hot reload reports a burst of changes only once the folder
                # has been quiet for a while. Read the objective files again before calling it unknown.
                reread()
                factory = self._source.factory()
                names = self._source.objective_names()
            if request.objective_name not in names:
                explain = getattr(self._source, "load_error", None)
                problem = explain(request.objective_name) if explain is not None else None
                if problem:
                    raise ObjectiveError(f"objective {request.objective_name!r} cannot run: {problem}")
                alternatives = did_you_mean(request.objective_name, names)
                restart = getattr(self._source, "restart_note", "")
                note = f"\nnote: {restart}" if restart else ""
                raise ObjectiveError(f"unknown objective {request.objective_name!r}; {alternatives}{note}")
            tree = factory.create_tree(request.objective_name)
            return tree, request.objective_name, factory.library.subtree_models.get(request.objective_name)
        xml = request.objective_xml
        if not xml.strip():
            raise ObjectiveError("the request names no objective and carries no objective XML")
        # An ASCII string's length is its UTF-8 size (isascii is a flag check): no copy of a 50 MB request.
        size = len(xml) if xml.isascii() else len(xml.encode("utf-8", "surrogatepass"))
        if size > MAX_OBJECTIVE_XML_BYTES:
            limit = MAX_OBJECTIVE_XML_BYTES / 1e6
            raise ObjectiveError(f"the objective XML is {size / 1e6:.1f} MB; the limit is {limit:.1f} MB")
        return _create_from_scratch_text(factory, xml)

    def _tick(self, worker: TickWorker) -> None:
        tree, run = self._tree, self._run
        assert tree is not None and run is not None
        deadline = time.monotonic() + self._period

        def interrupted() -> bool:
            # Checked between the iterations of a tree that re-ticks itself: serve a request, or let
            # the server publish and breathe once a tick period is used up.
            return self._interrupt or time.monotonic() >= deadline

        try:
            with self._behavior_code(worker, "tick"):
                status = tree.tick_once(interrupted)
        except Abandoned:
            raise
        except KinemaError as error:
            self._halt_quietly(worker, tree)
            message = _with_parameter_advice(str(error), run)
            self._end(run, ObjectiveResult.failure(message, run.objective_name), ObjectiveStatus.FAILURE)
            return
        except BaseException as error:  # SystemExit, KeyboardInterrupt...: fail the run, keep serving
            log.error("ticking objective %r raised", run.objective_name, exc_info=error)
            self._halt_quietly(worker, tree)
            where = _location_of(error)
            message = f"objective {run.objective_name!r} raised {type(error).__name__}: {error}{where}"
            self._end(run, ObjectiveResult.failure(message, run.objective_name), ObjectiveStatus.FAILURE)
            return
        if status is NodeStatus.SUCCESS:
            self._end(run, ObjectiveResult.success(run.objective_name), ObjectiveStatus.SUCCESS, tree)
        elif status is NodeStatus.FAILURE:
            failure = ObjectiveResult.failure(self._failure_message(run), run.objective_name)
            self._end(run, failure, ObjectiveStatus.FAILURE, tree)
        else:
            run._first_tick_returned()
            self._flush_node_changes(run)
            self._maybe_snapshot(run, tree, force=False)

    def _halt_quietly(self, worker: TickWorker, tree: Tree) -> None:
        try:
            with self._behavior_code(worker, "halt"):
                tree.halt_tree()
        except Abandoned:
            raise
        except BaseException:
            log.exception("halting the tree raised")

    def _finish_current(
        self, worker: TickWorker, make: Callable[[str, str], ObjectiveResult], reason: str
    ) -> None:
        run, tree, stuck = self._run, self._tree, self._run_stuck
        if run is None:
            return
        if stuck is not None:
            # Its tick thread was abandoned in behavior code: never wait for that tree again.
            if tree is not None:
                release_stuck_tree(tree, stuck)
            code = stuck.stuck or StuckCode("", "", stuck.busy_stage)
            seconds = time.monotonic() - stuck.stuck_since
            reason = f"{reason} ({code.describe(seconds)}; its tick thread was abandoned)"
        elif tree is not None:
            # A cancel, a newer request or a stop waits for this halt: the watchdog gives it as long
            # as it gives a pending request.
            with self._wake:
                if self._waiting_since is None:
                    self._waiting_since = time.monotonic()
            self._halt_quietly(worker, tree)
            with self._wake:
                waiting = any(not isinstance(item, _Call) for item in self._inbox) or self._stopping
                self._waiting_since = time.monotonic() if waiting else None
            self._flush_node_changes(run)
        result = make(reason, run.objective_name)
        self._end(run, result, ObjectiveStatus.CANCELLED if result.cancelled else ObjectiveStatus.FAILURE)

    def _end(
        self,
        run: ObjectiveRun,
        result: ObjectiveResult,
        status: ObjectiveStatus,
        completed: Tree | None = None,
    ) -> None:
        """End ``run``: the listeners are handed the last blackboard (of ``completed``, the tree that
        returned SUCCESS or FAILURE), then its clients get the result (its done callbacks), then the
        listeners hear the status changes, the last tick's node changes and the result;
        :meth:`ObjectiveRun.wait` returns after them.

        The blackboard goes first, and a listener with ``settle_blackboard()`` publishes it before the
        client is answered, so that a client that asks for the latched snapshot once its ``execute``
        returned sees this run's, not the one before (handed to a worker, it went out only after the
        worker's wake, and a loaded machine answered the client first)."""
        result = run._settle(result)
        if result.cancelled and status is ObjectiveStatus.SUCCESS:
            status = ObjectiveStatus.CANCELLED
        if run.stale_note and not result.succeeded:
            # The exception may come from code no longer in the file: say that the file did not load.
            result = replace(result, error_message=f"{result.error_message}\nnote: {run.stale_note}")
        self._tree = None
        self._run_stuck = None
        self._run = None
        self._ended_at = time.monotonic()
        told = self._status == (status, run.objective_name)
        self._status = (status, run.objective_name)
        if completed is not None:
            self._maybe_snapshot(run, completed, force=True)
            for listener in self._listeners:
                settle = getattr(listener, "settle_blackboard", None)
                if settle is not None:
                    try:
                        settle()
                    except Exception:
                        log.exception("a blackboard listener raised")
        answered = run._answer(result)
        try:
            if completed is not None:
                self._flush_node_changes(run)
            if not told:
                self._tell_status(status, run.objective_name)
            if answered:
                for listener in self._listeners:
                    try:
                        listener.on_run_finished(run, result)
                    except Exception:
                        log.exception("a run listener raised")
        finally:
            run._release()

    # -- observation (tick thread) --------------------------------------------------------------

    def _flush_node_changes(self, run: ObjectiveRun) -> None:
        changes = self._recorder.take()
        if changes is None:
            return
        for listener in self._listeners:
            try:
                listener.on_node_status(run.objective_name, changes)
            except Exception:
                log.exception("a node status listener raised")

    def _maybe_snapshot(self, run: ObjectiveRun, tree: Tree, *, force: bool) -> None:
        if self._blackboard_period <= 0:
            return
        now = time.monotonic()
        if not force and now - self._last_snapshot < self._blackboard_period:
            return
        self._last_snapshot = now
        entries = blackboard_entries(tree)
        for listener in self._listeners:
            try:
                listener.on_blackboard(run.objective_name, entries)
            except Exception:
                log.exception("a blackboard listener raised")

    def _failure_message(self, run: ObjectiveRun) -> str:
        failure = self._recorder.last_failure
        if failure is None:
            return f"objective {run.objective_name!r} returned FAILURE"
        path, registration_id = failure
        with self._notes_lock:
            message = self._failure_notes.get(path, "")
        detail = f": {message}" if message else " returned FAILURE"
        text = f"objective {run.objective_name!r} failed: node '{path}' [{registration_id}]{detail}"
        return _with_parameter_advice(text, run)


def _with_parameter_advice(message: str, run: ObjectiveRun) -> str:
    """``message`` led by what to do when it is a missing blackboard key that is one of the objective's own
    ports with no default and no override (the node's own words follow, for where); else ``message``."""
    if "unable to find the key" not in message:
        return message
    for name in run.unset_parameters:
        if f"[{name}]" in message:  # "... the key [port] remapped to [name]"
            return (
                f"{name!r} is a parameter of objective {run.objective_name!r} without a default: give it "
                f"(kinema objective run {run.objective_name!r} -p {name}=VALUE, or the SDK's overrides). "
                f"Where it was missed: {message}"
            )
    return message


def main_tree_id(xml: str) -> str:
    """The ID of the tree an XML document runs (``main_tree_to_execute``, or its only BehaviorTree).

    Raises:
        ObjectiveError: the text is not XML, or names no tree to run.
    """
    from kinema.bt.xmlsource import parse_xml

    return _main_tree_of(parse_xml(xml, _XML_NAME))


def _main_tree_of(root: etree._Element) -> str:
    """:func:`main_tree_id` of a parsed document."""
    main = root.get("main_tree_to_execute")
    if main:
        return main
    ids = [element.get("ID", "") for element in root.iter("BehaviorTree")]
    if len(ids) == 1 and ids[0]:
        return ids[0]
    if not ids:
        raise ObjectiveError("the objective XML has no <BehaviorTree>")
    raise ObjectiveError(
        f"the objective XML has {len(ids)} BehaviorTrees ({', '.join(ids)}) and no main_tree_to_execute"
    )


def blackboard_entries(tree: Tree) -> list[tuple[str, str, str, Any]]:
    """``(scope, key, type_name, value)`` of every entry of a tree, subtree scopes included."""
    snapshot = tree.blackboard_snapshot()
    entries: list[tuple[str, str, str, Any]] = []
    for scope, values in snapshot.items():
        for key, (type_name, value) in values.items():
            entries.append((scope, key, type_name, value))
    return entries


def _create_from_scratch_text(
    factory: BehaviorTreeFactory, xml: str
) -> tuple[Tree, str, SubtreeModel | None]:
    """Build the main tree of an ad-hoc XML document (:func:`main_tree_id`) without adding its trees to
    ``factory``; with its name and the model of its ports, as the document and the library declare it.
    The document is parsed once (the library keeps the parse of a text it loaded recently).

    An XML string sent to ``/do_objective`` may define trees named like library objectives; they must
    shadow the library for this run only, never replace it for later runs.
    """
    saved = factory.library
    scratch = copy.copy(saved)
    scratch.trees = dict(saved.trees)
    scratch.node_models = dict(saved.node_models)
    # Models are updated in place when a document declares ports for a known SubTree.
    scratch.subtree_models = (
        copy.deepcopy(saved.subtree_models) if "TreeNodesModel" in xml else dict(saved.subtree_models)
    )
    factory.library = scratch
    try:
        name = _main_tree_of(factory.register_behavior_tree_from_text(xml, filename=_XML_NAME))
        return factory.create_tree(name), name, scratch.subtree_models.get(name)
    finally:
        factory.library = saved


def _location_of(error: BaseException) -> str:
    """`` at file:line`` of the author's code that raised ``error`` ("" when none is outside Kinema)."""
    from kinema.behaviors.faults import author_location

    location = author_location(error)
    return f" at {location}" if location is not None else ""
