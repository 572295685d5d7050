"""Watch folders and report each burst of changes once (watchdog, debounced, with a polling fallback).

Editors save in many ways — write in place, write a temp file and rename it over the original, write a
backup first, save several times in a row — and each produces a different burst of file-system
events. The watcher waits until a folder has been quiet for ``debounce`` seconds, then compares a
fingerprint of the folder's relevant files with the last one it reported: a burst yields one callback,
and a burst that changed nothing (a touch, a duplicate event) yields none.
"""

from __future__ import annotations

import hashlib
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

from watchdog.events import FileSystemEvent, FileSystemEventHandler
from watchdog.observers.api import BaseObserver

OnChange = Callable[[Path, tuple[Path, ...], float], None]
"""``on_change(folder, changed_paths, first_event_time)``; first_event_time is ``time.monotonic()``."""

_IGNORED_PARTS = {"__pycache__", ".git", ".mypy_cache", ".pytest_cache", ".ruff_cache"}


def _is_relevant(path: Path, suffixes: tuple[str, ...]) -> bool:
    if any(part in _IGNORED_PARTS for part in path.parts):
        return False
    name = path.name
    # Editor temp and backup files (".file.swp", "file~", "#file#", ".goutputstream-XYZ").
    if name.startswith((".", "#")) or name.endswith("~"):
        return False
    return path.suffix in suffixes


def fingerprint(folder: Path, suffixes: tuple[str, ...]) -> str:
    """A digest of the names and contents of the relevant files under ``folder``."""
    digest = hashlib.blake2b(digest_size=16)
    if folder.is_dir():
        for path in sorted(folder.rglob("*")):
            if path.is_file() and _is_relevant(path.relative_to(folder), suffixes):
                digest.update(str(path.relative_to(folder)).encode())
                try:
                    digest.update(path.read_bytes())
                except OSError:
                    digest.update(b"<unreadable>")
    return digest.hexdigest()


@dataclass
class _Watched:
    folder: Path
    suffixes: tuple[str, ...]
    on_change: OnChange
    last_fingerprint: str
    pending: set[Path] = field(default_factory=set)
    first_event: float = 0.0
    last_event: float = 0.0


class _Forwarder(FileSystemEventHandler):
    def __init__(self, watcher: DirectoryWatcher, folder: Path) -> None:
        self._watcher = watcher
        self._folder = folder

    def on_any_event(self, event: FileSystemEvent) -> None:
        if event.is_directory or event.event_type in ("opened", "closed_no_write"):
            return
        for raw in (getattr(event, "dest_path", ""), event.src_path):
            if raw:
                self._watcher.notify(self._folder, Path(str(raw)))


class DirectoryWatcher:
    """Calls ``on_change`` once per quiet burst of relevant changes in each watched folder.

    Args:
        debounce: seconds a folder must be quiet before its changes are reported.
        polling: use stat polling instead of the OS's notification API (network file systems, containers
            without inotify); chosen automatically when the native observer cannot start.
        poll_interval: seconds between polls in polling mode.
    """

    def __init__(self, *, debounce: float = 0.08, polling: bool = False, poll_interval: float = 0.1) -> None:
        self.debounce = debounce
        self.polling = polling
        self.poll_interval = poll_interval
        self._watched: dict[Path, _Watched] = {}
        self._lock = threading.Condition()
        self._observer: BaseObserver | None = None
        self._worker: threading.Thread | None = None
        self._stopping = False
        # A burst taken from pending whose callback has not returned yet (see settle).
        self._reporting = False

    def add(self, folder: Path, suffixes: Iterable[str], on_change: OnChange) -> None:
        """Watch ``folder`` (recursively) for files ending in one of ``suffixes`` (e.g. ``.py``)."""
        folder = Path(folder).resolve()
        suffix_tuple = tuple(suffixes)
        with self._lock:
            self._watched[folder] = _Watched(
                folder, suffix_tuple, on_change, fingerprint(folder, suffix_tuple)
            )
            if self._observer is not None:
                self._schedule(folder)

    def notify(self, folder: Path, path: Path) -> None:
        """Record that ``path`` under ``folder`` changed (called from watchdog's thread)."""
        with self._lock:
            watched = self._watched.get(folder)
            if watched is None:
                return
            try:
                relative = path.resolve().relative_to(folder)
            except ValueError:
                return
            if not _is_relevant(relative, watched.suffixes):
                return
            now = time.monotonic()
            if not watched.pending:
                watched.first_event = now
            watched.pending.add(path)
            watched.last_event = now
            self._lock.notify_all()

    def start(self) -> None:
        """Start watching; falls back to polling when the native observer cannot start."""
        with self._lock:
            if self._observer is not None:
                return
            self._stopping = False
            self._observer = self._start_observer()
        self._worker = threading.Thread(target=self._run, name="kinema-hot-reload", daemon=True)
        self._worker.start()

    def stop(self) -> None:
        """Stop watching and wait for the worker threads to end."""
        with self._lock:
            self._stopping = True
            observer, self._observer = self._observer, None
            self._lock.notify_all()
        if observer is not None:
            observer.stop()
            observer.join(timeout=5)
        if self._worker is not None:
            self._worker.join(timeout=5)
            self._worker = None

    def __enter__(self) -> DirectoryWatcher:
        self.start()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.stop()

    def _start_observer(self) -> BaseObserver:
        from watchdog.observers import Observer
        from watchdog.observers.polling import PollingObserver

        if not self.polling:
            observer = Observer()
            try:
                for folder in self._watched:
                    observer.schedule(_Forwarder(self, folder), str(folder), recursive=True)
                observer.start()
                return observer
            except OSError:
                # inotify watch limits, or a file system without notifications: poll instead.
                self.polling = True
        observer = PollingObserver(timeout=self.poll_interval)
        for folder in self._watched:
            observer.schedule(_Forwarder(self, folder), str(folder), recursive=True)
        observer.start()
        return observer

    def _schedule(self, folder: Path) -> None:
        if folder.is_dir() and self._observer is not None:
            self._observer.schedule(_Forwarder(self, folder), str(folder), recursive=True)

    def _run(self) -> None:
        while True:
            due: list[tuple[_Watched, tuple[Path, ...], float]] = []
            with self._lock:
                if self._stopping:
                    return
                now = time.monotonic()
                wait = None
                for watched in self._watched.values():
                    if not watched.pending:
                        continue
                    quiet_at = watched.last_event + self.debounce
                    if now >= quiet_at:
                        due.append((watched, tuple(sorted(watched.pending)), watched.first_event))
                        watched.pending.clear()
                    else:
                        wait = quiet_at - now if wait is None else min(wait, quiet_at - now)
                if not due:
                    self._lock.wait(timeout=wait)
                    continue
                self._reporting = True
            try:
                for watched, paths, first_event in due:
                    current = fingerprint(watched.folder, watched.suffixes)
                    if current == watched.last_fingerprint:
                        continue
                    watched.last_fingerprint = current
                    watched.on_change(watched.folder, paths, first_event)
            finally:
                with self._lock:
                    self._reporting = False
                    self._lock.notify_all()

    def settle(self, timeout: float) -> bool:
        """Wait until every change seen so far is reported and its callback has returned: what asks next
        (a run) sees a file saved a moment ago, not the version before it. True once settled; False after
        ``timeout`` while changes keep coming or a callback still runs, and at once on the watcher's own
        thread (a callback that asks must not wait for itself)."""
        if threading.current_thread() is self._worker:
            return False
        deadline = time.monotonic() + timeout
        with self._lock:
            while not self._stopping and (
                self._reporting or any(watched.pending for watched in self._watched.values())
            ):
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self._lock.wait(remaining)
        return True
