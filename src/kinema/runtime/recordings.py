"""Every objective run recorded as a ``.btlog`` file (BT.CPP FileLogger2 format) that Groot2 replays.

The agent writes one file per run into the run folder's ``recordings/`` (``kinema logs --recordings``
lists them, ``kinema export-logs`` zips them with the logs): ``<YYYYmmdd-HHMMSS-micro>-<objective>.btlog``.
Sizes are bounded twice: a recording stops growing at ``max_file_bytes`` (its run keeps going; the log
says so), and before a new recording starts the oldest ones are deleted until the folder holds fewer
than ``keep`` files and at most ``max_total_bytes``.

Beside each ``.btlog`` (which holds only the tree and its transitions, as BT.CPP's format does) the
blackboard snapshots the objective server takes while the run goes (at most 10 a second) are kept in
``<same name>.blackboard.jsonl``: one JSON object a line, ``{"t_us": <microseconds since the
recording's first timestamp>, "entries": [[scope, key, type, value as YAML], ...]}``, written only when
something changed. ``kinema ui --replay`` shows both together.
"""

from __future__ import annotations

import json
import logging
import re
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinema.bt.btlog import SUFFIX, BtlogWriter, Recording, coded_records, pack_coded_transitions, read_btlog
from kinema.errors import KinemaError
from kinema.runtime.background_work import HandOff

if TYPE_CHECKING:
    from kinema.bt.tree import Tree
    from kinema.runtime.node_status import NodeStatusBatch
    from kinema.runtime.objective_server import ObjectiveRun
    from kinema.runtime.objective_status import ObjectiveStatus
    from kinema.runtime.result import ObjectiveResult

log = logging.getLogger("kinema.recordings")

FOLDER_NAME = "recordings"
DEFAULT_MAX_FILE_BYTES = 16 * 1024 * 1024
DEFAULT_MAX_TOTAL_BYTES = 256 * 1024 * 1024
DEFAULT_KEEP = 200
BLACKBOARD_SUFFIX = ".blackboard.jsonl"
# How long the end of a run waits for its last blackboard snapshot to be written.
DRAIN_AT_RUN_END_S = 0.5


def blackboard_path(recording: Path) -> Path:
    """The blackboard file beside a ``.btlog`` recording."""
    return recording.with_name(recording.stem + BLACKBOARD_SUFFIX)


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


class _BlackboardFile:
    """One run's ``.blackboard.jsonl``, written by the recorder's worker thread only."""

    def __init__(self, file: Any, max_bytes: int) -> None:
        self.file = file
        self.max_bytes = max_bytes
        self.size = 0
        self.last: list[list[str]] | None = None

    def write(self, offset_us: int, entries: list[tuple[str, str, str, Any]]) -> None:
        from kinema.runtime.blackboard_text import render_value

        if self.file is None:
            return
        rendered = [[scope, key, type_name, render_value(value)] for scope, key, type_name, value in entries]
        if rendered == self.last:
            return
        self.last = rendered
        line = json.dumps({"t_us": max(0, offset_us), "entries": rendered}, ensure_ascii=False) + "\n"
        if self.size + len(line) > self.max_bytes:
            return
        try:
            self.file.write(line)
            self.file.flush()
        except OSError as error:
            log.warning("blackboard recording stopped: %s", error)
            self.close()
            return
        self.size += len(line)

    def close(self) -> None:
        if self.file is not None:
            self.file.close()
            self.file = None


class RunRecorder:
    """An objective-server listener writing each run's transitions into its own ``.btlog`` file.

    Its listener methods run on the tick thread (see
    :class:`~kinema.runtime.objective_server.TreeListener`); blackboard snapshots are rendered and written
    by a worker thread of its own (:class:`~kinema.runtime.background_work.HandOff`): the tick thread only
    hands them over. :meth:`close` stops that thread.
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
        self._blackboard: _BlackboardFile | None = None
        self._work = HandOff("kinema-recording")
        self._clock: Any = None
        self._tree: Tree | None = None
        self._t0 = 0.0
        self._objective = ""
        # the 9-byte record of every code of the run's node table (made at its first batch)
        self._records: Any = None
        self._records_table = 0

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
        self._clock = tree.clock
        self._tree = tree
        self._t0 = tree.clock.now()
        self._objective = objective_name
        try:
            self._blackboard = _BlackboardFile(
                open(blackboard_path(path), "w", encoding="utf-8"), self.max_file_bytes
            )
        except OSError as error:
            log.warning("not recording the blackboard of %r: %s", objective_name, error)
            self._blackboard = None

    def on_node_status(self, objective_name: str, changes: NodeStatusBatch) -> None:
        writer = self._writer
        if writer is None:
            return
        was_truncated = writer.truncated
        table = changes.table
        if self._records_table != table.id:
            self._records = coded_records(table.uids)
            self._records_table = table.id
        t0 = self._t0
        # rounded half to even, as numpy's rint
        offsets = [round((stamp - t0) * 1e6) for stamp in changes.stamps]
        try:
            writer.write_packed(
                pack_coded_transitions(self._records, changes.code_array(), offsets, changes.starts)
            )
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
        # A run that ends on an exception (or a stop) may end without its last transitions (the halt)
        # having been reported: record what the tree shows now, so a replay does not end RUNNING.
        writer, tree = self._writer, self._tree
        if writer is not None and tree is not None and self._clock is not None:
            offset = round((self._clock.now() - self._t0) * 1e6)
            try:
                recorded = writer.last_statuses()
            except OSError:
                recorded = {}
            missing = [
                (offset, node.uid, int(node.status))
                for node in tree.nodes()
                if int(node.status) != recorded.get(node.uid & 0xFFFF, 0)
            ]
            try:
                writer.write(missing)
            except OSError as error:
                log.warning("recording %s: the end of the run was not written: %s", writer.path, error)
        self._tree = None
        self._close_writer()

    def on_status(self, status: ObjectiveStatus, objective_name: str) -> None:
        pass

    def on_blackboard(self, objective_name: str, entries: list[tuple[str, str, str, Any]]) -> None:
        target = self._blackboard
        if target is None or self._writer is None:
            return
        offset = round((self._clock.now() - self._t0) * 1e6) if self._clock is not None else 0
        self._work.submit(lambda: target.write(offset, entries), key=id(target))

    def close(self) -> None:
        """Close the file being written and stop the worker thread."""
        self._close_writer()
        self._work.close()

    def _close_blackboard(self) -> None:
        target, self._blackboard = self._blackboard, None
        if target is not None:
            self._work.submit(target.close)
            # The run's last snapshot is written when the recording ends (rendering is capped: a few ms).
            if not self._work.drain(DRAIN_AT_RUN_END_S):
                log.warning("the blackboard recording was still being written when its run ended")

    def _close_writer(self) -> None:
        self._close_blackboard()
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
            blackboard_path(oldest.path).unlink(missing_ok=True)


@dataclass(frozen=True)
class BlackboardFrame:
    """The blackboard at ``t_us`` microseconds after the recording's start: (scope, key, type, value)."""

    t_us: int
    entries: tuple[tuple[str, str, str, str], ...]


@dataclass
class Replay:
    """A recorded run: the ``.btlog`` and, when it was recorded, the blackboard beside it."""

    recording: Recording
    frames: list[BlackboardFrame] = field(default_factory=list)

    def blackboard_at(self, t_us: int) -> BlackboardFrame | None:
        """The blackboard as of a transition at ``t_us``: the first snapshot taken at or after it.

        Snapshots are taken after a tick (at most 10 a second), so the first one after a transition
        holds what the tick that made it wrote. Past the last snapshot, the last one (None: none).
        """
        for frame in self.frames:
            if frame.t_us >= t_us:
                return frame
        return self.frames[-1] if self.frames else None


def load_replay(path: Path) -> Replay:
    """Read a recording and its blackboard file (if any).

    Raises:
        BtlogError: the ``.btlog`` is missing or not a FileLogger2 recording.
    """
    recording = read_btlog(path)
    frames: list[BlackboardFrame] = []
    side = blackboard_path(Path(path))
    if side.is_file():
        for number, line in enumerate(side.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
            try:
                data = json.loads(line)
                entries = tuple(tuple(str(part) for part in entry) for entry in data["entries"])
                frames.append(BlackboardFrame(int(data["t_us"]), entries))  # type: ignore[arg-type]
            except (ValueError, KeyError, TypeError):
                log.warning("%s:%d: not a blackboard snapshot; skipped", side, number)
    return Replay(recording, frames)


def latest_recording() -> Path:
    """The newest recording of the newest run that has one.

    Raises:
        KinemaError: no run recorded anything yet.
    """
    from kinema.runtime.run_folder import list_runs, runs_dir

    for run in reversed(list_runs()):
        files = list_recordings(run.path / FOLDER_NAME)
        if files:
            return files[-1].path
    raise KinemaError(f"no recordings in {runs_dir()}: run an objective under `kinema run` first")
