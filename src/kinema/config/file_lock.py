"""An exclusive lock shared by threads and processes that read-modify-write the same file.

``fcntl.flock`` on a sidecar ``<file>.lock`` (never on the data file itself, which is replaced by
``os.replace`` and so changes inode on every write). flock locks belong to an open file description, so
two threads of one process that each open the lock file exclude each other just as two processes do.
On Windows, where there is no flock, ``msvcrt.locking`` on the first byte of the sidecar does the same.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from kinema.errors import ConfigError, SourceLocation


def lock_path_for(path: Path) -> Path:
    """The sidecar lock file of ``path``."""
    return path.with_name(path.name + ".lock")


@contextmanager
def locked(path: str | Path) -> Iterator[None]:
    """Hold the exclusive lock of ``path`` (blocking until it is free) for the ``with`` body."""
    lock_file = lock_path_for(Path(path))
    try:
        descriptor = os.open(lock_file, os.O_RDWR | os.O_CREAT, 0o666)
    except OSError as error:
        raise ConfigError(
            f"cannot create the lock file: {error.strerror}", location=SourceLocation(str(lock_file))
        ) from None
    try:
        _acquire(descriptor)
        try:
            yield
        finally:
            _release(descriptor)
    finally:
        os.close(descriptor)


if sys.platform == "win32":  # pragma: no cover - exercised on Windows only
    import msvcrt

    def _acquire(descriptor: int) -> None:
        while True:
            try:
                msvcrt.locking(descriptor, msvcrt.LK_NBLCK, 1)
                return
            except OSError:
                time.sleep(0.005)

    def _release(descriptor: int) -> None:
        os.lseek(descriptor, 0, os.SEEK_SET)
        msvcrt.locking(descriptor, msvcrt.LK_UNLCK, 1)

else:
    import fcntl

    def _acquire(descriptor: int) -> None:
        fcntl.flock(descriptor, fcntl.LOCK_EX)

    def _release(descriptor: int) -> None:
        fcntl.flock(descriptor, fcntl.LOCK_UN)
