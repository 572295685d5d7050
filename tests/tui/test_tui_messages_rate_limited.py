"""Watchdog and connection messages are plain words, say what to do, and come once per kind and period."""

from __future__ import annotations

from tui_pilot_harness import drive, settle

from kinema.tui.connection import ConnectionChanged, ConnectionState, Heartbeat, LogEntry, LogLevel
from kinema.tui.fake_connection import FakeConnection
from kinema.tui.repeat_limiter import RepeatLimiter

STUCK = (
    "watchdog: behavior 'Block' (main/block) has been in tick for {s:.1f} s; the objective cannot stop "
    "until it returns: cancel it (ctrl+x, kinema objective cancel)"
)


def test_the_limiter_lets_one_through_per_period_and_counts_the_rest() -> None:
    limiter = RepeatLimiter(period=30.0)
    assert limiter.admit("a", 0.0) == 0
    assert [limiter.admit("a", t) for t in (1.0, 2.0, 29.0)] == [None, None, None]
    assert limiter.admit("b", 2.0) == 0  # another kind is not held back
    assert limiter.admit("a", 31.0) == 3


def test_a_repeating_watchdog_warning_and_a_flapping_connection_come_once(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        shown_before = len(app.shown)
        for second in range(5):
            fake.emit(LogEntry(STUCK.format(s=3.0 + second), LogLevel.WARN, 1.0, "runtime"))
        for beat in range(4):
            fake.emit(
                ConnectionChanged(
                    ConnectionState.DISCONNECTED,
                    "fake://runtime",
                    "no heartbeat from the runtime for 3.2 s",
                )
            )
            fake.emit(ConnectionChanged(ConnectionState.CONNECTED, "fake://runtime"))
            fake.emit(Heartbeat(10.0 + beat, "", "Idle"))
        await settle(pilot)
        toasts = app.shown[shown_before:]
        assert len(toasts) == 3, toasts  # one warning, one Disconnected, one Reconnected
        watchdog = [entry for entry in app.logs if entry.source == "watchdog"]
        assert len(watchdog) == 1
        assert watchdog[0].message.startswith("Behavior 'Block' (main/block) has been in tick for 3.0 s")
        assert "cancel it (ctrl+x" in watchdog[0].message
        lost = [entry.message for entry in app.logs if entry.message.startswith("Disconnected")]
        assert len(lost) == 1
        assert "no sign of life from it for 3.2 s" in lost[0] and "reconnects by itself" in lost[0]
        assert "heartbeat" not in lost[0]

    drive(fake, scenario)
