"""Turn an exception raised by behavior code into one message naming the behavior, plugin and line.

The engine adds the node path when it wraps the error (``Exception in node 'Root/Add' [MyBehavior]:
...``), so the objective's failure message names all four: node path, behavior, plugin and the line
of the author's file that raised.
"""

from __future__ import annotations

import traceback
from pathlib import Path

from kinema.bt.errors import BTError, BTRuntimeError
from kinema.errors import KinemaError, SourceLocation

_KINEMA_SRC = Path(__file__).resolve().parent.parent


class BehaviorExecutionError(BTRuntimeError):
    """Behavior code raised while the tree ran it."""


def author_location(error: BaseException) -> SourceLocation | None:
    """The innermost traceback frame outside Kinema's own source: the line in the author's file."""
    frames = traceback.extract_tb(error.__traceback__)
    for frame in reversed(frames):
        try:
            ours = Path(frame.filename).resolve().is_relative_to(_KINEMA_SRC)
        except (OSError, ValueError):
            ours = False
        if not ours:
            return SourceLocation(frame.filename, frame.lineno or 0)
    return None


def behavior_fault(node: object, error: BaseException, stage: str) -> BTError:
    """Wrap ``error`` raised in ``stage`` (``tick``, ``do_work``, ``process_response`` ...) of ``node``.

    Errors that already carry an actionable message (engine and Kinema errors, such as a missing input
    port) keep it, with the behavior and plugin added; other exceptions are bugs and get the file:line
    of the author's code.
    """
    if isinstance(error, BehaviorExecutionError):
        return error
    behavior = getattr(node, "registration_id", type(node).__name__)
    plugin = getattr(type(node), "kinema_plugin", "")
    who = f"behavior '{behavior}'" + (f" of plugin '{plugin}'" if plugin else "")
    if isinstance(error, KinemaError):
        return BehaviorExecutionError(f"{who} failed in {stage}: {error.message}", location=error.location)
    location = author_location(error)
    where = f" at {location}" if location is not None else ""
    return BehaviorExecutionError(f"{who} raised in {stage}{where}: {type(error).__name__}: {error}")
