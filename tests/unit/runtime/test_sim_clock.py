"""SimClock: time follows /clock stamps, timers fire when sim time reaches them."""

from __future__ import annotations

from types import SimpleNamespace

from kinema.runtime.sim_clock import SimClock


def test_time_is_frozen_until_the_first_stamp() -> None:
    clock = SimClock()
    assert clock.now() == 0.0
    assert not clock.running
    clock.advance_to(2.5)
    assert clock.now() == 2.5
    assert clock.running


def test_timers_fire_in_order_when_sim_time_reaches_them() -> None:
    clock = SimClock()
    fired: list[str] = []
    clock.call_later(1.0, lambda: fired.append("one"))
    clock.call_later(0.5, lambda: fired.append("half"))
    clock.advance_to(0.4)
    assert fired == []
    clock.advance_to(0.5)
    assert fired == ["half"]
    clock.advance_to(10.0)
    assert fired == ["half", "one"]


def test_a_cancelled_timer_never_fires() -> None:
    clock = SimClock()
    fired: list[int] = []
    handle = clock.call_later(0.1, lambda: fired.append(1))
    handle.cancel()
    clock.advance_to(1.0)
    assert fired == []


def test_zero_delay_fires_at_the_next_stamp_not_synchronously() -> None:
    clock = SimClock(start=3.0)
    fired: list[int] = []
    clock.call_later(0.0, lambda: fired.append(1))
    assert fired == []
    clock.advance_to(3.0)
    assert fired == [1]


def test_a_reset_of_the_simulator_keeps_pending_sleeps_whole() -> None:
    clock = SimClock()
    clock.advance_to(10.0)
    fired: list[int] = []
    clock.call_later(2.0, lambda: fired.append(1))  # due at 12
    clock.advance_to(0.0)  # the simulator was reset: the timer is now due at 2
    clock.advance_to(1.9)
    assert fired == []
    clock.advance_to(2.0)
    assert fired == [1]


def test_clock_messages_carry_sec_and_nanosec() -> None:
    clock = SimClock()
    clock.on_clock_message(SimpleNamespace(clock=SimpleNamespace(sec=3, nanosec=250_000_000)))
    assert clock.now() == 3.25
