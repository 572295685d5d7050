"""``kinema shell`` talks to the runtime; ``kinema example add-two-ints-server`` answers AddTwoInts."""

from __future__ import annotations

import subprocess
import sys
from typing import Any


def test_the_shell_has_a_connected_client(agent: Any) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "kinema", "shell", "--plain", "--connect", agent.endpoint],
        input="print('RESULT', client.execute('Quick').succeeded)\n",
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    # Piped-in code runs as a script: its output only, no banner or prompts.
    assert done.stdout == "RESULT True\n"
    failing = subprocess.run(
        [sys.executable, "-m", "kinema", "shell", "--connect", agent.endpoint],
        input="x = 1\nraise ValueError('boom')\n",
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert failing.returncode == 1 and failing.stdout == ""
    assert 'File "<stdin>", line 2' in failing.stderr and failing.stderr.endswith("ValueError: boom\n")
    assert "shell.py" not in failing.stderr  # the user's frames, not Kinema's


def test_the_add_two_ints_example_serves_and_prints_requests(agent: Any) -> None:
    from kinema.transport import Node, open_session

    server = subprocess.Popen(
        [sys.executable, "-m", "kinema", "example", "add-two-ints-server", "--connect", agent.endpoint],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert server.stdout is not None
        assert "serving /add_two_ints" in server.stdout.readline()
        with open_session(agent.endpoint) as session:
            node = Node(session, "adder")
            client = node.create_client("example_interfaces/srv/AddTwoInts", "/add_two_ints")
            assert client.call({"a": 5, "b": 37}, timeout=10).sum == 42
        assert server.stdout.readline().strip() == "request: a=5 b=37 -> sum=42"
    finally:
        server.terminate()
        server.wait(10)
    assert server.returncode == 0
