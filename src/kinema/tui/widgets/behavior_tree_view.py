"""An objective's behavior tree as a tree view whose nodes show their live status."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

from rich.text import Text
from textual.widgets import Tree
from textual.widgets.tree import TreeNode

from kinema.tui.connection import NodeStatus, NodeStatusUpdate

if TYPE_CHECKING:
    from kinema.tui.tree_outline import OutlineNode, TreeOutline

STATUS_MARK: dict[NodeStatus, tuple[str, str]] = {
    NodeStatus.IDLE: ("○", "dim"),
    NodeStatus.RUNNING: ("◉", "bold yellow"),
    NodeStatus.SUCCESS: ("✔", "bold green"),
    NodeStatus.FAILURE: ("✘", "bold red"),
    NodeStatus.SKIPPED: ("⊘", "dim cyan"),
}
_RESULTS = frozenset({NodeStatus.SUCCESS, NodeStatus.FAILURE, NodeStatus.SKIPPED})


class BehaviorTreeView(Tree["OutlineNode"]):
    """Shows a :class:`TreeOutline`; :meth:`apply_statuses` marks nodes as the runtime reports them.

    A node keeps showing its last result (SUCCESS, FAILURE, SKIPPED) when its parent resets it to IDLE,
    so a finished run stays readable; a new run (:meth:`reset_statuses`) clears the marks.
    """

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__("(no objective selected)", id=id)
        self.outline: TreeOutline | None = None
        self.statuses: dict[int, NodeStatus] = {}
        self._by_uid: dict[int, TreeNode[OutlineNode]] = {}

    def show_outline(self, outline: TreeOutline | None, message: str = "") -> None:
        """Replace the tree with ``outline`` (or an empty tree labelled ``message``)."""
        self.outline = outline
        self.statuses = {}
        self._by_uid = {}
        self.clear()
        if outline is None or outline.root is None:
            self.root.set_label(Text(message or "(empty tree)"))
            return
        self.root.set_label(Text(outline.tree_id, style="bold"))
        self.root.data = None
        stack: list[tuple[OutlineNode, TreeNode[OutlineNode]]] = [(outline.root, self.root)]
        while stack:
            node, parent = stack.pop()
            label = self._label(node, NodeStatus.IDLE)
            if node.children:
                item = parent.add(label, data=node, expand=True)
            else:
                item = parent.add_leaf(label, data=node)
            self._by_uid[node.uid] = item
            stack.extend((child, item) for child in reversed(node.children))
        if outline.missing_subtrees:
            self.root.set_label(
                Text.assemble(
                    (outline.tree_id, "bold"),
                    (f"  (subtrees not found: {', '.join(outline.missing_subtrees)})", "yellow"),
                )
            )
        self.root.expand()

    def apply_statuses(self, updates: Iterable[NodeStatusUpdate]) -> int:
        """Mark the nodes named by ``updates``; returns how many were found in the outline."""
        if self.outline is None:
            return 0
        found = 0
        for update in updates:
            node = self.outline.find(update.uid, update.node_path)
            if node is None:
                continue
            found += 1
            previous = self.statuses.get(node.uid, NodeStatus.IDLE)
            if update.status is NodeStatus.IDLE and previous in _RESULTS:
                continue  # parents reset finished children to IDLE; keep showing how they ended
            self.statuses[node.uid] = update.status
            item = self._by_uid.get(node.uid)
            if item is not None:
                item.set_label(self._label(node, update.status))
        return found

    def reset_statuses(self) -> None:
        """Show every node as idle (a new run started)."""
        for uid in list(self.statuses):
            item = self._by_uid.get(uid)
            if item is not None and item.data is not None:
                item.set_label(self._label(item.data, NodeStatus.IDLE))
        self.statuses = {}

    def status_of(self, path: str) -> NodeStatus:
        """The status shown for the node with full path ``path`` (IDLE when not reported)."""
        if self.outline is not None:
            for node in self.outline.nodes():
                if node.path == path:
                    return self.statuses.get(node.uid, NodeStatus.IDLE)
        return NodeStatus.IDLE

    @staticmethod
    def _label(node: OutlineNode, status: NodeStatus) -> Text:
        mark, style = STATUS_MARK[status]
        text = Text()
        text.append(f"{mark} ", style=style)
        text.append(node.type_id, style="bold" if node.is_subtree else "")
        if node.name and node.name != node.type_id:
            text.append(f" “{node.name}”", style="italic")
        if status is not NodeStatus.IDLE:
            text.append(f"  {status.name}", style=style)  # before the ports, which may run off the edge
        ports = " ".join(f"{k}={v}" for k, v in node.attributes.items() if not k.startswith("_"))
        if ports:
            text.append(f"  {ports}", style="dim")
        return text
