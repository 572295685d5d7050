"""The log files of a run: one format for every process, read back merged and filtered by level.

Each process of a run (``supervisor``, ``agent``, each driver) writes ``<name>.log`` in the run folder,
one entry per line: ``2026-11-22 02:40:00.123 INFO    [agent] message``. Lines that do not start with
a time stamp (a traceback, a stray print) belong to the entry above them.

:data:`STACKS_SIGNAL` makes a process append every thread's Python stack to its log file, from
faulthandler's C code (it needs no interpreter lock, so a deadlocked process answers too): ``kinema down``
sends it to a run that did not stop in time before it kills the run.
"""

from __future__ import annotations

import faulthandler
import logging
import re
import signal
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

LOG_FORMAT = "%(asctime)s.%(msecs)03d %(levelname)-7s [%(name)s] %(message)s"
DATE_FORMAT = "%Y-%m-%d %H:%M:%S"
LEVELS = ("DEBUG", "INFO", "WARNING", "ERROR", "CRITICAL")
#: The agent's logger for plugin load errors and hot-reload outcomes; `kinema run` echoes its entries.
PLUGIN_LOGGER = "kinema.plugins"
#: Libraries whose INFO lines say nothing to a user of Kinema (``No OpenGL_accelerate module loaded`` in
#: every MuJoCo driver's log); their warnings still show, and all of it with ``--verbose``.
QUIET_LIBRARY_LOGGERS = ("OpenGL.acceleratesupport",)
#: Sent to a process of a run, it writes every thread's stack to its log file (see the module's docstring).
STACKS_SIGNAL = signal.SIGUSR1

_ENTRY = re.compile(r"^(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d{3}) (DEBUG|INFO|WARNING|ERROR|CRITICAL)\s")


@dataclass
class LogEntry:
    """One entry of a log file (continuation lines included in ``text``)."""

    stamp: str
    level: str
    process: str
    text: str

    @property
    def level_number(self) -> int:
        """The entry's level as a ``logging`` number."""
        return logging.getLevelName(self.level) if self.level in LEVELS else logging.INFO


def level_number(name: str) -> int:
    """``"warn"`` / ``"WARNING"`` / ``"error"`` ... as a logging level number.

    Raises:
        ValueError: an unknown level name (the message lists the valid ones).
    """
    upper = name.strip().upper()
    if upper == "WARN":
        upper = "WARNING"
    if upper not in LEVELS:
        raise ValueError(f"unknown log level {name!r}; valid: {', '.join(level.lower() for level in LEVELS)}")
    return int(logging.getLevelName(upper))


def configure_process_logging(log_file: Path | None, *, verbose: bool = False, echo: bool = False) -> None:
    """Send this process's ``logging`` output to ``log_file`` in the run format (and stderr if ``echo``)."""
    root = logging.getLogger()
    root.setLevel(logging.DEBUG if verbose else logging.INFO)
    for chatty in QUIET_LIBRARY_LOGGERS:
        logging.getLogger(chatty).setLevel(logging.DEBUG if verbose else logging.WARNING)
    formatter = logging.Formatter(LOG_FORMAT, DATE_FORMAT)
    for handler in list(root.handlers):
        root.removeHandler(handler)
    if log_file is not None:
        file_handler = logging.FileHandler(log_file, encoding="utf-8")
        file_handler.setFormatter(formatter)
        root.addHandler(file_handler)
        if file_handler.stream is not None:  # opened at once (FileHandler without delay)
            faulthandler.register(STACKS_SIGNAL, file=file_handler.stream, all_threads=True)
    if echo or log_file is None:
        stream = logging.StreamHandler(sys.stderr)
        stream.setFormatter(formatter)
        root.addHandler(stream)


def parse_entries(path: Path, lines: list[str] | None = None) -> list[LogEntry]:
    """The entries of one log file."""
    process = path.stem
    if lines is None:
        try:
            lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
        except FileNotFoundError:
            return []
    entries: list[LogEntry] = []
    for line in lines:
        match = _ENTRY.match(line)
        if match is not None:
            entries.append(LogEntry(match.group(1), match.group(2), process, line))
        elif entries:
            entries[-1].text += "\n" + line
        elif line.strip():
            entries.append(LogEntry("", "INFO", process, line))
    return entries


def merged_entries(paths: list[Path], *, min_level: int = logging.DEBUG) -> list[LogEntry]:
    """Entries of several files, in time order (stable for equal stamps), at or above ``min_level``."""
    entries = [entry for path in paths for entry in parse_entries(path)]
    entries.sort(key=lambda entry: entry.stamp)
    return [entry for entry in entries if entry.level_number >= min_level]


def follow_entries(
    folder: Path,
    *,
    min_level: int = logging.DEBUG,
    poll_s: float = 0.2,
    stop: threading.Event | None = None,
    from_start: bool = False,
) -> Iterator[LogEntry]:
    """Yield entries appended to any ``*.log`` file of ``folder`` after this call (like ``tail -f``).

    The current end of every file is taken when this function is called, not at the first ``next()``
    (with ``from_start``, every file is read from its start). Files that appear later are read from
    their start. The iteration ends when ``stop`` is set.
    """
    offsets = {
        path: 0 if from_start else path.stat().st_size
        for path in folder.glob("*.log")
        if not path.is_symlink()
    }
    return _follow(folder, offsets, min_level, poll_s, stop)


def _follow(
    folder: Path, offsets: dict[Path, int], min_level: int, poll_s: float, stop: threading.Event | None
) -> Iterator[LogEntry]:
    partial: dict[Path, str] = {}
    while stop is None or not stop.is_set():
        produced = False
        for path in sorted(folder.glob("*.log")):
            if path.is_symlink():
                continue  # not a log of the run: it could point anywhere
            offset = offsets.get(path, 0)
            try:
                size = path.stat().st_size
            except FileNotFoundError:
                continue
            if size < offset:
                offset = 0
            if size == offset:
                continue
            with path.open("rb") as handle:
                handle.seek(offset)
                chunk = handle.read(size - offset).decode("utf-8", errors="replace")
            offsets[path] = size
            lines = (partial.pop(path, "") + chunk).split("\n")
            if lines[-1]:
                partial[path] = lines[-1]
            for entry in parse_entries(path, lines[:-1]):
                if entry.level_number >= min_level:
                    produced = True
                    yield entry
        if not produced:
            time.sleep(poll_s)
