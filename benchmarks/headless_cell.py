"""``kinema run --headless`` for a benchmark: lab_sim on a free loopback port with private user folders.

Used by ``cli_start.py`` and ``soak.py`` (run as scripts, so ``benchmarks/`` is on the path).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from kinema.transport import free_endpoint

READY = "objectives can be started"


@dataclass
class HeadlessCell:
    """A running ``kinema run --headless``: its supervisor process, the router endpoint and the environment
    (endpoint, config, private ``XDG_*`` folders) that commands joining it run with."""

    supervisor: subprocess.Popen[str]
    endpoint: str
    env: dict[str, str]


@contextmanager
def headless_lab_sim(prefix: str, kinema: list[str] | None = None) -> Iterator[HeadlessCell]:
    """Start lab_sim headless (``kinema`` is the command that runs the CLI; ``python -m kinema`` by
    default), yield it once objectives can be started, and stop it (SIGINT, as Ctrl-C) on exit."""
    endpoint = free_endpoint()
    with tempfile.TemporaryDirectory(prefix=prefix) as home:
        env = {
            **os.environ,
            "KINEMA_ZENOH_CONNECT": endpoint,
            "KINEMA_CONFIG": "lab_sim",
            **{f"XDG_{n}_HOME": str(Path(home) / n.lower()) for n in ("CONFIG", "DATA", "STATE", "CACHE")},
        }
        supervisor = subprocess.Popen(
            [*(kinema or [sys.executable, "-m", "kinema"]), "run", "--headless"],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env=env,
        )
        try:
            assert supervisor.stdout is not None
            for line in supervisor.stdout:
                if READY in line:
                    break
            else:
                raise RuntimeError("kinema run stopped before it was ready")
            yield HeadlessCell(supervisor, endpoint, env)
        finally:
            supervisor.send_signal(signal.SIGINT)
            try:
                supervisor.wait(30)
            except subprocess.TimeoutExpired:
                supervisor.kill()
                supervisor.wait(10)
