"""The instantiated tree: tick API, wake-up signal, subtrees, halting and status observers."""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any

from kinema.bt.clock import Clock
from kinema.bt.errors import BTRuntimeError
from kinema.bt.limits import MAX_TREE_NODES
from kinema.bt.node import StatusObserver, TreeNode, node_children
from kinema.bt.status import FAILURE, IDLE, RUNNING, SKIPPED, SUCCESS, NodeStatus

if TYPE_CHECKING:
    from kinema.bt.blackboard import Blackboard, Entry
    from kinema.bt.factory import NodeManifest
    from kinema.bt.transitions import TransitionLog


class WakeUpSignal:
    """One flag plus a condition variable per tree: nodes emit it, ``Tree.sleep`` waits on it."""

    __slots__ = ("_cond", "_flag", "listener")

    def __init__(self) -> None:
        self._cond = threading.Condition(threading.Lock())
        self._flag = False
        # Called after every emit: lets a ticker that waits on its own condition (the objective
        # server's tick thread) tick again at once.
        self.listener: Callable[[], None] | None = None

    def emit(self) -> None:
        """Set the flag and wake any waiter (safe from any thread)."""
        with self._cond:
            self._flag = True
            self._cond.notify_all()
        listener = self.listener
        if listener is not None:
            listener()

    def consume(self) -> bool:
        """Clear the flag; True if it was set (``waitFor(0)``)."""
        if not self._flag:
            return False
        with self._cond:
            was_set = self._flag
            self._flag = False
            return was_set

    def wait(self, timeout: float, stop: Callable[[], bool] | None = None) -> bool:
        """Wait up to ``timeout`` real seconds, or until ``stop()`` is true; consume the flag."""
        with self._cond:
            if not self._flag:
                if stop is None:
                    self._cond.wait(timeout)
                else:
                    self._cond.wait_for(lambda: self._flag or stop(), timeout)
            was_set = self._flag
            self._flag = False
            return was_set

    def wait_forever_until(self, stop: Callable[[], bool]) -> bool:
        """Wait until the flag is set or ``stop()`` is true; consume the flag."""
        with self._cond:
            self._cond.wait_for(lambda: self._flag or stop())
            was_set = self._flag
            self._flag = False
            return was_set

    def notify(self) -> None:
        """Wake waiters without setting the flag (a timer expired)."""
        with self._cond:
            self._cond.notify_all()


class Subtree:
    """One instance of a ``<BehaviorTree>`` inside a Tree.

    Attributes:
        tree_id: the ID of the BehaviorTree definition.
        instance_name: the path of the instance ("" for the main tree, e.g. ``sub1``, ``A/B::5``).
        blackboard: the scope of this instance.
        nodes: the nodes of this instance in creation order.
    """

    __slots__ = ("blackboard", "instance_name", "nodes", "tree_id")

    def __init__(self, tree_id: str, instance_name: str, blackboard: Blackboard) -> None:
        self.tree_id = tree_id
        self.instance_name = instance_name
        self.blackboard = blackboard
        self.nodes: list[TreeNode] = []

    def __repr__(self) -> str:
        return f"Subtree({self.tree_id!r}, {self.instance_name!r}, {len(self.nodes)} nodes)"


# Ticking recurses through the tree (about three frames per level) and BT.CPP allows 256 levels of
# nesting, which is close to CPython's default limit of 1000 frames once the caller's own frames
# are counted.
_MIN_RECURSION_LIMIT = 4000
if sys.getrecursionlimit() < _MIN_RECURSION_LIMIT:
    sys.setrecursionlimit(_MIN_RECURSION_LIMIT)


class Tree:
    """A tree built by :class:`BehaviorTreeFactory`, ready to tick.

    Only one thread may tick and halt it; other threads may emit wake-up signals and read statuses.
    """

    def __init__(self, clock: Clock, manifests: dict[str, NodeManifest] | None = None) -> None:
        self.clock = clock
        self.subtrees: list[Subtree] = []
        self.wake_up = WakeUpSignal()
        self.manifests: dict[str, NodeManifest] = dict(manifests or {})
        self._uid = 0
        self._observer_handles: dict[int, list[Callable[[], None]]] = {}
        self._next_handle = 1
        # True when the last tick_once stopped at its ``until`` with a re-tick still owed.
        self.retick_due = False
        # The log attached by record_transitions(), marked at every root tick.
        self.transition_log: TransitionLog | None = None

    def next_uid(self) -> int:
        """Allocate the next node uid (1-based, used by the builder).

        Raises:
            BTRuntimeError: the tree would pass :data:`~kinema.bt.limits.MAX_TREE_NODES` nodes.
        """
        self._uid += 1
        if self._uid > MAX_TREE_NODES:
            raise BTRuntimeError(
                f"the tree has more than {MAX_TREE_NODES:,} nodes (the nodes of every SubTree instance "
                "included): node uids are 16-bit in BT.CPP's and Groot2's formats and in Kinema's status "
                "stream (kinema.bt.limits.MAX_TREE_NODES); split it into objectives or reuse fewer SubTrees"
            )
        return self._uid

    # -- structure -------------------------------------------------------------------------------

    @property
    def root_node(self) -> TreeNode | None:
        """The first node of the main tree."""
        if not self.subtrees or not self.subtrees[0].nodes:
            return None
        return self.subtrees[0].nodes[0]

    @property
    def root_blackboard(self) -> Blackboard:
        """The blackboard of the main tree (where ``@key`` lives)."""
        return self.subtrees[0].blackboard.root()

    def nodes(self) -> Iterator[TreeNode]:
        """Every node, subtree by subtree, in creation order."""
        for subtree in self.subtrees:
            yield from subtree.nodes

    def __iter__(self) -> Iterator[TreeNode]:
        return self.nodes()

    def __len__(self) -> int:
        return sum(len(s.nodes) for s in self.subtrees)

    def node_by_path(self, path: str) -> TreeNode:
        """The node whose ``full_path`` is ``path``.

        Raises:
            BTRuntimeError: no node has that path; the message suggests the closest paths.
        """
        for node in self.nodes():
            if node.full_path == path:
                return node
        from kinema.bt.errors import BTRuntimeError
        from kinema.errors import did_you_mean

        raise BTRuntimeError(
            f"no node with path '{path}'; {did_you_mean(path, [n.full_path for n in self.nodes()])}"
        )

    def nodes_by_name(self, name: str) -> list[TreeNode]:
        """Every node whose instance name is ``name``."""
        return [n for n in self.nodes() if n.name == name]

    def walk(self) -> Iterator[tuple[TreeNode, int]]:
        """Depth-first ``(node, depth)`` from the root, entering subtrees."""
        root = self.root_node
        if root is None:
            return
        stack: list[tuple[TreeNode, int]] = [(root, 0)]
        while stack:
            node, depth = stack.pop()
            yield node, depth
            for child in reversed(node_children(node)):
                stack.append((child, depth + 1))

    # -- ticking ---------------------------------------------------------------------------------

    def _tick_root(self, mode: int, sleep_time: float, until: Callable[[], bool] | None = None) -> NodeStatus:
        root = self.root_node
        if root is None:
            from kinema.bt.errors import BTRuntimeError

            raise BTRuntimeError("Empty Tree")
        wake_up = self.wake_up
        status = IDLE
        self.retick_due = False
        log = self.transition_log
        while status is IDLE or (mode == 2 and status is RUNNING):
            if log is not None:
                log.mark()
            status = root.execute_tick()
            while mode != 0 and status is RUNNING and wake_up.consume():
                if until is not None and until():
                    # The signal is consumed and the tick it asks for is owed: the caller's next
                    # tick_once starts with it, so the sequence of root ticks is BT.CPP's.
                    self.retick_due = True
                    return status
                if log is not None:
                    log.mark()
                status = root.execute_tick()
            if status is SUCCESS or status is FAILURE:
                root.reset_status()
            if status is RUNNING and until is not None and until():
                return status
            if status is RUNNING and sleep_time > 0:
                self.sleep(sleep_time)
            if status is SKIPPED:
                break
        return status

    def tick_exactly_once(self) -> NodeStatus:
        """Tick the root once, even if a node asked to be ticked again."""
        return self._tick_root(0, 0.0)

    def tick_once(self, until: Callable[[], bool] | None = None) -> NodeStatus:
        """Tick the root, again immediately while a node emitted a wake-up signal.

        Args:
            until: checked before each immediate re-tick; when it returns True the method returns
                RUNNING at once and sets :attr:`retick_due` (the re-tick is owed: call ``tick_once``
                again to continue). A ticker uses it to notice a halt request or a time budget between
                the iterations of a tree that re-ticks itself forever, such as
                ``<Repeat num_cycles="-1"><AlwaysSuccess/></Repeat>``.
        """
        return self._tick_root(1, 0.0, until)

    def tick_while_running(
        self, sleep_time: float = 0.01, until: Callable[[], bool] | None = None
    ) -> NodeStatus:
        """Tick until the root is no longer RUNNING, sleeping ``sleep_time`` between ticks.

        The sleep is interrupted by wake-up signals and measured on the tree's clock. ``until`` works
        as in :meth:`tick_once`; it is also checked between ticks, and RUNNING is returned when it is true.
        """
        return self._tick_root(2, sleep_time, until)

    def sleep(self, seconds: float) -> bool:
        """Sleep ``seconds`` of the tree's clock; return True early if a wake-up signal arrives."""
        if seconds <= 0:
            return self.wake_up.consume()
        if getattr(self.clock, "realtime", False):
            return self.wake_up.wait(seconds)
        fired = threading.Event()

        def on_timer() -> None:
            fired.set()
            self.wake_up.notify()

        handle = self.clock.call_later(seconds, on_timer)
        try:
            return self.wake_up.wait_forever_until(fired.is_set)
        finally:
            handle.cancel()

    def halt_tree(self) -> None:
        """Halt the root, then call ``halt_node`` on every node (``_onHalted`` runs everywhere)."""
        root = self.root_node
        if root is None:
            return
        root.halt_node()
        for node in self.nodes():
            node.halt_node()
        root.reset_status()

    halt = halt_tree

    def __enter__(self) -> Tree:
        return self

    def __exit__(self, *exc_info: object) -> None:
        # BT.CPP's Tree destructor halts the tree; a with-block gives Python code the same guarantee.
        self.halt_tree()

    # -- observers -------------------------------------------------------------------------------

    def add_status_observer(self, callback: StatusObserver) -> int:
        """Call ``callback(timestamp, node, prev, new)`` on every status change of every node.

        Returns a handle for :meth:`remove_status_observer`.
        """
        handle = self._next_handle
        self._next_handle += 1
        self._observer_handles[handle] = [node.subscribe_to_status_change(callback) for node in self.nodes()]
        return handle

    def record_transitions(self) -> TransitionLog:
        """Append every status change of every node to a :class:`~kinema.bt.transitions.TransitionLog`.

        The same changes an observer callback gets, at a fraction of the cost: no call per
        transition; read them once per tick with ``take()``. One log per tree at a time.
        """
        from kinema.bt.transitions import TransitionLog

        return TransitionLog(self)

    def remove_status_observer(self, handle: int) -> None:
        """Stop the observer registered with ``handle`` (unknown handles are ignored)."""
        for unsubscribe in self._observer_handles.pop(handle, []):
            unsubscribe()

    # -- blackboards -----------------------------------------------------------------------------

    def blackboard_snapshot(self) -> dict[str, dict[str, tuple[str, Any]]]:
        """``{subtree instance name or tree ID: {key: (type name, value)}}`` for every scope."""
        out: dict[str, dict[str, tuple[str, Any]]] = {}
        for subtree in self.subtrees:
            scope = subtree.instance_name or subtree.tree_id
            values: dict[str, tuple[str, Any]] = {}
            for key, entry in subtree.blackboard.local_entries():
                values[key] = (entry.type_name, entry.value)
            out[scope] = values
        return out

    def add_blackboard_observer(self, callback: Callable[[str, str, Entry], None]) -> Callable[[], None]:
        """Call ``callback(scope, key, entry)`` after every write to any scope of the tree."""
        removers = []
        for subtree in self.subtrees:
            scope = subtree.instance_name or subtree.tree_id

            def forward(key: str, entry: Entry, _scope: str = scope) -> None:
                callback(_scope, key, entry)

            removers.append(subtree.blackboard.add_observer(forward))

        def remove() -> None:
            for remover in removers:
                remover()

        return remove

    def __repr__(self) -> str:
        root = self.root_node
        return (
            f"<Tree {self.subtrees[0].tree_id if self.subtrees else '?'}: {len(self)} nodes, root {root!r}>"
        )
