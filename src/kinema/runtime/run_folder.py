"""Per-run log folders under the user's state directory.

Every ``kinema run`` writes its logs (the agent's, each driver's, the supervisor's) into a fresh folder
``<state>/kinema/runs/<YYYYmmdd-HHMMSS-micro>-<config>/``; ``<state>`` is ``$XDG_STATE_HOME`` (or
``~/.local/state``) on Linux and the platform's equivalent elsewhere. ``kinema logs`` reads the newest
folder and ``kinema export-logs`` zips it.
"""

from __future__ import annotations

import os
import re
import stat
import time
from dataclasses import dataclass
from pathlib import Path

from kinema.errors import KinemaError

# A run folder is kept for later inspection; only this many of the newest are kept around.
KEEP_RUNS = 20


def state_dir() -> Path:
    """Kinema's state directory (created on demand)."""
    import platformdirs

    path = platformdirs.user_state_path("kinema")
    path.mkdir(parents=True, exist_ok=True)
    return path


def runs_dir() -> Path:
    """The folder holding one sub-folder per run."""
    path = state_dir() / "runs"
    path.mkdir(parents=True, exist_ok=True)
    return path


@dataclass(frozen=True)
class RunFolder:
    """The log folder of one run."""

    path: Path

    @property
    def name(self) -> str:
        """The folder's name, ``<timestamp>-<config>``."""
        return self.path.name

    def log_file(self, process: str) -> Path:
        """The log file of one process of the run (``agent``, ``supervisor``, a driver's name)."""
        return self.path / f"{process}.log"

    def log_files(self) -> list[Path]:
        """Every log file in the folder, sorted by name (symbolic links are not log files of the run)."""
        return [path for path in self.files() if path.parent == self.path and path.suffix == ".log"]

    def files(self) -> list[Path]:
        """Every regular file under the folder, sorted, never through a symbolic link.

        A link (to a file or a folder) could point anywhere on the machine; what ``kinema logs`` prints
        and ``kinema export-logs`` archives must come from the run folder itself.
        """
        found = []
        for folder, subfolders, names in os.walk(self.path, followlinks=False):
            base = Path(folder)
            subfolders[:] = [name for name in subfolders if not (base / name).is_symlink()]
            found += [base / name for name in names if _regular_file(base / name)]
        return sorted(found)

    def links(self) -> list[Path]:
        """The symbolic links under the folder (skipped by :meth:`files`), sorted."""
        found = []
        for folder, subfolders, names in os.walk(self.path, followlinks=False):
            base = Path(folder)
            found += [base / name for name in (*subfolders, *names) if (base / name).is_symlink()]
        return sorted(found)

    @classmethod
    def create(cls, config_name: str, *, keep: int | None = KEEP_RUNS) -> RunFolder:
        """Create a fresh folder for a run of ``config_name`` and prune the oldest beyond ``keep``
        (None: prune later, with :func:`prune_runs`, once the run has started).
        """
        safe = re.sub(r"[^A-Za-z0-9_.-]+", "_", config_name) or "run"
        now = time.time()
        # The stamp leads the name, so names sort in creation order (mtimes can tie).
        stamp = time.strftime("%Y%m%d-%H%M%S", time.localtime(now)) + f"-{int(now * 1e6) % 1_000_000:06d}"
        base = runs_dir()
        path = base / f"{stamp}-{safe}"
        suffix = 1
        while path.exists():
            suffix += 1
            path = base / f"{stamp}-{safe}-{suffix}"
        path.mkdir(parents=True)
        if keep is not None:
            _prune(base, keep)
        return cls(path)

    def discard(self) -> None:
        """Remove the folder of a run that started nothing (a refused ``kinema run``), so that it is
        neither the latest run for ``kinema logs`` nor counted against the runs kept.
        """
        import logging
        import shutil

        root = logging.getLogger()
        for handler in list(root.handlers):
            if isinstance(handler, logging.FileHandler) and Path(handler.baseFilename).parent == self.path:
                root.removeHandler(handler)
                handler.close()
        shutil.rmtree(self.path, ignore_errors=True)

    @classmethod
    def latest(cls) -> RunFolder:
        """The newest run's folder; raises KinemaError when there has been no run yet."""
        runs = list_runs()
        if not runs:
            raise KinemaError(f"no run logs in {runs_dir()}: start one with `kinema run`")
        return runs[-1]


def list_runs() -> list[RunFolder]:
    """Every run folder, oldest first (a symbolic link in the runs folder is not a run)."""
    base = runs_dir()
    return [RunFolder(p) for p in sorted(p for p in base.iterdir() if p.is_dir() and not p.is_symlink())]


def _regular_file(path: Path) -> bool:
    try:
        return stat.S_ISREG(path.lstat().st_mode)
    except OSError:
        return False


def prune_runs(keep: int = KEEP_RUNS) -> None:
    """Remove the oldest run folders beyond ``keep``."""
    _prune(runs_dir(), keep)


def _prune(base: Path, keep: int) -> None:
    import shutil

    folders = sorted(p for p in base.iterdir() if p.is_dir())
    for old in folders[: max(0, len(folders) - keep)]:
        shutil.rmtree(old, ignore_errors=True)
