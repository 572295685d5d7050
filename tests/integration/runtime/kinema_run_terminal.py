"""A `kinema run` started as a user starts it, with its terminal output read line by line."""

from __future__ import annotations

import queue
import signal
import subprocess
import sys
import threading
import time

READY = "objectives can be started"
DRIVERS_READY = "drivers only"


class Terminal:
    """The output of one `kinema run` (stdout and stderr), line by line."""

    def __init__(self, args: list[str], env: dict[str, str]) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "kinema", "run", *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env=env,
        )
        self.lines: list[str] = []
        self._queue: queue.Queue[str] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self._queue.put(line)

    def wait_for(self, *needles: str, timeout: float = 60) -> str:
        """The first new line that contains every needle; fails with the whole output otherwise."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                line = self._queue.get(timeout=0.5)
            except queue.Empty:
                if self.process.poll() is not None and self._queue.empty():
                    break
                continue
            self.lines.append(line)
            if all(needle in line for needle in needles):
                return line
        raise AssertionError(f"no line with {needles} in:\n{''.join(self.lines)}")

    def stop(self) -> None:
        """Ctrl-C, then kill if it does not stop."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
            try:
                self.process.wait(20)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(5)
