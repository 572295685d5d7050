"""Replacing a file atomically: readers see the old content or the new one, never half of either.

The new content goes to a temporary file in the same folder (same file system, so ``os.replace`` is an
atomic rename), is flushed to disk, and then takes the old file's name. An existing file's permission
bits are kept. A writer killed between the two steps leaves its temporary file
(``.<name>.<random>.tmp``) behind; :func:`remove_temporaries_of` deletes those, for callers that
know no other writer is busy (they hold the file's lock).
"""

from __future__ import annotations

import contextlib
import glob
import os
import tempfile
from pathlib import Path

from kinema.errors import ConfigError, KinemaError, SourceLocation


def _read_umask() -> int:
    # os.umask can only be read by setting it; done once at import, before threads write files.
    umask = os.umask(0o022)
    os.umask(umask)
    return umask


_UMASK = _read_umask()


def atomic_write_bytes(path: str | Path, data: bytes, *, error: type[KinemaError] = ConfigError) -> None:
    """Replace ``path`` with ``data`` atomically (creating it when it does not exist).

    Raises:
        KinemaError: (of class ``error``) the folder is missing or not writable, the disk is full, ...
    """
    path = Path(path)
    try:
        _replace(path, data)
    except OSError as exc:
        raise error(
            f"cannot write the file: {exc.strerror or exc}", location=SourceLocation(str(path))
        ) from None


def _replace(path: Path, data: bytes) -> None:
    try:
        mode: int | None = path.stat().st_mode & 0o7777
    except FileNotFoundError:
        mode = None
    descriptor, temporary = tempfile.mkstemp(prefix=temporary_prefix(path), suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(descriptor, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        if mode is not None:
            os.chmod(temporary, mode)
        else:
            os.chmod(temporary, 0o666 & ~_UMASK)
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temporary)
        raise


def temporary_prefix(path: Path) -> str:
    """The name prefix of the temporary files written for ``path``."""
    return f".{path.name}."


def remove_temporaries_of(path: str | Path) -> list[Path]:
    """Delete the temporary files a killed writer of ``path`` left behind; return what was deleted.

    Only call it while no other writer of ``path`` can be busy (e.g. under the file's lock).
    """
    path = Path(path)
    removed = []
    try:
        candidates = list(path.parent.glob(f"{glob.escape(temporary_prefix(path))}*.tmp"))
    except OSError:
        return []
    for candidate in candidates:
        with contextlib.suppress(OSError):
            candidate.unlink()
            removed.append(candidate)
    return removed


def atomic_write_text(path: str | Path, text: str, *, error: type[KinemaError] = ConfigError) -> None:
    """Replace ``path`` with UTF-8 ``text`` atomically (see :func:`atomic_write_bytes`)."""
    atomic_write_bytes(path, text.encode("utf-8"), error=error)
