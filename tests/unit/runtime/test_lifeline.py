"""A child holding the supervisor's lifeline ends soon after the supervisor is gone, whatever it is doing."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from kinema.process.lifeline import ENV, GRACE_S, Lifeline, hold

# Each child prints "held" once it watches the lifeline, then does something that would keep it alive.
STUBBORN = {
    "ignores SIGTERM": "signal.signal(signal.SIGTERM, signal.SIG_IGN)\nwhile True: time.sleep(1)",
    "exits cleanly on SIGTERM": "signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))\n"
    "while True: time.sleep(1)",
    # The main thread returns but a non-daemon thread never ends: the interpreter waits for it at exit.
    "hangs at interpreter exit": "threading.Thread(target=lambda: threading.Event().wait()).start()\n"
    "signal.signal(signal.SIGTERM, lambda *_: None)",
}


def _child(lifeline: Lifeline, body: str) -> subprocess.Popen[str]:
    code = (
        "import signal, sys, threading, time\n"
        "from kinema.process import lifeline\n"
        "print('held' if lifeline.hold() else 'not held', flush=True)\n" + body
    )
    return subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, **lifeline.child_env()},
        pass_fds=(lifeline.read_fd,),
    )


@pytest.mark.parametrize("behaviour", sorted(STUBBORN))
def test_the_child_ends_within_the_grace_after_the_supervisor_is_gone(behaviour: str) -> None:
    lifeline = Lifeline()
    child = _child(lifeline, STUBBORN[behaviour])
    try:
        assert child.stdout is not None
        assert child.stdout.readline().strip() == "held"
        time.sleep(0.2)
        assert child.poll() is None, "the child ended while its supervisor was alive"
        lifeline.close()  # what the kernel does when the supervisor dies
        try:
            code = child.wait(GRACE_S + 5)
        except subprocess.TimeoutExpired:
            pytest.fail(f"a child that {behaviour} was still running {GRACE_S + 5} s after its supervisor")
        assert code is not None
    finally:
        lifeline.close()
        if child.poll() is None:
            child.kill()
            child.wait(5)


def test_a_process_started_by_hand_holds_no_lifeline(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(ENV, raising=False)
    assert hold() is False
    monkeypatch.setenv(ENV, "987654:1")  # an inherited name whose descriptor this process does not have
    assert hold() is False
    assert ENV not in os.environ  # never handed on to grandchildren
