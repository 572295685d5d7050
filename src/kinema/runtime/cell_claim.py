"""The claim a ``kinema run`` holds on its cell's roles on this machine: one agent, one set of drivers.

Looking at the network before starting (:func:`kinema.runtime.cell.check_cell_is_free`) cannot tell two
``kinema run`` started in the same second apart: both look, both see nothing, both start. So each also
takes an exclusive lock per role it starts (``agent``, ``drivers``) on a file named after the router's
endpoint and the domain, in the machine's temporary folder, and holds it while it runs; the kernel drops
it when the process ends, however it ends. The second one to ask waits until the first one's members are
on the network and refuses with the usual message (or, if they never show, names the process holding the
claim). ``-n`` and ``-o`` take one role each, so the two halves of a cell still start side by side.

Two machines that start the same role for one router at once are not seen here (the lock is local); the
cell watch reports them once both are up.
"""

from __future__ import annotations

import os
import re
import tempfile
from pathlib import Path
from typing import IO

AGENT, DRIVERS = "agent", "drivers"


def claim_path(endpoint: str, domain_id: int, role: str) -> Path:
    """The lock file of ``role`` for the router at ``endpoint`` on ``domain_id``."""
    safe = re.sub(r"[^A-Za-z0-9.]+", "_", endpoint).strip("_")
    return Path(tempfile.gettempdir()) / f"kinema-cell-{domain_id}-{safe}-{role}.lock"


class CellClaim:
    """The locks of one ``kinema run`` (see the module docstring). Release with :meth:`release`."""

    def __init__(self) -> None:
        self._files: list[IO[str]] = []

    def take(self, endpoint: str, domain_id: int, roles: list[str]) -> str | None:
        """Take every role's lock; None on success, else the pid text of the holder of one (nothing kept)."""
        import fcntl

        for role in roles:
            path = claim_path(endpoint, domain_id, role)
            try:
                file = open(path, "a+", encoding="utf-8")
            except OSError:
                continue  # an unwritable temp folder: the network check alone decides
            try:
                fcntl.flock(file.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                file.seek(0)
                holder = file.read().strip() or "?"
                file.close()
                self.release()
                return holder
            file.seek(0)
            file.truncate()
            file.write(str(os.getpid()))
            file.flush()
            self._files.append(file)
        return None

    def release(self) -> None:
        """Drop the locks (the process ending drops them too)."""
        files, self._files = self._files, []
        for file in files:
            file.close()
