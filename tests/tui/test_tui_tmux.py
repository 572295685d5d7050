"""Run ``kinema ui`` in a real terminal (tmux) as a person would, and read the screen with ``capture-pane``.

CI needs tmux installed (``apt-get install -y tmux``); without it this test is skipped, saying so.
"""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import time
import uuid
from collections.abc import Callable, Iterator

import pytest

pytestmark = pytest.mark.skipif(
    shutil.which("tmux") is None,
    reason="tmux is not installed (apt-get install -y tmux); CI should install it",
)


class Terminal:
    """A detached tmux session on its own server socket, running one command."""

    def __init__(self, command: list[str], width: int = 120, height: int = 34) -> None:
        self.socket = f"kinema-test-{uuid.uuid4().hex[:8]}"
        env = {**os.environ, "TERM": "xterm-256color", "KINEMA_WORKSPACE": "", "KINEMA_CONFIG": ""}
        shell_command = " ".join(_quote(part) for part in command)
        self._tmux(
            "new-session", "-d", "-s", "ui", "-x", str(width), "-y", str(height), shell_command, env=env
        )

    def _tmux(self, *args: str, env: dict[str, str] | None = None) -> str:
        done = subprocess.run(
            ["tmux", "-L", self.socket, *args],
            capture_output=True,
            text=True,
            timeout=10,
            env=env,
            check=False,
        )
        return done.stdout

    def screen(self) -> str:
        """The visible screen as text."""
        return self._tmux("capture-pane", "-p", "-t", "ui")

    def press(self, *keys: str) -> None:
        for key in keys:
            self._tmux("send-keys", "-t", "ui", key)

    def wait_for(self, check: Callable[[str], bool], what: str, timeout: float = 20.0) -> str:
        deadline = time.monotonic() + timeout
        text = ""
        while time.monotonic() < deadline:
            text = self.screen()
            if check(text):
                return text
            time.sleep(0.1)
        raise AssertionError(f"timed out waiting for {what}; the screen shows:\n{text}")

    def alive(self) -> bool:
        return "ui" in self._tmux("list-sessions", "-F", "#{session_name}")

    def close(self) -> None:
        self._tmux("kill-server")


def _quote(part: str) -> str:
    return "'" + part.replace("'", "'\"'\"'") + "'"


@pytest.fixture
def terminal() -> Iterator[Terminal]:
    term = Terminal([sys.executable, "-m", "kinema.cli.main", "ui", "--demo"])
    try:
        yield term
    finally:
        term.close()


def test_a_person_browses_runs_and_quits_in_a_real_terminal(terminal: Terminal) -> None:
    terminal.wait_for(lambda s: "Pick Object" in s and "connected" in s, "the first paint")
    # The footer paints after the tree on a busy machine: wait for both.
    first = terminal.wait_for(
        lambda s: "○ Sleep" in s and "^p palette" in s, "the objective's tree and the footer"
    )
    lines = first.rstrip().splitlines()  # the footer is the last line drawn
    assert "1 Configs" in lines[0] and "6 Waypoints" in lines[0]  # every screen is named, with its key
    assert "● connected fake://runtime" in first  # the status bar
    assert "⏎ Run" in lines[-1] and "^q Quit" in lines[-1] and "^x Cancel" in lines[-1]  # the footer
    terminal.wait_for(lambda s: "Enter or ctrl+r runs" in s, "the list saying what Enter runs")
    assert "○ MoveToWaypoint" in first and "○ Sleep" in first  # the tree, subtree expanded

    terminal.press("r")  # a letter on the list searches; it never runs
    searched = terminal.wait_for(lambda s: "of 3 objectives" in s, "the search")
    assert "Run 'Pick Object'" not in searched
    terminal.press("BSpace", "Enter", "Enter")
    terminal.wait_for(lambda s: "Run 'Pick Object'" in s, "the run notification")
    terminal.press("Tab")  # away from the list: the digits are the screens' keys again

    terminal.press("3")
    terminal.wait_for(lambda s: "filter by key" in s and "History" in s, "the Blackboard screen")

    terminal.press("6")
    waypoints = terminal.wait_for(lambda s: "Look at Table" in s, "the Waypoints screen")
    assert "★" in waypoints and "Home" in waypoints

    terminal.press("1")
    terminal.wait_for(lambda s: "example_config" in s and "lab_sim" in s, "the Configs screen")

    terminal.press("q")
    deadline = time.monotonic() + 10
    while terminal.alive() and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not terminal.alive(), "q did not close the app"


def test_kinema_run_opens_the_app_and_closing_it_stops_the_runtime() -> None:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    command = [
        sys.executable,
        "-m",
        "kinema.cli.main",
        "run",
        "-c",
        "lab_sim",
        "-n",
        "--connect",
        f"tcp/127.0.0.1:{port}",
    ]
    term = Terminal(["sh", "-c", " ".join(_quote(p) for p in command) + "; echo KINEMA-EXIT=$?; sleep 30"])
    try:
        screen = term.wait_for(
            lambda s: "● connected" in s and "Hello Tree" in s, "the app on the runtime", 90
        )
        assert f"tcp/127.0.0.1:{port}" in screen
        term.press("q")  # on the objective list a letter searches; ctrl+q quits from anywhere
        term.press("C-q")
        question = term.wait_for(lambda s: "This stops the runtime" in s, "the quit question")
        assert "y: Quit and stop" in question and "n or Esc: Stay" in question  # the dialog says its keys
        term.press("y")
        term.wait_for(lambda s: "KINEMA-EXIT=0" in s, "kinema run to exit", 30)
        with socket.socket() as probe:  # the router it hosted is gone: nothing listens on its port
            probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            probe.bind(("127.0.0.1", port))
    finally:
        term.close()
