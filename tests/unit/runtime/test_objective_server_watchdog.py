"""Cancel always wins: self-re-ticking trees, behavior code that never returns, BaseExceptions, dead
threads."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator

import pytest

from kinema.behaviors import AsyncBehavior, NodeStatus, SyncBehavior
from kinema.behaviors.context import BehaviorContext
from kinema.runtime.objective_server import (
    FactoryTreeSource,
    ObjectiveRequest,
    ObjectiveRun,
    ObjectiveServer,
)
from kinema.runtime.objective_status import ObjectiveStatus
from kinema.runtime.result import ObjectiveResult
from kinema.testing.harness import registry_of

SPIN = (
    '<root BTCPP_format="4"><BehaviorTree ID="Spin">'
    '<Repeat num_cycles="-1"><AlwaysSuccess/></Repeat></BehaviorTree></root>'
)
COUNTING_SPIN = SPIN.replace("<AlwaysSuccess/>", "<Counts/>")
QUICK = '<root BTCPP_format="4"><BehaviorTree ID="Quick"><AlwaysSuccess/></BehaviorTree></root>'
RELEASE = threading.Event()
# Set by a behavior once it is inside the call that blocks (or the work that runs until halted): the test
# acts on the stuck tree from then on, not after a guessed delay.
STUCK = threading.Event()
TICKS: list[int] = []
# Longer than any served cancel, far shorter than the 30 s a stuck behavior blocks here.
LATE = 2.0


class BlockingTick(SyncBehavior):
    """Blocks in tick until the test releases it (a careless author's socket read)."""

    def tick(self) -> NodeStatus:
        STUCK.set()
        RELEASE.wait(30)
        return NodeStatus.SUCCESS


class Counts(SyncBehavior):
    """Succeeds at once, counting its ticks (a Repeat of it re-ticks without end)."""

    def tick(self) -> NodeStatus:
        TICKS.append(1)
        return NodeStatus.SUCCESS


class BlockingHalt(AsyncBehavior):
    """Work that runs until halted; its do_halt then blocks."""

    def do_work(self) -> bool:
        STUCK.set()
        while not self.stop_requested():
            time.sleep(0.01)
        return True

    def do_halt(self) -> None:
        RELEASE.wait(30)


class IgnoresHalt(AsyncBehavior):
    """A plain-function do_work that never looks at stop_requested()."""

    def do_work(self) -> bool:
        STUCK.set()
        RELEASE.wait(30)
        return True


EVENTS: list[str] = []


class Moves(AsyncBehavior):
    """Stands for a motion: runs until halted, and records the halt."""

    def do_work(self) -> bool:
        while not self.stop_requested():
            time.sleep(0.005)
        return True

    def do_halt(self) -> None:
        EVENTS.append("motion halted")


class Records(SyncBehavior):
    def tick(self) -> NodeStatus:
        EVENTS.append("ticked after the stuck node")
        return NodeStatus.SUCCESS


class BlocksTheLoop(AsyncBehavior):
    """An ``async def`` that blocks instead of awaiting: every async behavior of the process stalls."""

    async def do_work(self) -> bool:
        RELEASE.wait(30)
        return True


class Exits(SyncBehavior):
    def tick(self) -> NodeStatus:
        raise SystemExit(3)


class Interrupted(SyncBehavior):
    def tick(self) -> NodeStatus:
        raise KeyboardInterrupt


class GeneratorExits(SyncBehavior):
    def tick(self) -> NodeStatus:
        raise GeneratorExit


class AsyncExits(AsyncBehavior):
    async def do_work(self) -> bool:
        raise SystemExit("bye")


class AsyncOk(AsyncBehavior):
    async def do_work(self) -> bool:
        return True


BEHAVIORS = [
    BlockingTick,
    Counts,
    BlockingHalt,
    IgnoresHalt,
    Moves,
    Records,
    Exits,
    Interrupted,
    GeneratorExits,
    AsyncExits,
    AsyncOk,
    BlocksTheLoop,
]


def _tree(node: str, tree_id: str = "T") -> str:
    return f'<root BTCPP_format="4"><BehaviorTree ID="{tree_id}">{node}</BehaviorTree></root>'


@pytest.fixture
def server() -> Iterator[ObjectiveServer]:
    RELEASE.clear()
    STUCK.clear()
    TICKS.clear()
    factory = registry_of(BEHAVIORS).create_factory(BehaviorContext.offline())
    with ObjectiveServer(FactoryTreeSource(factory), watchdog_report_s=0.2) as running:
        yield running
    RELEASE.set()


def _wait(condition: Callable[[], bool], what: str, timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.005)


def _xml(server: ObjectiveServer, xml: str) -> ObjectiveRun:
    return server.submit(ObjectiveRequest(objective_xml=xml))


def _running(server: ObjectiveServer) -> bool:
    return server.status[0] is ObjectiveStatus.RUNNING


# -- 1. a tree that re-ticks itself synchronously ---------------------------------------------------


def test_cancel_stops_an_endless_synchronous_repeat(server: ObjectiveServer) -> None:
    run = _xml(server, COUNTING_SPIN)
    _wait(lambda: len(TICKS) > 100, "the Repeat to spin")
    started = time.monotonic()
    assert server.cancel(timeout=5), "the cancel was refused"
    result = run.wait(5)
    latency = time.monotonic() - started
    assert result is not None and result.cancelled, result
    # The bound is a tick period + 100 ms (benchmarks/cancel_latency.py measures it); the test only
    # tells "served" from "stuck" so that a loaded machine does not fail it.
    assert latency < LATE, f"the cancel took {latency:.3f} s"
    # And the server still serves the next objective.
    assert _xml(server, QUICK).wait(5) == ObjectiveResult.success("Quick")


def test_a_new_objective_preempts_an_endless_synchronous_repeat(server: ObjectiveServer) -> None:
    spin = _xml(server, SPIN)
    _wait(lambda: _running(server), "the Repeat to run")
    started = time.monotonic()
    quick = _xml(server, QUICK)
    assert quick.wait(5) == ObjectiveResult.success("Quick"), quick.result
    latency = time.monotonic() - started
    result = spin.result
    assert result is not None and result.cancelled and "newer" in result.error_message, result
    assert latency < LATE, f"the preemption took {latency:.3f} s"


def test_an_endless_repeat_keeps_publishing_node_changes() -> None:
    # The server flushes node status changes between ticks: a tree that re-ticks itself forever must
    # not keep them all in memory until it ends.
    batches: list[int] = []

    class Listener:
        def on_status(self, *args: object) -> None: ...
        def on_blackboard(self, *args: object) -> None: ...
        def on_run_finished(self, *args: object) -> None: ...
        def on_node_status(self, name: str, changes: list[object]) -> None:
            batches.append(len(changes))

    factory = registry_of([]).create_factory(BehaviorContext.offline())
    with ObjectiveServer(FactoryTreeSource(factory), listeners=[Listener()]) as server:
        run = _xml(server, SPIN)
        _wait(lambda: len(batches) >= 5, "five batches of node changes")
        run.cancel()
        assert run.wait(5) is not None


# -- 2. behavior code that never returns ---------------------------------------------------------------


def test_a_blocking_tick_is_reported_and_cancel_abandons_its_thread(server: ObjectiveServer) -> None:
    run = _xml(server, _tree('<Sequence name="seq"><BlockingTick name="stuck"/><AsyncOk/></Sequence>'))
    _wait(lambda: any("in tick" in w for w in server.health().warnings), "the watchdog's report")
    warning = next(w for w in server.health().warnings if "in tick" in w)
    assert warning.startswith("behavior 'BlockingTick' (stuck) has been in tick for "), warning
    started = time.monotonic()
    assert server.cancel(reason="cancelled by the test", timeout=5)
    result = run.wait(5)
    latency = time.monotonic() - started
    assert result is not None and result.cancelled, result
    assert "cancelled by the test" in result.error_message
    assert "behavior 'BlockingTick' (stuck)" in result.error_message, result.error_message
    assert "abandoned" in result.error_message
    assert latency < LATE, f"the cancel took {latency:.3f} s"
    health = server.health()
    assert health.replacements == 1 and health.tick_thread_alive
    assert any(w.startswith("abandoned tick thread") for w in health.warnings), health
    # The next objective runs on a fresh tick thread.
    assert _xml(server, QUICK).wait(5) == ObjectiveResult.success("Quick")
    # When the stuck call returns, the abandoned tree starts nothing new and the thread goes away.
    RELEASE.set()
    _wait(lambda: not any("abandoned" in w for w in server.health().warnings), "the abandoned thread to end")


def test_a_new_objective_preempts_a_blocking_tick(server: ObjectiveServer) -> None:
    stuck = _xml(server, _tree('<BlockingTick name="stuck"/>'))
    _wait(lambda: _running(server), "the stuck objective to run")
    _wait(STUCK.is_set, "the behavior to be stuck")
    quick = _xml(server, QUICK)
    assert quick.wait(5) == ObjectiveResult.success("Quick"), quick.result
    result = stuck.result
    assert result is not None and result.cancelled and "newer objective" in result.error_message, result


def test_a_blocking_halt_does_not_block_the_cancel(server: ObjectiveServer) -> None:
    run = _xml(server, _tree('<BlockingHalt name="halts slowly"/>'))
    _wait(lambda: _running(server), "the objective to run")
    _wait(STUCK.is_set, "the behavior to be stuck")
    assert server.cancel(timeout=5)
    result = run.wait(5)
    assert result is not None and result.cancelled, result
    assert "behavior 'BlockingHalt' (halts slowly) has been in" in result.error_message, result
    assert _xml(server, QUICK).wait(5) == ObjectiveResult.success("Quick")


def test_the_abandoned_tree_stops_its_motion_and_starts_nothing_new(server: ObjectiveServer) -> None:
    EVENTS.clear()
    xml = _tree(
        '<Parallel success_count="2" failure_count="1"><Moves/>'
        '<Sequence><BlockingTick name="stuck"/><Records/></Sequence></Parallel>'
    )
    run = _xml(server, xml)
    _wait(lambda: _running(server), "the objective to run")
    _wait(STUCK.is_set, "the behavior to be stuck")
    assert server.cancel(timeout=5)
    result = run.wait(5)
    assert result is not None and result.cancelled, result
    # The motion beside the stuck node is halted (after a moment's grace for the stuck thread).
    _wait(lambda: "motion halted" in EVENTS, "the motion of the abandoned tree to be halted")
    # When the stuck tick returns, the rest of that tree no longer runs.
    RELEASE.set()
    _wait(lambda: not any("abandoned" in w for w in server.health().warnings), "the abandoned thread to end")
    assert "ticked after the stuck node" not in EVENTS, EVENTS


def test_a_new_objective_preempts_a_tree_whose_halt_blocks(server: ObjectiveServer) -> None:
    run = _xml(server, _tree('<BlockingHalt name="halts slowly"/>'))
    _wait(lambda: _running(server), "the objective to run")
    _wait(STUCK.is_set, "the behavior to be stuck")
    assert _xml(server, QUICK).wait(5) == ObjectiveResult.success("Quick")
    result = run.result
    assert result is not None and result.cancelled and "newer objective" in result.error_message, result
    assert "behavior 'BlockingHalt' (halts slowly)" in result.error_message, result.error_message


def test_do_work_that_ignores_halt_is_reported(server: ObjectiveServer) -> None:
    run = _xml(server, _tree('<IgnoresHalt name="deaf"/>'))
    _wait(lambda: _running(server), "the objective to run")
    _wait(STUCK.is_set, "the behavior to be stuck")
    assert server.cancel(timeout=5)
    result = run.wait(5)
    assert result is not None and result.cancelled
    expected = "behavior 'IgnoresHalt' (deaf) has ignored a halt"
    _wait(lambda: any(expected in w for w in server.health().warnings), "the report of the running work")
    assert _xml(server, QUICK).wait(5) == ObjectiveResult.success("Quick")
    RELEASE.set()
    _wait(lambda: not any("ignored a halt" in w for w in server.health().warnings), "the work to end")


def test_a_coroutine_blocking_the_event_loop_is_reported_and_async_work_goes_on(
    server: ObjectiveServer,
) -> None:
    run = _xml(server, _tree('<BlocksTheLoop name="sleeps in async"/>'))
    expected = "behavior 'BlocksTheLoop' (sleeps in async) has been in do_work for"
    _wait(lambda: any(expected in w for w in server.health().warnings), "the report of the blocked loop")
    assert server.cancel(timeout=5)
    result = run.wait(5)
    assert result is not None and result.cancelled, result
    # Other async behaviors run on a fresh loop meanwhile.
    assert _xml(server, _tree("<AsyncOk/>")).wait(5) == ObjectiveResult.success("T")
    RELEASE.set()
    _wait(lambda: not any(expected in w for w in server.health().warnings), "the blocked loop to run again")


# -- 3. BaseExceptions from behavior code -------------------------------------------------------------


@pytest.mark.parametrize(
    ("behavior", "raised"),
    [
        ("Exits", "SystemExit: 3"),
        ("Interrupted", "KeyboardInterrupt"),
        ("GeneratorExits", "GeneratorExit"),
        ("AsyncExits", "SystemExit: bye"),
    ],
)
def test_a_base_exception_in_a_behavior_fails_the_objective_with_its_line(
    server: ObjectiveServer, behavior: str, raised: str
) -> None:
    result = _xml(server, _tree(f'<Sequence><{behavior} name="bad"/></Sequence>')).wait(5)
    assert result is not None and result.failed, result
    assert raised in result.error_message, result.error_message
    assert "test_objective_server_watchdog.py:" in result.error_message, result.error_message
    assert "'bad'" in result.error_message or "(bad)" in result.error_message, result.error_message
    # The tick thread lives on: same thread, next objective runs.
    assert server.health().replacements == 0
    assert _xml(server, QUICK).wait(5) == ObjectiveResult.success("Quick")
    # Async work still runs (the event loop survived a SystemExit in a coroutine).
    assert _xml(server, _tree("<AsyncOk/>")).wait(5) == ObjectiveResult.success("T")


def test_a_dead_tick_thread_is_reported_and_replaced() -> None:
    class Killer:
        """A listener with a bug no handler expects: it ends the tick thread once."""

        fired = False

        def on_status(self, status: ObjectiveStatus, name: str) -> None:
            if status is ObjectiveStatus.RUNNING and not Killer.fired:
                Killer.fired = True
                raise SystemExit("listener bug")

        def on_node_status(self, *args: object) -> None: ...
        def on_blackboard(self, *args: object) -> None: ...
        def on_run_finished(self, *args: object) -> None: ...

    factory = registry_of([]).create_factory(BehaviorContext.offline())
    with ObjectiveServer(FactoryTreeSource(factory), listeners=[Killer()]) as server:
        first = _xml(server, QUICK).wait(5)
        assert first is not None and first.failed, first
        assert "tick thread" in first.error_message and "died" in first.error_message, first
        health = server.health()
        assert health.replacements == 1
        assert any("died: SystemExit: listener bug" in w for w in health.warnings), health
        _wait(lambda: server.health().tick_thread_alive, "a new tick thread")
        assert _xml(server, QUICK).wait(5) == ObjectiveResult.success("Quick")


def test_a_tick_thread_dying_mid_motion_still_halts_the_motion() -> None:
    EVENTS.clear()

    class Killer:
        fired = False

        def on_status(self, *args: object) -> None: ...
        def on_blackboard(self, *args: object) -> None: ...
        def on_run_finished(self, *args: object) -> None: ...
        def on_node_status(self, name: str, changes: list[object]) -> None:
            if not Killer.fired:
                Killer.fired = True
                raise KeyboardInterrupt

    factory = registry_of(BEHAVIORS).create_factory(BehaviorContext.offline())
    with ObjectiveServer(FactoryTreeSource(factory), listeners=[Killer()]) as server:
        result = _xml(server, _tree("<Moves/>")).wait(5)
        assert result is not None and result.failed and "died: KeyboardInterrupt" in result.error_message
        _wait(lambda: "motion halted" in EVENTS, "the motion of the dead thread's tree to be halted")
        assert _xml(server, QUICK).wait(5) == ObjectiveResult.success("Quick")


# -- code that holds the interpreter (C code that does not release the GIL) --------------------------

GO = threading.Event()


class HoldsTheInterpreter(SyncBehavior):
    """Waits for the test, then sits 1 s in C code that keeps the GIL (ctypes.PyDLL never releases it)."""

    def tick(self) -> NodeStatus:
        import ctypes

        GO.wait(30)
        ctypes.PyDLL(None).usleep(1_000_000)
        return NodeStatus.SUCCESS


def test_a_cancel_accepted_while_a_tick_holds_the_interpreter_wins_and_the_stack_is_reported() -> None:
    """The probe: C code holding the GIL for 15 s lost a cancel, and the objective reported SUCCESS."""
    GO.clear()
    factory = registry_of([HoldsTheInterpreter]).create_factory(BehaviorContext.offline())
    with ObjectiveServer(
        FactoryTreeSource(factory), watchdog_report_s=0.2, abandon_after_s=30, stall_report_s=0.2
    ) as server:
        run = _xml(server, _tree("<HoldsTheInterpreter/>"))
        _wait(lambda: _running(server), "the objective to run")
        assert run.request_cancel("cancelled by the test")  # what /do_objective's cancel_goal does
        server.cancel(run, reason="cancelled by the test", timeout=0)
        GO.set()
        result = run.wait(30)
        assert result is not None and result.cancelled, result
        assert "cancelled by the test" in result.error_message
        assert not run.request_cancel("too late"), "a settled run accepts no cancel"

        def reported() -> list[str]:
            return [w for w in server.health().warnings if "the interpreter was held" in w]

        _wait(lambda: bool(reported()), "the watchdog's report of the held interpreter")
        assert "test_objective_server_watchdog.py" in reported()[0] and "in tick" in reported()[0], reported()
    GO.set()


def test_a_run_that_succeeded_accepts_no_cancel(server: ObjectiveServer) -> None:
    run = _xml(server, QUICK)
    assert run.wait(5) == ObjectiveResult.success("Quick")
    assert not run.request_cancel("late") and not server.cancel(run)
