"""A tree's transition log: every status change as one integer in one list, read once per tick.

A status observer callback (``Tree.add_status_observer``) costs a Python call per node and per
transition, several times the cost of ticking a simple node, plus the garbage collector's work
on the objects it makes. The log is what a runtime attaches instead: a node appends one small
integer per change (``node index * 25 + previous * 5 + new``, untracked by the garbage
collector), and the tree marks the time at the start of every root tick. The reader takes the
batch once per tick (:meth:`TransitionLog.take`).

Timestamps are the time of the root tick a change happened in (changes made outside a tick, by a
halt, get the time they are taken), not the instant of each change as observer callbacks get it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from kinema.bt.errors import BTLogicError
from kinema.bt.status import NodeStatus

if TYPE_CHECKING:
    from kinema.bt.node import TreeNode
    from kinema.bt.tree import Tree

Transition = tuple["TreeNode", NodeStatus, NodeStatus, float]
"""``(node, previous status, new status, timestamp)``."""

_STATUSES = tuple(NodeStatus)


class TransitionLog:
    """Records every status change of a tree, in order. One log per tree at a time (a second one
    raises); other readers use status observers.

    Attributes:
        nodes: the logged nodes; a code's node is ``nodes[code // 25]``.
        codes: one integer per change since the last :meth:`take_codes`.
    """

    __slots__ = ("_clock", "_marks", "_tree", "codes", "nodes")

    def __init__(self, tree: Tree) -> None:
        self.codes: list[int] = []
        # (index into codes, time) at the start of each root tick
        self._marks: list[tuple[int, float]] = []
        self._tree = tree
        self._clock: Callable[[], float] = tree.clock.now
        self.nodes: list[TreeNode] = list(tree.nodes())
        if tree.transition_log is not None:
            raise BTLogicError(
                "the tree already has a transition log: a tree has one at a time "
                "(close it first, or use Tree.add_status_observer for another reader)"
            )
        codes = self.codes
        for index, node in enumerate(self.nodes):
            node._log_codes = codes
            node._log_base = index * 25
            node._rewire()
        tree.transition_log = self

    def mark(self) -> None:
        """Note the time: the changes appended from now on happened at it (called per root tick)."""
        marks = self._marks
        index = len(self.codes)
        if marks and marks[-1][0] == index:
            marks[-1] = (index, self._clock())
        else:
            marks.append((index, self._clock()))

    def take_codes(self) -> list[tuple[float, list[int]]]:
        """The changes since the last call as ``(time, codes)`` batches, oldest first."""
        codes = self.codes
        marks = self._marks
        if not codes:
            marks.clear()
            return []
        if not marks or marks[0][0] != 0:
            marks.insert(0, (0, self._clock()))
        batches = []
        for i, (start, stamp) in enumerate(marks):
            end = marks[i + 1][0] if i + 1 < len(marks) else len(codes)
            if end > start:
                batches.append((stamp, codes[start:end]))
        codes.clear()
        marks.clear()
        return batches

    def take_columns(self) -> tuple[list[float], list[int], list[int]]:
        """The changes since the last call column-wise, without a Python step per change:
        ``(stamps, starts, codes)``, where the codes from ``starts[i]`` up to the next start
        happened at ``stamps[i]``. All three are empty when nothing changed."""
        codes = self.codes
        marks = self._marks
        if not codes:
            marks.clear()
            return [], [], []
        if not marks or marks[0][0] != 0:
            marks.insert(0, (0, self._clock()))
        stamps: list[float] = []
        starts: list[int] = []
        count = len(codes)
        for start, stamp in marks:
            if start >= count:
                break
            if starts and starts[-1] == start:  # an empty batch: the later mark wins
                stamps[-1] = stamp
            else:
                starts.append(start)
                stamps.append(stamp)
        taken = codes[:]
        codes.clear()
        marks.clear()
        return stamps, starts, taken

    def take(self) -> list[Transition]:
        """The changes since the last call as ``(node, previous, new, time)``, oldest first."""
        nodes = self.nodes
        return [
            (nodes[code // 25], _STATUSES[code // 5 % 5], _STATUSES[code % 5], stamp)
            for stamp, codes in self.take_codes()
            for code in codes
        ]

    def close(self) -> None:
        """Stop recording (what was recorded stays readable)."""
        for node in self.nodes:
            node._log_codes = None
            node._rewire()
        if self._tree.transition_log is self:
            self._tree.transition_log = None
