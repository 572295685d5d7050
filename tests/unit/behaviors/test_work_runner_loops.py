"""A retired event loop (a coroutine blocked it) stops once it unblocks: no thread or descriptor stays."""

from __future__ import annotations

import asyncio
import os
import threading
import time

from kinema.behaviors.work_runner import WorkRunner


def _wait(condition, what: str, timeout: float = 10.0) -> None:  # type: ignore[no-untyped-def]
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.005)


def _fds() -> int:
    return len(os.listdir("/proc/self/fd"))


def test_a_retired_loop_finishes_its_tasks_then_its_thread_ends_and_the_loop_closes() -> None:
    runner = WorkRunner()
    release = threading.Event()
    fds_before = _fds()

    async def blocks() -> str:
        release.wait(30)  # blocks the loop instead of awaiting
        return "unblocked"

    async def awaits() -> str:
        await asyncio.sleep(0.05)
        return "finished"

    stuck = runner.run_coroutine(blocks())
    _wait(lambda: runner.blocked_loop() is not None and runner.blocked_loop()[0] > 0.2, "the loop to block")
    old_loop, old_thread = runner._loop, runner._loop_thread
    assert old_loop is not None and old_thread is not None
    later = asyncio.run_coroutine_threadsafe(awaits(), old_loop)  # queued on the blocked loop
    runner.retire_blocked_loop()
    fresh = runner.run_coroutine(awaits())
    assert fresh.result(10) == "finished" and runner._loop_thread is not old_thread
    release.set()
    assert stuck.result(10) == "unblocked" and later.result(10) == "finished"
    old_thread.join(10)
    assert not old_thread.is_alive(), "the retired loop's thread still runs"
    assert old_loop.is_closed()
    # Retire the fresh loop too (nothing blocks it): its thread ends as well.
    fresh_thread = runner._loop_thread
    runner.retire_blocked_loop()
    assert fresh_thread is not None
    fresh_thread.join(10)
    assert not fresh_thread.is_alive()
    assert _fds() <= fds_before, "the retired loops' selectors and self-pipes were not closed"


def test_a_late_beat_of_a_loop_that_waits_for_work_is_not_a_blocked_loop() -> None:
    # On a loaded machine the loop's beat came 2.3 s late with no coroutine running, and the watchdog
    # reported "in a coroutine for 2.3 s" and retired a loop that nothing blocked.
    runner = WorkRunner()

    async def quick() -> str:
        return "done"

    assert runner.run_coroutine(quick()).result(10) == "done"
    time.sleep(0.1)  # the loop now waits in its selector
    runner._beats[0] = time.monotonic() - 5.0  # as if the process had not run for 5 s
    blocked = runner.blocked_loop()
    assert blocked is not None and blocked[0] == 0.0
    runner.retire_blocked_loop()
