"""Every objective run recorded as a ``.btlog`` file (BT.CPP FileLogger2 format) that Groot2 replays.

The agent writes one file per run into the run folder's ``recordings/`` (``kinema logs --recordings``
lists them, ``kinema export-logs`` zips them with the logs): ``<YYYYmmdd-HHMMSS-micro>-<objective>.btlog``.
Sizes are bounded twice: a recording stops growing at ``max_file_bytes`` (its run keeps going; the log
says so), and before a new recording starts the oldest ones are deleted until the folder holds fewer
than ``keep`` files and at most ``max_total_bytes``.
"""

from __future__ import annotations

import logging
import re
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinema.bt.btlog import SUFFIX, BtlogWriter
from kinema.errors import KinemaError

if TYPE_CHECKING:
    from kinema.bt.tree import Tree
    from kinema.runtime.objective_server import NodeStatusChange, ObjectiveRun
    from kinema.runtime.objective_status import ObjectiveStatus
    from kinema.runtime.result import ObjectiveResult

log = logging.getLogger("kinema.recordings")

FOLDER_NAME = "recordings"
DEFAULT_MAX_FILE_BYTES = 16 * 1024 * 1024
DEFAULT_MAX_TOTAL_BYTES = 256 * 1024 * 1024
DEFAULT_KEEP = 200


@dataclass(frozen=True)
class RecordingFile:
    """One recording on disk."""

    path: Path
    size: int

    @property
    def objective_name(self) -> str:
        """The objective the file recorded (from its name)."""
        return self.path.stem.split("-", 3)[-1]


def list_recordings(folder: Path) -> list[RecordingFile]:
    """The ``.btlog`` files of a recordings folder, oldest first (names start with the time)."""
    if not folder.is_dir():
        return []
    return [RecordingFile(p, p.stat().st_size) for p in sorted(folder.glob(f"*{SUFFIX}"))]


class RunRecorder:
    """An objective-server listener writing each run's transitions into its own ``.btlog`` file.

    All methods run on the tick thread (see :class:`~kinema.runtime.objective_server.TreeListener`).
    """

    def __init__(
        self,
        folder: Path,
        *,
        max_file_bytes: int = DEFAULT_MAX_FILE_BYTES,
        max_total_bytes: int = DEFAULT_MAX_TOTAL_BYTES,
        keep: int = DEFAULT_KEEP,
    ) -> None:
        if max_file_bytes <= 0 or max_total_bytes < max_file_bytes or keep < 1:
            raise KinemaError(
                f"recording limits must satisfy 0 < max_file_bytes <= max_total_bytes and keep >= 1; got "
                f"{max_file_bytes}, {max_total_bytes}, {keep}"
            )
        self.folder = Path(folder)
        self.max_file_bytes = max_file_bytes
        self.max_total_bytes = max_total_bytes
        self.keep = keep
        self._writer: BtlogWriter | None = None
        self._t0 = 0.0
        self._objective = ""

    @property
    def current(self) -> Path | None:
        """The file being written, if a run is being recorded."""
        return self._writer.path if self._writer is not None else None

    def on_tree_loaded(self, objective_name: str, tree: Tree) -> None:
        from kinema.bt.model_xml import write_tree_to_xml

        self._close_writer()
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            self._rotate()
            path = self._new_path(objective_name)
            self._writer = BtlogWriter(path, write_tree_to_xml(tree), max_bytes=self.max_file_bytes)
        except (OSError, KinemaError) as error:
            log.warning("not recording objective %r: %s", objective_name, error)
            self._writer = None
            return
        self._t0 = tree.clock.now()
        self._objective = objective_name

    def on_node_status(self, objective_name: str, changes: list[NodeStatusChange]) -> None:
        writer = self._writer
        if writer is None:
            return
        t0 = self._t0
        was_truncated = writer.truncated
        try:
            writer.write((round((c.timestamp - t0) * 1e6), c.uid, c.status) for c in changes)
        except OSError as error:
            log.warning("recording %s stopped: %s", writer.path, error)
            self._close_writer()
            return
        if writer.truncated and not was_truncated:
            log.warning(
                "recording %s reached its size cap (%d bytes): later transitions of %r are not recorded",
                writer.path,
                self.max_file_bytes,
                objective_name,
            )

    def on_run_finished(self, run: ObjectiveRun, result: ObjectiveResult) -> None:
        self._close_writer()

    def on_status(self, status: ObjectiveStatus, objective_name: str) -> None:
        pass

    def on_blackboard(self, objective_name: str, entries: list[tuple[str, str, str, Any]]) -> None:
        pass

    def close(self) -> None:
        """Close the file being written."""
        self._close_writer()

    def _close_writer(self) -> None:
        if self._writer is not None:
            self._writer.close()
            log.info("recorded %s (%d transitions)", self._writer.path, self._writer.count)
            self._writer = None

    def _new_path(self, objective_name: str) -> Path:
        safe = re.sub(r"[^A-Za-z0-9_.-]+", "_", objective_name).strip("_") or "objective"
        now = time.time()
        stamp = time.strftime("%Y%m%d-%H%M%S", time.localtime(now)) + f"-{int(now * 1e6) % 1_000_000:06d}"
        path = self.folder / f"{stamp}-{safe}{SUFFIX}"
        suffix = 1
        while path.exists():
            suffix += 1
            path = self.folder / f"{stamp}-{safe}-{suffix}{SUFFIX}"
        return path

    def _rotate(self) -> None:
        """Delete the oldest recordings so one more of at most ``max_file_bytes`` fits both limits."""
        files = list_recordings(self.folder)
        total = sum(f.size for f in files)
        while files and (len(files) >= self.keep or total + self.max_file_bytes > self.max_total_bytes):
            oldest = files.pop(0)
            total -= oldest.size
            oldest.path.unlink(missing_ok=True)
