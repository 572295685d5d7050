"""An objective's behavior tree as a tree view whose nodes show their live status.

After a run that failed or was cancelled the view explains it: nodes keep how they ended (a node that
was RUNNING when the run stopped shows HALTED), the path from the root to the failed node is
highlighted and expanded, the cursor is put on the failed node, and that node opens onto its ports and
the failure message. Everything stays until the next run starts.

While a run goes on, the view keeps the deepest node that started running in sight (the line of its folded
SubTree when it runs inside one), so a long objective at 80x24 shows where it is; once the user moves the
cursor or scrolls, the view stays where they put it until the next run.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from typing import TYPE_CHECKING

from rich.text import Text
from textual import events
from textual.widgets import Tree
from textual.widgets.tree import TreeNode

from kinema.tui.connection import NodeStatus, NodeStatusUpdate
from kinema.tui.run_outcome import failure_text

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
HALTED_MARK = ("◼", "bold dark_orange")
FAILED_PATH_STYLE = "on #5f0000"
# "objective 'X' failed: node 'Sub::3/Fail' [AlwaysFailure]: message" (the objective server's wording).
_FAILED_NODE = re.compile(r"node '([^']+)' \[")


def failed_node_path(message: str) -> str | None:
    """The node path a failure message names, or None."""
    found = _FAILED_NODE.search(message)
    return found.group(1) if found else None


class BehaviorTreeView(Tree["OutlineNode"]):
    """Shows a :class:`TreeOutline`; :meth:`apply_statuses` marks nodes as the runtime reports them.

    A node keeps showing its last result (SUCCESS, FAILURE, SKIPPED) when its parent resets it to IDLE,
    so a finished run stays readable; a new run (:meth:`reset_statuses`) clears the marks.
    """

    def __init__(self, *, id: str | None = None) -> None:
        # Text, not a string: a string label is parsed as markup, which imports rich's emoji table.
        super().__init__(Text("(no objective selected)"), id=id)
        self.outline: TreeOutline | None = None
        self.statuses: dict[int, NodeStatus] = {}
        self.halted: set[int] = set()
        self.failed_path: list[int] = []
        self.failure_message = ""
        # True from a run's end (finish_run) to the next run's start: nothing runs any more, so a
        # RUNNING reported then is the ended run's, late (its statuses and its outcome travel on two
        # topics), and must not undo how the run ended.
        self.run_over = False
        self._by_uid: dict[int, TreeNode[OutlineNode]] = {}
        self._parents: dict[int, int | None] = {}
        self._details: list[TreeNode[OutlineNode]] = []
        # Whether the view follows the running node: until the user moves or scrolls during a run.
        self.following = True

    # The user's own moves stop the view from following the run (until the next run starts).
    def action_cursor_up(self) -> None:
        self.following = False
        super().action_cursor_up()

    def action_cursor_down(self) -> None:
        self.following = False
        super().action_cursor_down()

    def action_page_up(self) -> None:
        self.following = False
        super().action_page_up()

    def action_page_down(self) -> None:
        self.following = False
        super().action_page_down()

    def action_scroll_home(self) -> None:
        self.following = False
        super().action_scroll_home()

    def action_scroll_end(self) -> None:
        self.following = False
        super().action_scroll_end()

    def _on_mouse_scroll_down(self, event: events.MouseScrollDown) -> None:
        self.following = False
        super()._on_mouse_scroll_down(event)

    def _on_mouse_scroll_up(self, event: events.MouseScrollUp) -> None:
        self.following = False
        super()._on_mouse_scroll_up(event)

    def show_outline(self, outline: TreeOutline | None, message: str = "") -> None:
        """Replace the tree with ``outline`` (or an empty tree labelled ``message``)."""
        self.outline = outline
        self.statuses = {}
        self.halted = set()
        self.failed_path = []
        self.failure_message = ""
        self.run_over = False
        self._by_uid = {}
        self._parents = {}
        self._details = []
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
                # MoveIt Pro's editor folds a SubTree marked _collapsed="true"; its status shows on it.
                folded = node.is_subtree and node.attributes.get("_collapsed", "").lower() == "true"
                item = parent.add(label, data=node, expand=not folded)
            else:
                item = parent.add_leaf(label, data=node)
            self._by_uid[node.uid] = item
            parent_node = parent.data
            self._parents[node.uid] = parent_node.uid if parent_node is not None else None
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
        started: list[int] = []
        for update in updates:
            node = self.outline.find(update.uid, update.node_path)
            if node is None:
                continue
            found += 1
            if update.status is NodeStatus.RUNNING and self.run_over:
                continue  # the ended run's start, reported after its end: it keeps showing how it ended
            if update.status is NodeStatus.RUNNING:
                started.append(node.uid)
            previous = self.statuses.get(node.uid, NodeStatus.IDLE)
            if update.status is NodeStatus.IDLE and previous in _RESULTS:
                continue  # parents reset finished children to IDLE; keep showing how they ended
            if update.status is NodeStatus.IDLE and node.uid in self.halted:
                continue  # its halt, reported after the run's end had already shown it halted
            if update.status is NodeStatus.IDLE and previous is NodeStatus.RUNNING:
                self.halted.add(node.uid)  # a running node reset to IDLE was halted
            else:
                self.halted.discard(node.uid)
            self.statuses[node.uid] = update.status
            self._relabel(node.uid)
        running = [uid for uid in started if self.statuses.get(uid) is NodeStatus.RUNNING]
        if running and self.following:
            self._show_running(max(running, key=self._depth))
        return found

    def _depth(self, uid: int) -> int:
        depth, parent = 0, self._parents.get(uid)
        while parent is not None:
            depth, parent = depth + 1, self._parents.get(parent)
        return depth

    def _show_running(self, uid: int) -> None:
        """Scroll the running node ``uid`` (or the folded SubTree it runs in) into view."""
        item = self._by_uid.get(uid)
        shown = item
        ancestor = item.parent if item is not None else None
        while ancestor is not None and ancestor is not self.root:
            if not ancestor.is_expanded:
                shown = ancestor  # the outermost folded ancestor is the line on screen
            ancestor = ancestor.parent
        if shown is not None:
            self.call_after_refresh(self.scroll_to_node, shown, animate=False)

    def reset_statuses(self) -> None:
        """Show every node as idle (a new run started)."""
        self._clear_failure()
        self.run_over = False
        self.following = True
        uids = set(self.statuses) | self.halted
        self.statuses = {}
        self.halted = set()
        for uid in uids:
            self._relabel(uid)

    def finish_run(self, outcome: str, message: str = "") -> OutlineNode | None:
        """The run ended with ``outcome`` (``Failure`` or ``Cancelled``): explain it on the tree.

        Nodes still shown RUNNING were halted. For a failure, the node named by ``message`` (else the
        deepest node reported FAILURE) is marked failed, the path to it highlighted and expanded (its
        ancestors that were running failed with it), and it opens onto its ports and ``message``. Returns
        the failed node, if one was found.
        """
        self.run_over = True
        for running, status in list(self.statuses.items()):
            if status is NodeStatus.RUNNING:
                self.statuses[running] = NodeStatus.IDLE
                self.halted.add(running)
                self._relabel(running)
        if outcome != "Failure" or self.outline is None:
            return None
        failed = self._failed_node(message)
        if failed is None:
            return None
        self._clear_failure()
        self.failure_message = message
        self.statuses[failed.uid] = NodeStatus.FAILURE
        self.halted.discard(failed.uid)
        path: list[int] = []
        step: int | None = failed.uid
        while step is not None:
            path.append(step)
            step = self._parents.get(step)
        self.failed_path = list(reversed(path))
        for uid in self.failed_path:
            if uid != failed.uid and (
                uid in self.halted or self.statuses.get(uid) in (None, NodeStatus.IDLE)
            ):
                # Running when their descendant failed (an exception escaped through them, maybe before
                # their status was even sent): they failed with it; BT.CPP never halts them itself, and
                # the runtime's halt that followed is how it stops a failed tree, not a cancel.
                self.halted.discard(uid)
                self.statuses[uid] = NodeStatus.FAILURE
            self._relabel(uid)
            item = self._by_uid.get(uid)
            if item is not None and uid != failed.uid:
                item.expand()
        item = self._by_uid.get(failed.uid)
        if item is not None:
            self._add_details(item, failed, message)
            self.move_cursor(item)
        return failed

    def _failed_node(self, message: str) -> OutlineNode | None:
        assert self.outline is not None
        path = failed_node_path(message)
        if path:
            for node in self.outline.nodes():
                if node.path == path:
                    return node
        failed = [n for n in self.outline.nodes() if self.statuses.get(n.uid) is NodeStatus.FAILURE]
        deepest = [
            n for n in failed if not any(self.statuses.get(c.uid) is NodeStatus.FAILURE for c in n.children)
        ]
        return deepest[-1] if deepest else None

    def _add_details(self, item: TreeNode[OutlineNode], node: OutlineNode, message: str) -> None:
        item.allow_expand = True
        lines: list[Text] = []
        for key, value in node.attributes.items():
            if not key.startswith("_"):
                lines.append(Text.assemble((f"{key}", "bold"), (" = ", "dim"), value))
        if message:
            # A tree line does not wrap: the exception first, then where, each wrapped to the view's width
            # (at the depth of the failed node), so neither is cut at the edge.
            explained = failure_text(message)
            depth, parent = 0, item.parent
            while parent is not None:
                depth, parent = depth + 1, parent.parent
            width = max(30, self.size.width - 4 * (depth + 1) - 2)
            lines.extend(_wrapped("why: ", explained.headline, "bold red", width))
            for note in explained.notes:
                lines.extend(_wrapped("note: ", note, "bold yellow", width))
            if explained.where:
                lines.extend(_wrapped("at: ", explained.where, "bold", width))
        lines.append(Text(f"path: {node.path}" + (f"  (line {node.line})" if node.line else ""), style="dim"))
        for line in lines:
            self._details.append(item.add_leaf(line))
        item.expand()

    def _clear_failure(self) -> None:
        for detail in self._details:
            detail.remove()
        self._details = []
        path, self.failed_path = self.failed_path, []
        self.failure_message = ""
        for uid in path:
            self._relabel(uid)

    def _relabel(self, uid: int) -> None:
        item = self._by_uid.get(uid)
        if item is None or item.data is None:
            return
        label = self._label(item.data, self.statuses.get(uid, NodeStatus.IDLE), halted=uid in self.halted)
        if uid in self.failed_path:
            label.stylize(FAILED_PATH_STYLE)
        item.set_label(label)

    def shown_as(self, path: str) -> str:
        """What the view shows for node ``path``: a status name, or ``HALTED``."""
        if self.outline is not None:
            for node in self.outline.nodes():
                if node.path == path:
                    return (
                        "HALTED"
                        if node.uid in self.halted
                        else self.statuses.get(node.uid, NodeStatus.IDLE).name
                    )
        return NodeStatus.IDLE.name

    def status_of(self, path: str) -> NodeStatus:
        """The status shown for the node with full path ``path`` (IDLE when not reported)."""
        if self.outline is not None:
            for node in self.outline.nodes():
                if node.path == path:
                    return self.statuses.get(node.uid, NodeStatus.IDLE)
        return NodeStatus.IDLE

    @staticmethod
    def _label(node: OutlineNode, status: NodeStatus, *, halted: bool = False) -> Text:
        mark, style = HALTED_MARK if halted else STATUS_MARK[status]
        text = Text()
        text.append(f"{mark} ", style=style)
        text.append(node.type_id, style="bold" if node.is_subtree else "")
        if node.name and node.name != node.type_id:
            text.append(f" “{node.name}”", style="italic")
        if halted:
            text.append("  HALTED", style=style)
        elif status is not NodeStatus.IDLE:
            text.append(f"  {status.name}", style=style)  # before the ports, which may run off the edge
        ports = " ".join(f"{k}={v}" for k, v in node.attributes.items() if not k.startswith("_"))
        if ports:
            text.append(f"  {ports}", style="dim")
        return text


def _wrapped(label: str, text: str, style: str, width: int) -> list[Text]:
    """``label`` and ``text`` as tree lines of at most ``width`` cells, the continuation lines indented."""
    import textwrap

    indent = " " * len(label)
    pieces = textwrap.wrap(
        text, width, initial_indent=label, subsequent_indent=indent, break_on_hyphens=False
    )
    lines = []
    for index, piece in enumerate(pieces or [label]):
        line = Text()
        if index == 0:
            line.append(label, style=style)
            line.append(piece[len(label) :])
        else:
            line.append(piece)
        lines.append(line)
    return lines
