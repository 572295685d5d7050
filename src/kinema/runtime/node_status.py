"""Node status changes of a running objective, column-wise: the objective server's status observer.

A tick of a large tree changes thousands of statuses. Turning each change into an object (and then
into a message field by field) cost the tick thread 20 µs per change, 40 ms per tick of a 1,000-leaf
Sequence. Here a change stays what the tree's :class:`~kinema.bt.transitions.TransitionLog` made of it,
one integer: ``node index * 25 + previous * 5 + status``, where the index is into the run's
:class:`NodeTable`. The recorder hands listeners a :class:`NodeStatusBatch` of those integers per
tick; a listener that wants objects iterates it (decoding then), the agent publishes the integers as
they are (``kinema_msgs/msg/NodeStatusCodes``, with the table once per run as
``kinema_msgs/msg/NodeTable``), and the Groot2 and ``.btlog`` listeners read its numpy columns.
"""

from __future__ import annotations

import array
import itertools
import secrets
from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING, Any, NamedTuple, overload

import numpy as np

from kinema.bt.node import node_children
from kinema.bt.status import NodeStatus

if TYPE_CHECKING:
    from kinema.bt import Tree
    from kinema.bt.node import TreeNode
    from kinema.bt.transitions import TransitionLog

# codes per node: 5 previous statuses x 5 new ones
CODES_PER_NODE = 25
_FAILURE = int(NodeStatus.FAILURE)
# A batch at least this long is searched for failed leaves with numpy (below, a set is quicker).
_NUMPY_FROM = 256
# Table ids start at a random number: a subscriber that outlives a runtime must not take the new
# runtime's first table for the old one's.
_table_ids = itertools.count(secrets.randbelow(1 << 30) + 1)


class NodeStatusChange(NamedTuple):
    """One node of the running tree changed status (what iterating a :class:`NodeStatusBatch` gives)."""

    timestamp: float
    uid: int
    node_path: str
    node_id: str
    node_name: str
    previous: int
    status: int


_new_tuple = tuple.__new__


class NodeTable:
    """The nodes of one run's tree in transition-log order: a code's node is ``code // 25``.

    Attributes:
        id: unique in this process; the run's batches (and messages) carry it.
        uids, paths, node_ids, names: per node.
        leaves: per node, True for a node without children (a failed leaf names a failure).
    """

    __slots__ = (
        "_leaf_failure",
        "_leaf_failure_codes",
        "_uid_array",
        "id",
        "leaves",
        "names",
        "node_ids",
        "paths",
        "uids",
    )

    def __init__(self, nodes: Sequence[TreeNode]) -> None:
        self.id = next(_table_ids)
        self.uids = [int(node.uid) for node in nodes]
        self.paths = [node.full_path for node in nodes]
        self.node_ids = [node.registration_id for node in nodes]
        self.names = [node.name for node in nodes]
        self.leaves = [not node_children(node) for node in nodes]
        self._uid_array: np.ndarray | None = None
        self._leaf_failure: np.ndarray | None = None
        self._leaf_failure_codes: frozenset[int] | None = None

    def __len__(self) -> int:
        return len(self.uids)

    @property
    def uid_array(self) -> np.ndarray:
        """The uids as a numpy array (index: node)."""
        if self._uid_array is None:
            self._uid_array = np.array(self.uids, dtype=np.uint32)
        return self._uid_array

    def leaf_failure_codes(self) -> frozenset[int]:
        """Every code of a leaf turning FAILURE."""
        if self._leaf_failure_codes is None:
            self._leaf_failure_codes = frozenset(
                index * CODES_PER_NODE + previous * 5 + _FAILURE
                for index, leaf in enumerate(self.leaves)
                if leaf
                for previous in range(5)
                if previous != _FAILURE
            )
        return self._leaf_failure_codes

    def leaf_failure_mask(self) -> np.ndarray:
        """A boolean per code: True where the code is a leaf turning FAILURE."""
        if self._leaf_failure is None:
            mask = np.zeros(len(self.uids) * CODES_PER_NODE, dtype=bool)
            mask[list(self.leaf_failure_codes())] = True
            self._leaf_failure = mask
        return self._leaf_failure

    def change(self, timestamp: float, code: int) -> NodeStatusChange:
        """The change ``code`` names."""
        index = code // CODES_PER_NODE
        return _new_tuple(
            NodeStatusChange,
            (
                timestamp,
                self.uids[index],
                self.paths[index],
                self.node_ids[index],
                self.names[index],
                code // 5 % 5,
                code % 5,
            ),
        )


class NodeStatusBatch(Sequence[NodeStatusChange]):
    """The status changes of one flush (usually one tick), column-wise.

    Code ``codes[k]`` is node ``table`` index ``codes[k] // 25`` going from ``codes[k] // 5 % 5`` to
    ``codes[k] % 5``; the codes from ``starts[i]`` up to the next start happened at ``stamps[i]``.
    Indexing or iterating it gives :class:`NodeStatusChange` objects (decoded on first use).
    """

    __slots__ = ("_array", "_columns", "_decoded", "codes", "stamps", "starts", "table")

    def __init__(self, table: NodeTable, stamps: list[float], starts: list[int], codes: list[int]) -> None:
        self.table = table
        self.stamps = stamps
        self.starts = starts
        self.codes = codes
        self._array: array.array | None = None
        self._decoded: list[NodeStatusChange] | None = None
        self._columns: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None

    def __len__(self) -> int:
        return len(self.codes)

    @overload
    def __getitem__(self, index: int) -> NodeStatusChange: ...

    @overload
    def __getitem__(self, index: slice) -> list[NodeStatusChange]: ...

    def __getitem__(self, index: int | slice) -> Any:
        return self.changes()[index]

    def __iter__(self) -> Iterator[NodeStatusChange]:
        return iter(self.changes())

    def __repr__(self) -> str:
        return f"<NodeStatusBatch of {len(self.codes)} changes, table {self.table.id}>"

    def changes(self) -> list[NodeStatusChange]:
        """Every change as an object, oldest first."""
        if self._decoded is None:
            change = self.table.change
            decoded: list[NodeStatusChange] = []
            bounds = [*self.starts[1:], len(self.codes)]
            for stamp, start, end in zip(self.stamps, self.starts, bounds, strict=True):
                decoded.extend([change(stamp, code) for code in self.codes[start:end]])
            self._decoded = decoded
        return self._decoded

    def code_array(self) -> np.ndarray:
        """The codes as a numpy ``uint32`` array (shared, do not modify)."""
        if self._array is None:
            self._array = array.array("I", self.codes)
        return np.frombuffer(self._array, dtype=np.uint32)

    def columns(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(timestamps, uids, previous, status)``, one element per change, as numpy arrays (computed once:
        Groot2 and the recording both read them; shared, do not modify)."""
        if self._columns is None:
            self._columns = self._compute_columns()
        return self._columns

    def _compute_columns(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        codes = self.code_array()
        counts = np.diff(np.append(np.asarray(self.starts, dtype=np.int64), len(codes)))
        times = np.repeat(np.asarray(self.stamps, dtype=np.float64), counts)
        uids = self.table.uid_array[codes // CODES_PER_NODE]
        return times, uids, (codes // 5) % 5, codes % 5

    def split(self, most: int) -> list[NodeStatusBatch]:
        """This batch as consecutive batches of at most ``most`` changes each (itself if it fits)."""
        codes = self.codes
        if len(codes) <= most:
            return [self]
        parts = []
        bounds = [*self.starts, len(codes)]
        for first in range(0, len(codes), most):
            last = min(first + most, len(codes))
            stamps: list[float] = []
            starts: list[int] = []
            for i, stamp in enumerate(self.stamps):
                if bounds[i] < last and bounds[i + 1] > first:  # batch i overlaps [first, last)
                    stamps.append(stamp)
                    starts.append(max(bounds[i], first) - first)
            parts.append(NodeStatusBatch(self.table, stamps, starts, codes[first:last]))
        return parts

    def last_leaf_failure(self) -> int | None:
        """The code of the last leaf that turned FAILURE in this batch, or None."""
        codes = self.codes
        if len(codes) < _NUMPY_FROM:
            failing = self.table.leaf_failure_codes()
            if failing.isdisjoint(codes):
                return None
            return next(code for code in reversed(codes) if code in failing)
        hits = np.flatnonzero(self.table.leaf_failure_mask()[self.code_array()])
        return int(codes[hits[-1]]) if hits.size else None


class NodeStatusRecorder:
    """The server's status observer: reads the tree's transition log once per tick and hands the
    changes over as a :class:`NodeStatusBatch`; remembers the last leaf that failed (the failure
    message names it)."""

    __slots__ = ("_last_failure", "_log", "_pending", "_table")

    def __init__(self) -> None:
        self._log: TransitionLog | None = None
        self._table: NodeTable | None = None
        self._pending: list[NodeStatusBatch] = []
        self._last_failure: tuple[str, str] | None = None

    def attach(self, tree: Tree) -> None:
        """Record the transitions of ``tree`` through its transition log (one per tree)."""
        self.detach()
        self._log = tree.record_transitions()
        self._table = None

    @property
    def table(self) -> NodeTable | None:
        """The node table of the attached (or last) tree, made when first needed: for a run that ends
        in its first tick, after its client has the result (None before any tree was attached)."""
        if self._table is None and self._log is not None:
            self._table = NodeTable(self._log.nodes)
        return self._table

    def detach(self) -> None:
        """Stop recording the attached tree (what was recorded stays readable)."""
        log = self._log
        if log is not None:
            self._drain()
            log.close()
            self._log = None

    def _drain(self) -> None:
        log = self._log
        if log is None or not log.codes:
            return
        table = self.table
        assert table is not None
        batch = NodeStatusBatch(table, *log.take_columns())
        failed = batch.last_leaf_failure()
        if failed is not None:
            index = failed // CODES_PER_NODE
            self._last_failure = (table.paths[index], table.node_ids[index])
        self._pending.append(batch)

    @property
    def pending(self) -> bool:
        """True when changes are waiting to be taken."""
        self._drain()
        return bool(self._pending)

    @property
    def last_failure(self) -> tuple[str, str] | None:
        """``(path, registration ID)`` of the last leaf that failed, or None."""
        self._drain()
        return self._last_failure

    def take(self) -> NodeStatusBatch | None:
        """The changes since the last call as one batch (None when there were none)."""
        self._drain()
        pending, self._pending = self._pending, []
        if not pending:
            return None
        if len(pending) == 1:
            return pending[0]
        stamps: list[float] = []
        starts: list[int] = []
        codes: list[int] = []
        for batch in pending:
            starts.extend([start + len(codes) for start in batch.starts])
            stamps.extend(batch.stamps)
            codes.extend(batch.codes)
        return NodeStatusBatch(pending[0].table, stamps, starts, codes)
