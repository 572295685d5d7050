"""HandOff: jobs in order, the newest of a key replacing a queued one, and no thread left behind."""

from __future__ import annotations

import threading

from kinema.runtime import background_work
from kinema.runtime.background_work import HandOff


def test_jobs_run_in_order_and_a_keyed_job_replaces_its_queued_predecessor() -> None:
    work = HandOff("test-handoff")
    gate = threading.Event()
    done: list[str] = []
    work.submit(lambda: gate.wait(10))  # holds the worker while the rest queues
    work.submit(lambda: done.append("snapshot 1"), key="snapshot")
    work.submit(lambda: done.append("close"))
    work.submit(lambda: done.append("snapshot 2"), key="snapshot")  # replaces snapshot 1 in its place
    gate.set()
    assert work.drain(10)
    assert done == ["snapshot 2", "close"]
    work.close()
    assert not work.running
    work.submit(lambda: done.append("after close"))
    assert work.drain(1) and done == ["snapshot 2", "close"]


def test_an_idle_worker_ends_its_thread_and_the_next_job_starts_one(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.setattr(background_work, "IDLE_EXIT_S", 0.05)
    work = HandOff("test-handoff-idle")
    ran = threading.Event()
    work.submit(ran.set)
    assert ran.wait(10)
    thread = work._thread
    assert thread is not None
    thread.join(10)
    assert not thread.is_alive() and not work.running
    again = threading.Event()
    work.submit(again.set)
    assert again.wait(10)
    work.close()


def test_a_job_that_raises_is_logged_and_the_worker_goes_on(caplog) -> None:  # type: ignore[no-untyped-def]
    work = HandOff("test-handoff-raise")
    done: list[int] = []
    work.submit(lambda: 1 / 0)  # type: ignore[func-returns-value]
    work.submit(lambda: done.append(1))
    assert work.drain(10) and done == [1]
    assert "a job raised" in caplog.text
    work.close()
