"""Per-node statistics collected from status changes (BT.CPP's ``TreeObserver``)."""

from __future__ import annotations

from dataclasses import dataclass

from kinema.bt.errors import BTRuntimeError
from kinema.bt.node import TreeNode
from kinema.bt.status import NodeStatus
from kinema.bt.tree import Tree
from kinema.errors import did_you_mean


@dataclass(slots=True)
class NodeStatistics:
    """What a :class:`TreeObserver` counted for one node.

    ``transitions_count`` excludes transitions to IDLE; ``skip_count`` stays 0 for standard nodes
    because SKIPPED is never stored as a status.
    """

    last_result: NodeStatus = NodeStatus.IDLE
    current_status: NodeStatus = NodeStatus.IDLE
    transitions_count: int = 0
    success_count: int = 0
    failure_count: int = 0
    skip_count: int = 0
    last_timestamp: float = 0.0


class TreeObserver:
    """Counts status transitions of every node of a tree, by full path and by uid."""

    def __init__(self, tree: Tree) -> None:
        self._tree = tree
        self._by_uid: dict[int, NodeStatistics] = {}
        self._path_to_uid: dict[str, int] = {}
        for node in tree.nodes():
            self._by_uid[node.uid] = NodeStatistics()
            self._path_to_uid[node.full_path] = node.uid
        self._handle = tree.add_status_observer(self._callback)

    def _callback(self, timestamp: float, node: TreeNode, prev: NodeStatus, status: NodeStatus) -> None:
        stats = self._by_uid.setdefault(node.uid, NodeStatistics())
        stats.current_status = status
        stats.last_timestamp = timestamp
        if status is NodeStatus.IDLE:
            return
        stats.transitions_count += 1
        if status is NodeStatus.SUCCESS:
            stats.last_result = status
            stats.success_count += 1
        elif status is NodeStatus.FAILURE:
            stats.last_result = status
            stats.failure_count += 1
        elif status is NodeStatus.SKIPPED:
            stats.skip_count += 1

    def statistics(self, key: str | int) -> NodeStatistics:
        """Statistics of the node with this full path or uid.

        Raises:
            BTRuntimeError: no node has that path or uid.
        """
        if isinstance(key, int):
            stats = self._by_uid.get(key)
            if stats is None:
                raise BTRuntimeError(f"no node with uid {key} in the observed tree")
            return stats
        uid = self._path_to_uid.get(key)
        if uid is None:
            raise BTRuntimeError(
                f"no node with path '{key}' in the observed tree; {did_you_mean(key, self._path_to_uid)}"
            )
        return self._by_uid[uid]

    def paths(self) -> dict[str, int]:
        """Full path -> uid of every observed node."""
        return dict(self._path_to_uid)

    def all_statistics(self) -> dict[str, NodeStatistics]:
        """Full path -> statistics."""
        return {path: self._by_uid[uid] for path, uid in self._path_to_uid.items()}

    def reset(self) -> None:
        """Zero every counter."""
        for uid in self._by_uid:
            self._by_uid[uid] = NodeStatistics()

    def close(self) -> None:
        """Stop observing."""
        self._tree.remove_status_observer(self._handle)
