"""``.btlog`` recordings in BT.CPP's ``FileLogger2`` format: what Groot2 opens to replay a run.

Layout (little-endian), as BT.CPP 4.8's ``FileLogger2`` writes it:

==========  ================================================================================
18 bytes    ``BTCPP4-FileLogger2``
1 byte      protocol version, 1
4 bytes     int32 N: the length of the tree XML
N bytes     the tree as ``WriteTreeToXML(tree, add_metadata=true, add_builtin_models=true)``
8 bytes     int64: the first timestamp, microseconds since the Unix epoch
9 bytes     per transition: 6 bytes of microseconds since the first timestamp, uint16 node uid,
            uint8 new status (IDLE transitions included)
==========  ================================================================================

A recording is written as the run goes, so a file cut short by a crash still replays up to its last
whole transition; :func:`read_btlog` ignores a partial one at the end.
"""

from __future__ import annotations

import struct
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

from kinema.bt.errors import BTRuntimeError
from kinema.bt.status import NodeStatus
from kinema.errors import SourceLocation

if TYPE_CHECKING:
    from kinema.bt.node import TreeNode
    from kinema.bt.tree import Tree

MAGIC = b"BTCPP4-FileLogger2"
PROTOCOL = 1
SUFFIX = ".btlog"
TRANSITION_SIZE = 9
_MAX_OFFSET_US = (1 << 48) - 1


class BtlogError(BTRuntimeError):
    """A recording cannot be written or read."""


@dataclass(frozen=True, slots=True)
class Transition:
    """One status change: ``offset_us`` microseconds after the recording's first timestamp."""

    offset_us: int
    uid: int
    status: NodeStatus


def pack_transition(offset_us: int, uid: int, status: int) -> bytes:
    """The 9 bytes of one transition (offsets are clamped to the 48 bits the format keeps)."""
    offset = min(max(int(offset_us), 0), _MAX_OFFSET_US)
    return offset.to_bytes(6, "little") + struct.pack("<HB", uid & 0xFFFF, int(status))


_RECORD = None  # the numpy dtype of one 9-byte record, made on first use


def _record_dtype() -> Any:
    global _RECORD
    if _RECORD is None:
        import numpy as np

        _RECORD = np.dtype([("low", "<u4"), ("high", "<u2"), ("uid", "<u2"), ("status", "u1")])
    return _RECORD


def pack_transition_columns(offsets_us: Any, uids: Any, statuses: Any) -> bytes:
    """The 9-byte records of many transitions at once: ``uids`` and ``statuses`` are equally long
    arrays, ``offsets_us`` one more or a single offset for all (microseconds, clamped to 48 bits)."""
    import numpy as np

    records = np.empty(len(uids), dtype=_record_dtype())
    offsets = np.clip(np.asarray(offsets_us, dtype=np.int64), 0, _MAX_OFFSET_US)
    records["low"] = offsets & 0xFFFFFFFF
    records["high"] = offsets >> 32
    records["uid"] = np.asarray(uids) & 0xFFFF
    records["status"] = statuses
    return records.tobytes()


def coded_records(uids: Any) -> Any:
    """The 9-byte record of every transition-log code (``node index * 25 + previous * 5 + status``,
    :mod:`kinema.bt.transitions`) with a zero offset, as a numpy array indexed by code: node ``index``
    has uid ``uids[index]``. Made once per run; :func:`pack_coded_transitions` gathers from it."""
    import numpy as np

    count = len(uids)
    records = np.zeros(count * 25, dtype=_record_dtype())
    records["uid"] = np.repeat(np.asarray(uids, dtype=np.int64) & 0xFFFF, 25)
    records["status"] = np.tile(np.arange(25, dtype=np.uint8) % 5, count)
    return records


def pack_coded_transitions(
    records: Any, codes: Any, offsets_us: Sequence[int], starts: Sequence[int]
) -> bytes:
    """The 9-byte records of transition-log ``codes`` (a numpy integer array), the same bytes as
    :func:`pack_transition_columns` gives for their uids and statuses: ``records`` is
    :func:`coded_records` of the run's nodes, and the codes from ``starts[i]`` up to the next start
    happened ``offsets_us[i]`` microseconds after the recording's first timestamp (clamped to 48 bits).
    One gather per batch and two stores per offset, where the columns took a dozen array operations."""
    packed = records.take(codes)
    if len(starts) == 1:
        offset = min(max(offsets_us[0], 0), _MAX_OFFSET_US)
        packed["low"] = offset & 0xFFFFFFFF
        packed["high"] = offset >> 32
    else:
        for offset, start, end in zip(offsets_us, starts, [*starts[1:], len(codes)], strict=True):
            offset = min(max(offset, 0), _MAX_OFFSET_US)
            packed["low"][start:end] = offset & 0xFFFFFFFF
            packed["high"][start:end] = offset >> 32
    return packed.tobytes()


def last_per_key(keys: Any, values: Any) -> tuple[Any, Any]:
    """For each distinct key (a small non-negative integer, a uid), the value that came last:
    ``(keys, values)``, keys ascending. Linear (``np.maximum.at`` keeps the latest position of each key),
    where sorting (``np.unique``) cost ten times more per tick."""
    import numpy as np

    if not len(keys):
        return keys, values
    latest = np.full(int(keys.max()) + 1, -1, dtype=np.int64)
    np.maximum.at(latest, keys, np.arange(len(keys)))
    present = np.flatnonzero(latest >= 0)
    return present.astype(keys.dtype, copy=False), values[latest[present]]


def header_bytes(tree_xml: str, start_epoch_us: int) -> bytes:
    """Everything before the first transition."""
    xml = tree_xml.encode("utf-8")
    return MAGIC + bytes([PROTOCOL]) + struct.pack("<i", len(xml)) + xml + struct.pack("<q", start_epoch_us)


class BtlogWriter:
    """Writes one ``.btlog`` file: the header at once, then transitions as they come.

    Args:
        path: the file to create (its suffix must be ``.btlog``, as BT.CPP requires for Groot2).
        tree_xml: the tree as :func:`kinema.bt.model_xml.write_tree_to_xml` writes it.
        start_epoch_us: the first timestamp (default: now), microseconds since the Unix epoch.
        max_bytes: stop adding transitions once the file would grow past this size (None: no cap);
            :attr:`truncated` then says so.

    Raises:
        BtlogError: the suffix is wrong or the file cannot be created.
    """

    def __init__(
        self,
        path: str | Path,
        tree_xml: str,
        *,
        start_epoch_us: int | None = None,
        max_bytes: int | None = None,
    ) -> None:
        self.path = Path(path)
        if self.path.suffix != SUFFIX:
            raise BtlogError(f"a recording's file name must end in {SUFFIX}, got '{self.path.name}'")
        self.start_epoch_us = int(time.time() * 1e6) if start_epoch_us is None else int(start_epoch_us)
        header = header_bytes(tree_xml, self.start_epoch_us)
        try:
            self._file: IO[bytes] | None = open(self.path, "wb")
            self._file.write(header)
            self._file.flush()
        except OSError as error:
            raise BtlogError(
                f"cannot write the recording: {error.strerror or error}", location=SourceLocation(str(path))
            ) from None
        self.size = len(header)
        self.max_bytes = max_bytes
        self.truncated = False
        self.count = 0

    def write(self, transitions: Iterable[tuple[int, int, int]]) -> None:
        """Append ``(offset_us, uid, status)`` transitions and flush them to disk."""
        file = self._file
        if file is None or self.truncated:
            return
        chunk = bytearray()
        for offset_us, uid, status in transitions:
            if self.max_bytes is not None and self.size + len(chunk) + TRANSITION_SIZE > self.max_bytes:
                self.truncated = True
                break
            chunk += pack_transition(offset_us, uid, status)
        if chunk:
            file.write(chunk)
            file.flush()
            self.size += len(chunk)
            self.count += len(chunk) // TRANSITION_SIZE

    def write_packed(self, records: bytes) -> None:
        """Append transitions already packed (:func:`pack_transition_columns`) and flush them."""
        file = self._file
        if file is None or self.truncated or not records:
            return
        if self.max_bytes is not None and self.size + len(records) > self.max_bytes:
            room = max(0, self.max_bytes - self.size) // TRANSITION_SIZE * TRANSITION_SIZE
            records = records[:room]
            self.truncated = True
        if records:
            file.write(records)
            file.flush()
            self.size += len(records)
            self.count += len(records) // TRANSITION_SIZE

    def last_statuses(self) -> dict[int, int]:
        """uid -> the status its last transition in the file gives it (what a replay ends on)."""
        import numpy as np

        if self._file is None or not self.count:
            return {}
        self._file.flush()
        header = self.size - self.count * TRANSITION_SIZE
        with open(self.path, "rb") as file:
            file.seek(header)
            data = file.read(self.count * TRANSITION_SIZE)
        records = np.frombuffer(data, dtype=np.uint8)[: len(data) // TRANSITION_SIZE * TRANSITION_SIZE]
        records = records.reshape(-1, TRANSITION_SIZE)
        uids = records[:, 6].astype(np.int64) | (records[:, 7].astype(np.int64) << 8)
        keys, values = last_per_key(uids, records[:, 8])
        return dict(zip(keys.tolist(), values.tolist(), strict=True))

    def close(self) -> None:
        """Flush and close the file (idempotent)."""
        if self._file is not None:
            self._file.close()
            self._file = None

    def __enter__(self) -> BtlogWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class FileLogger2:
    """Records every status change of ``tree`` into a ``.btlog`` file (BT.CPP ``FileLogger2``).

    For a tree you tick yourself; the runtime records objective runs through
    :mod:`kinema.runtime.recordings` instead. Times come from the tree's clock. Call :meth:`close`
    (or use ``with``) when done.
    """

    def __init__(self, tree: Tree, path: str | Path, *, max_bytes: int | None = None) -> None:
        from kinema.bt.model_xml import write_tree_to_xml

        self._tree = tree
        self._writer = BtlogWriter(path, write_tree_to_xml(tree), max_bytes=max_bytes)
        self._t0 = tree.clock.now()
        self._handle: int | None = tree.add_status_observer(self._on_status)

    @property
    def path(self) -> Path:
        """The file being written."""
        return self._writer.path

    def _on_status(self, timestamp: float, node: TreeNode, previous: NodeStatus, status: NodeStatus) -> None:
        self._writer.write([(round((timestamp - self._t0) * 1e6), node.uid, int(status))])

    def close(self) -> None:
        """Stop recording and close the file."""
        if self._handle is not None:
            self._tree.remove_status_observer(self._handle)
            self._handle = None
        self._writer.close()

    def __enter__(self) -> FileLogger2:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@dataclass(frozen=True)
class Recording:
    """A ``.btlog`` file read back."""

    path: Path
    tree_xml: str
    start_epoch_us: int
    transitions: list[Transition]
    # Bytes at the end that do not make a whole transition (a recording cut short).
    trailing_bytes: int = 0

    @property
    def tree_id(self) -> str:
        """The ID of the recorded main tree (its first ``<BehaviorTree>``), "" when unreadable."""
        from lxml import etree

        try:
            root = etree.fromstring(self.tree_xml.encode("utf-8"))
        except etree.XMLSyntaxError:
            return ""
        first = next(root.iter("BehaviorTree"), None)
        return (first.get("ID") or "") if first is not None else ""

    def statuses_at(self, index: int) -> dict[int, NodeStatus]:
        """``uid -> status`` after the first ``index`` transitions (0: every node IDLE)."""
        statuses: dict[int, NodeStatus] = {}
        for transition in self.transitions[:index]:
            statuses[transition.uid] = transition.status
        return statuses


def read_btlog(path: str | Path) -> Recording:
    """Read a ``.btlog`` file.

    Raises:
        BtlogError: the file is missing, or is not a FileLogger2 recording (the message says what was
            found instead).
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as error:
        raise BtlogError(
            f"cannot read the recording: {error.strerror or error}", location=SourceLocation(str(path))
        ) from None
    return parse_btlog(data, path)


def parse_btlog(data: bytes, path: str | Path = "<bytes>") -> Recording:
    """Parse the bytes of a ``.btlog`` file (see :func:`read_btlog`)."""
    where = SourceLocation(str(path))
    if not data.startswith(MAGIC):
        raise BtlogError(
            f"not a BT.CPP FileLogger2 recording: it starts with {data[:18]!r}, not {MAGIC!r}", location=where
        )
    offset = len(MAGIC)
    if len(data) < offset + 5:
        raise BtlogError("the recording ends inside its header", location=where)
    if data[offset] != PROTOCOL:
        raise BtlogError(
            f"FileLogger2 protocol {data[offset]} is not supported (only {PROTOCOL})", location=where
        )
    (xml_size,) = struct.unpack_from("<i", data, offset + 1)
    offset += 5
    if xml_size < 0 or len(data) < offset + xml_size + 8:
        raise BtlogError("the recording ends inside its tree XML or first timestamp", location=where)
    tree_xml = data[offset : offset + xml_size].decode("utf-8", "replace")
    offset += xml_size
    (start,) = struct.unpack_from("<q", data, offset)
    offset += 8
    transitions: list[Transition] = []
    end = offset + (len(data) - offset) // TRANSITION_SIZE * TRANSITION_SIZE
    for at in range(offset, end, TRANSITION_SIZE):
        offset_us = int.from_bytes(data[at : at + 6], "little")
        uid, status = struct.unpack_from("<HB", data, at + 6)
        try:
            transitions.append(Transition(offset_us, uid, NodeStatus(status)))
        except ValueError:
            raise BtlogError(
                f"transition {len(transitions)} (byte {at}) has status {status}, not 0-4", location=where
            ) from None
    return Recording(Path(path), tree_xml, start, transitions, len(data) - end)
