"""WaitDeadline: a wait on another party times out only once its seconds passed in sim and in wall time."""

from __future__ import annotations

import time

from kinema.behaviors.wait_deadline import WaitDeadline


class FastClock:
    """Sim time running 1000 times faster than the wall clock (a simulation at maximum speed)."""

    def __init__(self) -> None:
        self._start = time.monotonic()

    def now(self) -> float:
        return (time.monotonic() - self._start) * 1000.0


class StoppedClock:
    """Sim time standing still (a paused or very slow simulation)."""

    def now(self) -> float:
        return 12.0


def test_a_fast_simulation_does_not_shorten_the_wait() -> None:
    deadline = WaitDeadline(FastClock(), 0.2)
    time.sleep(0.05)  # 50 s of sim time
    assert not deadline.passed(), "0.2 s of sim time passed, but not of wall time"
    time.sleep(0.2)
    assert deadline.passed()


def test_a_slow_simulation_does_not_shorten_it_either() -> None:
    deadline = WaitDeadline(StoppedClock(), 0.05)
    time.sleep(0.1)
    assert not deadline.passed(), "the wall clock passed 0.05 s, the simulation did not"


def test_a_negative_timeout_never_passes() -> None:
    deadline = WaitDeadline(FastClock(), -1.0)
    assert deadline.forever and not deadline.passed()
