"""Importing plugin code within a time limit: an import that never finishes is reported and abandoned.

Module-level code of a behavior package runs at import: a ``while True``, a blocking socket or a lock
that is never released there would otherwise hold the hot-reload thread (and the plugin host's lock)
forever, so no other package could reload and the runtime could not even start. Each import runs on a
thread of its own; when it has not finished after the limit, the caller gets a :class:`PluginError`
naming the line the import is stuck on, and the thread is left to finish or hang on its own (Python
cannot stop a thread). Whatever it imports later is thrown away by ``on_late_result``.
"""

from __future__ import annotations

import sys
import threading
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

from kinema.errors import PluginError, SourceLocation

T = TypeVar("T")

#: Seconds a plugin's import may take. Generous: importing numpy, scipy or pinocchio the first time on a
#: loaded machine takes seconds, but never this long.
IMPORT_TIME_LIMIT_S = 30.0


def call_with_deadline(
    function: Callable[[], T],
    seconds: float,
    *,
    what: str,
    root: Path | None = None,
    on_late_result: Callable[[T], None] | None = None,
) -> T:
    """Run ``function`` on a daemon thread; return its result or raise what it raised.

    Args:
        function: the import to run.
        seconds: the time limit.
        what: what is imported, for the message (``behavior package 'my_pkg'``).
        root: the package folder; the reported location is the innermost frame under it.
        on_late_result: called with the result should the abandoned import finish after all.

    Raises:
        PluginError: the import did not finish in time (with the file:line it is stuck on).
    """
    done = threading.Event()
    outcome: dict[str, Any] = {}
    abandoned = threading.Event()

    def target() -> None:
        try:
            outcome["value"] = function()
        except BaseException as error:  # handed to the caller's thread, which decides
            outcome["error"] = error
        finally:
            done.set()
        if abandoned.is_set() and "value" in outcome and on_late_result is not None:
            on_late_result(outcome["value"])

    thread = threading.Thread(target=target, name=f"kinema-import {what}", daemon=True)
    thread.start()
    if not done.wait(seconds):
        abandoned.set()
        location = _stuck_at(thread, root)
        raise PluginError(
            f"{what} did not finish importing within {seconds:g} s (module-level code that blocks or "
            "loops?); it was abandoned, the other packages load and reload as usual",
            location=location,
        )
    if "error" in outcome:
        raise outcome["error"]
    return outcome["value"]  # type: ignore[no-any-return]


def _stuck_at(thread: threading.Thread, root: Path | None) -> SourceLocation | None:
    """The line ``thread`` is executing: the innermost frame in a file under ``root`` if there is one."""
    frame = sys._current_frames().get(thread.ident or -1)
    if frame is None:
        return None
    frames = traceback.extract_stack(frame)
    if root is not None:
        resolved = Path(root).resolve()
        for entry in reversed(frames):
            try:
                if Path(entry.filename).resolve().is_relative_to(resolved):
                    return SourceLocation(entry.filename, entry.lineno or 0)
            except (OSError, ValueError):
                continue
    innermost = frames[-1] if frames else None
    return SourceLocation(innermost.filename, innermost.lineno or 0) if innermost is not None else None
