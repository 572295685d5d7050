"""The objective server: one objective at a time, ticked at a fixed rate by one thread.

Everything that wants to change what runs (an SDK call, ``/do_objective``, ``/cancel_objective``, a
hot reload) sends the tick thread a request; only the tick thread builds, ticks and halts the Tree
(DESIGN invariant 1). A cancel or a newer request wakes the tick thread at once, so running behaviors
are halted well within one tick period (invariant 2).

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
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, NamedTuple, Protocol

from kinema.bt.node import node_children
from kinema.bt.status import NodeStatus
from kinema.errors import KinemaError, ObjectiveError, did_you_mean
from kinema.runtime.objective_status import ObjectiveStatus
from kinema.runtime.overrides import ParameterOverride, apply_overrides
from kinema.runtime.result import ObjectiveResult

if TYPE_CHECKING:
    from kinema.bt import BehaviorTreeFactory, Tree

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


class NodeStatusChange(NamedTuple):
    """One node of the running tree changed status (published as kinema_msgs/NodeStatusChange).

    A named tuple: one is made per status transition on the tick thread (thousands per tick in a
    large tree), and a tuple is built several times faster than a frozen dataclass.
    """

    timestamp: float
    uid: int
    node_path: str
    node_id: str
    node_name: str
    previous: int
    status: int


class ServerListener(Protocol):
    """Receives what happens in the server. Every method runs on the tick thread and must not block."""

    def on_status(self, status: ObjectiveStatus, objective_name: str) -> None:
        """The server's status changed (Idle, Loading, Running, Success, Failure, Cancelled)."""

    def on_node_status(self, objective_name: str, changes: list[NodeStatusChange]) -> None:
        """Nodes changed status during one tick."""

    def on_blackboard(self, objective_name: str, entries: list[tuple[str, str, str, Any]]) -> None:
        """A blackboard snapshot: ``(scope, key, type_name, value)`` for every entry (throttled)."""

    def on_run_finished(self, run: ObjectiveRun, result: ObjectiveResult) -> None:
        """A run ended (succeeded, failed, was cancelled or preempted)."""


class ObjectiveRun:
    """A submitted request and, once it ends, its result. Thread-safe; returned by ``submit``."""

    def __init__(self, run_id: int, request: ObjectiveRequest, server: ObjectiveServer) -> None:
        self.id = run_id
        self.request = request
        self.objective_name = request.label
        self._server = server
        self._done = threading.Event()
        self._result: ObjectiveResult | None = None
        self._callbacks: list[Callable[[ObjectiveResult], None]] = []
        self._lock = threading.Lock()

    @property
    def done(self) -> bool:
        """True once the run ended."""
        return self._done.is_set()

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

    def release_xml(self) -> None:
        """Let go of the request's objective XML (up to MAX_OBJECTIVE_XML_BYTES, or a larger refused
        one): it is not needed once the tree is built or the run ended, and the tick thread may keep
        the run referenced while it waits for the next request."""
        if self.request.objective_xml:
            self.request = replace(self.request, objective_xml="")

    def _finish(self, result: ObjectiveResult) -> bool:
        self.release_xml()
        with self._lock:
            if self._result is not None:
                return False
            self._result = result
            callbacks, self._callbacks = self._callbacks, []
        self._done.set()
        for callback in callbacks:
            try:
                callback(result)
            except Exception:
                log.exception("a done callback of objective run %d raised", self.id)
        return True

    def __repr__(self) -> str:
        return f"ObjectiveRun({self.id}, {self.objective_name!r}, result={self._result})"


@dataclass
class _Cancel:
    run: ObjectiveRun | None  # None: whatever runs now
    reason: str
    ack: threading.Event = field(default_factory=threading.Event)
    cancelled: bool = False


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


class ObjectiveServer:
    """Runs one objective at a time on its own tick thread.

    Args:
        source: where trees come from (a factory and the names of the runnable objectives).
        tick_rate_hz: ticks per second while an objective runs (100 Hz, as MoveIt Pro's server).
        listeners: receive status, node status changes, blackboard snapshots and results.
        blackboard_period_s: the minimum time between two blackboard snapshots (0 disables them).
        result_hold_s: how long a run's final status is shown before the server reports Idle again.
    """

    def __init__(
        self,
        source: TreeSource,
        *,
        tick_rate_hz: float = DEFAULT_TICK_RATE_HZ,
        listeners: Sequence[ServerListener] = (),
        blackboard_period_s: float = BLACKBOARD_SNAPSHOT_PERIOD_S,
        result_hold_s: float = RESULT_HOLD_S,
    ) -> None:
        if tick_rate_hz <= 0:
            raise KinemaError(f"the tick rate must be positive, got {tick_rate_hz} Hz")
        self._source = source
        self._period = 1.0 / tick_rate_hz
        self._listeners = list(listeners)
        self._blackboard_period = blackboard_period_s
        self._ids = itertools.count(1)
        self._inbox: deque[ObjectiveRun | _Cancel | _Call] = deque()
        self._wake = threading.Condition()
        self._woken = False
        self._tick_now = False
        self._stopping = False
        self._thread: threading.Thread | None = None
        # Owned by the tick thread:
        self._tree: Tree | None = None
        self._run: ObjectiveRun | None = None
        self._pending_changes: list[NodeStatusChange] = []
        self._last_snapshot = 0.0
        self._failures: list[tuple[str, str]] = []
        self._failure_notes: dict[str, str] = {}
        self._notes_lock = threading.Lock()
        # Read by any thread (a consistent pair, replaced atomically):
        self._status: tuple[ObjectiveStatus, str] = (ObjectiveStatus.IDLE, "")
        self._result_hold = result_hold_s
        self._ended_at: float | None = None

    # -- lifecycle --------------------------------------------------------------------------------

    def start(self) -> None:
        """Start the tick thread."""
        if self._thread is not None:
            return
        self._thread = threading.Thread(target=self._loop, name="kinema-tick", daemon=True)
        self._thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        """Halt the running objective (its result is PREEMPTED) and stop the tick thread."""
        with self._wake:
            self._stopping = True
            self._woken = True
            self._wake.notify()
        if self._thread is not None:
            self._thread.join(timeout)
            self._thread = None

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

    # -- requests (any thread) ------------------------------------------------------------------

    @property
    def status(self) -> tuple[ObjectiveStatus, str]:
        """``(status, objective_name)`` right now."""
        return self._status

    def submit(self, request: ObjectiveRequest) -> ObjectiveRun:
        """Queue ``request``; the running objective (if any) is preempted when the tick thread takes it."""
        run = ObjectiveRun(next(self._ids), request, self)
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
        request = _Cancel(run, reason)
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
        if threading.current_thread() is self._thread or self._thread is None:
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
            self._wake.notify()

    def _wake_up(self) -> None:
        # A tree's wake-up signal (a behavior finished its work off-thread): tick again at once.
        with self._wake:
            self._woken = True
            self._tick_now = True
            self._wake.notify()

    def note_failure(self, node_path: str, message: str) -> None:
        """Remember why a node is failing (a behavior's ``publish_failure``), for the run's error message.

        Safe from any thread; notes are cleared when the next objective loads.
        """
        with self._notes_lock:
            self._failure_notes[node_path] = message

    # -- tick thread ------------------------------------------------------------------------------

    def _loop(self) -> None:
        next_tick = time.monotonic()
        while True:
            with self._wake:
                if self._tree is not None:
                    timeout: float | None = max(0.0, next_tick - time.monotonic())
                elif self._ended_at is not None:
                    timeout = max(0.0, self._ended_at + self._result_hold - time.monotonic())
                else:
                    timeout = None
                if not self._woken and not self._stopping and (timeout is None or timeout > 0):
                    self._wake.wait(timeout)
                self._woken = False
                tick_now, self._tick_now = self._tick_now, False
                stopping = self._stopping
                inbox = list(self._inbox)
                self._inbox.clear()
            if stopping:
                self._finish_current(ObjectiveResult.preempted, "the objective server stopped")
                for item in inbox:
                    self._reject(item, "the objective server stopped")
                return
            start = self._take_requests(inbox)
            if start is not None:
                self._load(start)
                next_tick = time.monotonic()
            elif (
                self._tree is None
                and self._ended_at is not None
                and time.monotonic() >= self._ended_at + self._result_hold
            ):
                self._ended_at = None
                self._set_status(ObjectiveStatus.IDLE, self._status[1])
            if self._tree is not None and (tick_now or time.monotonic() >= next_tick - 1e-4):
                next_tick += self._period
                now = time.monotonic()
                if next_tick < now:
                    # Fell behind (a slow tick): do not try to catch up with a burst of ticks.
                    next_tick = now + self._period
                self._tick()

    def _reject(self, item: ObjectiveRun | _Cancel | _Call, reason: str) -> None:
        if isinstance(item, ObjectiveRun):
            item._finish(ObjectiveResult.preempted(reason, item.objective_name))
        elif isinstance(item, _Cancel):
            item.ack.set()
        else:
            item.error = KinemaError(reason)
            item.done.set()

    def _take_requests(self, inbox: list[ObjectiveRun | _Cancel | _Call]) -> ObjectiveRun | None:
        """Apply queued requests in order; returns the newest start request still wanted.

        Of a burst of start requests only the last one is built: each earlier one is preempted by the
        next without ever being loaded, which keeps a flood of requests cheap.
        """
        start: ObjectiveRun | None = None
        for item in inbox:
            if isinstance(item, ObjectiveRun):
                if start is not None:
                    start._finish(
                        ObjectiveResult.preempted(
                            "preempted by a newer objective request", start.objective_name
                        )
                    )
                start = item
            elif isinstance(item, _Cancel):
                if start is not None and (item.run is None or item.run is start):
                    start._finish(ObjectiveResult.preempted(item.reason, start.objective_name))
                    start = None
                    item.cancelled = True
                if self._run is not None and (item.run is None or item.run is self._run):
                    self._finish_current(ObjectiveResult.preempted, item.reason)
                    item.cancelled = True
                item.ack.set()
            else:
                try:
                    item.value = item.fn()
                except BaseException as error:
                    item.error = error
                item.done.set()
        return start

    def _set_status(self, status: ObjectiveStatus, name: str) -> None:
        if self._status == (status, name):
            return
        self._status = (status, name)
        for listener in self._listeners:
            try:
                listener.on_status(status, name)
            except Exception:
                log.exception("a status listener raised")

    def _load(self, run: ObjectiveRun) -> None:
        """Build the tree of ``run`` (preempting what runs now) and apply its overrides."""
        if self._run is not None:
            self._finish_current(ObjectiveResult.preempted, "preempted by a newer objective request")
        self._run = run
        self._set_status(ObjectiveStatus.LOADING, run.objective_name)
        try:
            tree, name = self._build(run.request)
            run.objective_name = name
            apply_overrides(tree, run.request.overrides, objective_name=name)
        except KinemaError as error:
            self._end(run, ObjectiveResult.failure(str(error), run.objective_name), ObjectiveStatus.FAILURE)
            return
        except Exception as error:  # a behavior's constructor raised: report it, keep serving
            log.exception("building objective %r failed", run.objective_name)
            message = f"building objective {run.objective_name!r} failed: {type(error).__name__}: {error}"
            self._end(run, ObjectiveResult.failure(message, run.objective_name), ObjectiveStatus.FAILURE)
            return
        run.release_xml()
        self._tree = tree
        self._failures = []
        with self._notes_lock:
            self._failure_notes = {}
        self._pending_changes = []
        self._last_snapshot = 0.0
        tree.add_status_observer(self._on_node_status)
        tree.wake_up.listener = self._wake_up
        self._set_status(ObjectiveStatus.RUNNING, name)

    def _build(self, request: ObjectiveRequest) -> tuple[Tree, str]:
        factory = self._source.factory()
        if request.objective_name:
            names = self._source.objective_names()
            if request.objective_name not in names:
                explain = getattr(self._source, "load_error", None)
                problem = explain(request.objective_name) if explain is not None else None
                if problem:
                    raise ObjectiveError(f"objective {request.objective_name!r} cannot run: {problem}")
                alternatives = did_you_mean(request.objective_name, names)
                raise ObjectiveError(f"unknown objective {request.objective_name!r}; {alternatives}")
            return factory.create_tree(request.objective_name), request.objective_name
        xml = request.objective_xml
        if not xml.strip():
            raise ObjectiveError("the request names no objective and carries no objective XML")
        size = len(xml.encode("utf-8", "surrogatepass"))
        if size > MAX_OBJECTIVE_XML_BYTES:
            limit = MAX_OBJECTIVE_XML_BYTES / 1e6
            raise ObjectiveError(f"the objective XML is {size / 1e6:.1f} MB; the limit is {limit:.1f} MB")
        name = main_tree_id(xml)
        return _create_from_scratch_text(factory, xml), name

    def _tick(self) -> None:
        tree, run = self._tree, self._run
        assert tree is not None and run is not None
        try:
            status = tree.tick_once()
        except KinemaError as error:
            self._halt_quietly(tree)
            self._end(run, ObjectiveResult.failure(str(error), run.objective_name), ObjectiveStatus.FAILURE)
            return
        except Exception as error:
            log.exception("ticking objective %r raised", run.objective_name)
            self._halt_quietly(tree)
            message = f"objective {run.objective_name!r} raised {type(error).__name__}: {error}"
            self._end(run, ObjectiveResult.failure(message, run.objective_name), ObjectiveStatus.FAILURE)
            return
        self._flush_node_changes(run)
        self._maybe_snapshot(run, force=status.is_completed)
        if status is NodeStatus.SUCCESS:
            self._end(run, ObjectiveResult.success(run.objective_name), ObjectiveStatus.SUCCESS)
        elif status is NodeStatus.FAILURE:
            self._end(
                run,
                ObjectiveResult.failure(self._failure_message(run), run.objective_name),
                ObjectiveStatus.FAILURE,
            )

    def _halt_quietly(self, tree: Tree) -> None:
        try:
            tree.halt_tree()
        except Exception:
            log.exception("halting the tree raised")

    def _finish_current(self, make: Callable[[str, str], ObjectiveResult], reason: str) -> None:
        run, tree = self._run, self._tree
        if run is None:
            return
        if tree is not None:
            self._halt_quietly(tree)
            self._flush_node_changes(run)
        self._end(run, make(reason, run.objective_name), ObjectiveStatus.CANCELLED)

    def _end(self, run: ObjectiveRun, result: ObjectiveResult, status: ObjectiveStatus) -> None:
        self._tree = None
        self._run = None
        self._ended_at = time.monotonic()
        self._set_status(status, run.objective_name)
        if run._finish(result):
            for listener in self._listeners:
                try:
                    listener.on_run_finished(run, result)
                except Exception:
                    log.exception("a run listener raised")

    # -- observation (tick thread) --------------------------------------------------------------

    def _on_node_status(self, timestamp: float, node: Any, previous: Any, status: Any) -> None:
        path = node.full_path
        self._pending_changes.append(
            NodeStatusChange(
                timestamp, int(node.uid), path, node.registration_id, node.name, int(previous), int(status)
            )
        )
        if status is NodeStatus.FAILURE and not node_children(node):
            self._failures.append((path, node.registration_id))

    def _flush_node_changes(self, run: ObjectiveRun) -> None:
        if not self._pending_changes:
            return
        changes, self._pending_changes = self._pending_changes, []
        for listener in self._listeners:
            try:
                listener.on_node_status(run.objective_name, changes)
            except Exception:
                log.exception("a node status listener raised")

    def _maybe_snapshot(self, run: ObjectiveRun, *, force: bool) -> None:
        if self._blackboard_period <= 0 or self._tree is None:
            return
        now = time.monotonic()
        if not force and now - self._last_snapshot < self._blackboard_period:
            return
        self._last_snapshot = now
        entries = blackboard_entries(self._tree)
        for listener in self._listeners:
            try:
                listener.on_blackboard(run.objective_name, entries)
            except Exception:
                log.exception("a blackboard listener raised")

    def _failure_message(self, run: ObjectiveRun) -> str:
        if not self._failures:
            return f"objective {run.objective_name!r} returned FAILURE"
        path, registration_id = self._failures[-1]
        with self._notes_lock:
            message = self._failure_notes.get(path, "")
        detail = f": {message}" if message else " returned FAILURE"
        return f"objective {run.objective_name!r} failed: node '{path}' [{registration_id}]{detail}"


def main_tree_id(xml: str) -> str:
    """The ID of the tree an XML document runs (``main_tree_to_execute``, or its only BehaviorTree).

    Raises:
        ObjectiveError: the text is not XML, or names no tree to run.
    """
    from kinema.bt.xmlsource import parse_xml

    root = parse_xml(xml, "<objective XML>")
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


def _create_from_scratch_text(factory: BehaviorTreeFactory, xml: str) -> Tree:
    """Build the main tree of an ad-hoc XML document without adding its trees to ``factory``.

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
        return factory.create_tree_from_text(xml, filename="<objective XML>")
    finally:
        factory.library = saved
