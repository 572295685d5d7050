"""What a failing test prints about the world it ran in: log tails, the Kinema processes still running.

A module of its own rather than part of ``conftest`` (test modules are imported by basename, and every
folder has a ``conftest``); fixtures use it through ``show_on_failure`` in the root conftest.
"""

from __future__ import annotations

import os
from pathlib import Path


def log_tail(path: Path, lines: int = 40) -> str:
    """The last ``lines`` lines of a log file, or why there are none."""
    try:
        return "\n".join(path.read_text(encoding="utf-8", errors="replace").splitlines()[-lines:])
    except OSError as error:
        return f"(no log at {path}: {error.strerror})"


def describe_process(pid: int) -> str | None:
    """``pid, state, command line`` of a running process (None when it is gone)."""
    proc = Path("/proc") / str(pid)
    try:
        cmdline = (proc / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace").strip()
        state = (proc / "stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return None
    return f"{pid:>7} {state} {cmdline[:200]}"


def kinema_processes() -> str:
    """One line per running process whose command line mentions kinema: pid, state, command."""
    rows = []
    for proc in Path("/proc").glob("[0-9]*"):
        row = describe_process(int(proc.name)) if int(proc.name) != os.getpid() else None
        if row is not None and "kinema" in row:
            rows.append(row)
    return "\n".join(rows) or "(none)"
