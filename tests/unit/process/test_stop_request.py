"""A stop asked for by SIGTERM or Ctrl-C reaches the process whatever its main thread is doing."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time

from kinema.process.stop import POLL_S, TERMINATE, StopRequest

# The main thread is inside the waiter's own lock (as in every Event.wait) when SIGTERM arrives; a handler
# that set a threading.Event there waited for itself, and the process never stopped.
SIGNAL_INSIDE_THE_WAIT = """
import os, signal
from kinema.process.stop import TERMINATE, StopRequest
with StopRequest().handle_signals(TERMINATE) as stop:
    with stop._event._cond:
        os.kill(os.getpid(), signal.SIGTERM)
        for _ in range(1000):  # the handler runs on one of these bytecodes
            pass
    print("stopped" if stop.wait(5) else "not stopped", stop.reason, flush=True)
"""


def test_sigterm_arriving_while_the_main_thread_holds_the_waiters_lock_still_stops_it() -> None:
    result = subprocess.run(
        [sys.executable, "-c", SIGNAL_INSIDE_THE_WAIT], capture_output=True, text=True, timeout=20
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["stopped", "SIGTERM"]


def test_a_signal_on_another_thread_is_noticed_by_a_waiting_main_thread() -> None:
    stop = StopRequest()
    with stop.handle_signals(TERMINATE):
        threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGINT)).start()
        started = time.monotonic()
        assert stop.wait(10)
        assert time.monotonic() - started < 5
    assert stop.reason == "Ctrl-C"


def test_the_handlers_before_are_back_after_the_block() -> None:
    before = signal.getsignal(signal.SIGTERM)
    with StopRequest().handle_signals(TERMINATE):
        assert signal.getsignal(signal.SIGTERM) is not before
    assert signal.getsignal(signal.SIGTERM) is before


def test_a_thread_stops_a_waiter_at_once_and_the_first_reason_is_kept() -> None:
    stop = StopRequest()
    assert not stop.wait(POLL_S / 2)
    assert not stop.is_set()
    threading.Timer(0.1, stop.set, ("the terminal UI was closed",)).start()
    assert stop.wait(10)
    stop.set("SIGTERM")
    assert stop.reason == "the terminal UI was closed"
