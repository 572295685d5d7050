"""The one error hierarchy of Kinema.

Every error a user can cause is a :class:`KinemaError` with a message a person can act on: what was
wrong, where (``file:line``, package, node path) and, where it helps, the valid alternatives. Errors are
rendered once, at the edge (the CLI, the TUI, an SDK reply), never printed where they are raised.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass


@dataclass(frozen=True)
class SourceLocation:
    """A place in a source file: ``file:line`` (line is 1-based, 0 when unknown)."""

    file: str
    line: int = 0

    def __str__(self) -> str:
        return f"{self.file}:{self.line}" if self.line else self.file


class KinemaError(Exception):
    """Base class of every error Kinema raises on purpose."""

    def __init__(self, message: str, *, location: SourceLocation | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.location = location

    def __str__(self) -> str:
        if self.location is not None:
            return f"{self.location}: {self.message}"
        return self.message


class ConfigError(KinemaError):
    """A config package, workspace or YAML file is wrong."""


class ObjectiveError(KinemaError):
    """An objective could not be loaded, built or run."""


class PluginError(KinemaError):
    """A behavior plugin failed to load, register or reload."""


class TransportError(KinemaError):
    """A message could not be sent, received or answered over the transport."""


class NoAnswerError(TransportError):
    """No server answered a request within its timeout: none was reachable (not there, not discovered
    yet, or access rules keep the request from it), or the one that took it stayed silent."""


class MotionError(KinemaError):
    """Planning, kinematics or time parameterization failed."""


class DriverError(KinemaError):
    """A driver (simulation or hardware) failed or refused a command."""


class PerceptionError(KinemaError):
    """Bad input to perception maths: array shapes, sizes, point cloud or mesh files."""


class ScaffoldError(KinemaError):
    """A template could not be generated (bad name, existing folder, ...)."""


def did_you_mean(value: str, choices: Iterable[str], *, limit: int = 8) -> str:
    """Return a short sentence listing the valid alternatives, closest first.

    Used by error messages so a bad name always comes with what would have been accepted.
    """
    import difflib

    options = sorted(set(choices))
    if not options:
        return "there are none"
    close = difflib.get_close_matches(value, options, n=3, cutoff=0.6)
    # A cut listing keeps the close names: a "Valid:" list without the one suggested reads as a contradiction.
    shown = (
        options
        if len(options) <= limit
        else sorted({*close, *[o for o in options if o not in close][: limit - len(close)]})
    )
    listing = ", ".join(shown) + (f", … ({len(options)} in all)" if len(options) > limit else "")
    if close:
        return f"did you mean {' or '.join(repr(c) for c in close)}? Valid: {listing}"
    return f"valid: {listing}"


def zenoh_message(error: BaseException) -> str:
    """A zenoh error's text without the place in zenoh's Rust sources it ends with (``at /root/.cargo/
    .../lib.rs:1507.``): nothing a user can act on."""
    import re

    return re.sub(r"\s+at /\S+\.rs:\d+\.?$", "", str(error).strip())
