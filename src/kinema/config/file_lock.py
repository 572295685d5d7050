"""An exclusive lock shared by threads and processes that read-modify-write the same file.

``fcntl.flock`` on a sidecar ``<file>.lock`` (never on the data file itself, which is replaced by
``os.replace`` and so changes inode on every write). flock locks belong to an open file description, so
two threads of one process that each open the lock file exclude each other just as two processes do.
"""

from __future__ import annotations

import fcntl
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


def lock_path_for(path: Path) -> Path:
    """The sidecar lock file of ``path``."""
    return path.with_name(path.name + ".lock")


@contextmanager
def locked(path: str | Path) -> Iterator[None]:
    """Hold the exclusive lock of ``path`` (blocking until it is free) for the ``with`` body."""
    lock_file = lock_path_for(Path(path))
    descriptor = os.open(lock_file, os.O_RDWR | os.O_CREAT, 0o666)
    try:
        fcntl.flock(descriptor, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(descriptor, fcntl.LOCK_UN)
    finally:
        os.close(descriptor)
