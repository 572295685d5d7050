"""How a run ended, read from the message the objective server publishes when it fails or is cancelled.

The agent publishes ``objective 'X' failed (FAILURE): ...`` (error) or ``objective 'X' was cancelled: ...``
(warning) on its log stream when a run ends badly (:meth:`kinema.runtime.result.ObjectiveResult.__str__`);
that message is what the UI keeps on screen until dismissed.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

_ENDED = re.compile(r"^objective (['\"])(?P<name>.*?)\1 (?P<how>failed|was cancelled)\b")


@dataclass(frozen=True)
class RunOutcome:
    """A run that ended badly: ``outcome`` is ``Failure`` or ``Cancelled``."""

    objective_name: str
    outcome: str
    message: str


def parse_outcome(message: str) -> RunOutcome | None:
    """The outcome a log message announces, or None for any other message."""
    found = _ENDED.match(message)
    if found is None:
        return None
    outcome = "Failure" if found.group("how") == "failed" else "Cancelled"
    return RunOutcome(found.group("name"), outcome, message)


@dataclass(frozen=True)
class FailureText:
    """A failure message laid out for reading: what went wrong first, where second, notes last.

    Attributes:
        headline: the exception (``ValueError: ...``) or the failing node's own message.
        where: the XML file:line, node path and Python file:line that lead to it ("" if none).
        notes: sentences the runtime added (``note: ...``: older code runs, a parameter to give).
    """

    headline: str
    where: str
    notes: tuple[str, ...]


_PREFIX = re.compile(r"^objective (['\"]).*?\1 (?:failed(?: \([A-Z_]+\))?|was cancelled)(?::\s*|$)")
_EXCEPTION = re.compile(r"\b[A-Z][A-Za-z0-9_]*(?:Error|Exception|Interrupt|Exit|Timeout)\b: ")
_NODE = re.compile(r"node '[^']*' \[[^\]]*\]: ")


def failure_text(message: str) -> FailureText:
    """Split a run's message (``objective 'X' failed (FAILURE): ...``) into headline, where and notes.

    The runtime writes the path first and the exception last, which a box of a few lines or a tree line
    cuts at the exception: this puts the exception first.
    """
    body, *notes = message.split("\nnote: ")
    # "objective 'X' failed (FAILURE): objective 'X' failed: node ...": the server's prefix, twice.
    while True:
        stripped = _PREFIX.sub("", body, count=1)
        if stripped == body:
            break
        body = stripped
    found = list(_EXCEPTION.finditer(body))
    if found:
        start = found[-1].start()
        headline, where = body[start:], body[:start]
    else:
        nodes = list(_NODE.finditer(body))
        if nodes:
            headline, where = body[nodes[-1].end() :], body[: nodes[-1].end()]
        else:
            headline, where = body, ""
    where = where.rstrip().rstrip(":").rstrip()
    return FailureText(headline.strip() or body.strip(), where, tuple(note.strip() for note in notes))
