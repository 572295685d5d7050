"""Replay: step through a recorded run (a ``.btlog`` and its blackboard file) transition by transition.

The tree is read from the recording itself (the tree as it ran, subtrees expanded, numbered as the
engine numbered it), so a replay needs no runtime and no behaviors installed. The statuses shown at
step ``i`` are what the live Objectives screen showed after the first ``i`` transitions, and the
blackboard is the first snapshot taken after that transition (the end of its tick).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.text import Text
from textual.app import App, ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.screen import Screen
from textual.widgets import Static

from kinema.tui.connection import NodeStatus, NodeStatusUpdate
from kinema.tui.widgets.behavior_tree_view import STATUS_MARK, BehaviorTreeView
from kinema.tui.widgets.fitted_table import Column, FittedTable
from kinema.tui.widgets.key_footer import KeyFooter

if TYPE_CHECKING:
    from kinema.tui.tree_outline import TreeOutline


class ReplayScreen(Screen[None]):
    """One recorded run; left/right step, page up/down jump 10, home/end go to either end."""

    # Priority: the tree view (focused) would otherwise take the arrows, home/end and page keys.
    BINDINGS = [
        Binding("right,l", "step(1)", "Next", id="replay.next", tooltip="The next transition", priority=True),
        Binding(
            "left,h",
            "step(-1)",
            "Previous",
            id="replay.previous",
            tooltip="The previous transition",
            priority=True,
        ),
        Binding(
            "pagedown", "step(10)", "+10", id="replay.forward", tooltip="10 transitions later", priority=True
        ),
        Binding(
            "pageup", "step(-10)", "-10", id="replay.back", tooltip="10 transitions earlier", priority=True
        ),
        Binding(
            "home", "go(0)", "Start", id="replay.start", tooltip="Before the first transition", priority=True
        ),
        Binding("end", "go(-1)", "End", id="replay.end", tooltip="After the last transition", priority=True),
        Binding("f", "next_failure", "Next failure", id="replay.failure", tooltip="The next FAILURE"),
        Binding("escape", "close", "Close", id="replay.close", tooltip="Close the replay"),
    ]

    DEFAULT_CSS = """
    ReplayScreen #replay-position { height: auto; padding: 0 1; background: $boost; }
    ReplayScreen #replay-tree { width: 3fr; }
    ReplayScreen #replay-blackboard { width: 2fr; border-left: solid $primary-background; }
    """

    def __init__(self, path: Path, loaded: tuple[Any, TreeOutline] | None = None) -> None:
        super().__init__()
        self.path = Path(path)
        self.replay, self.outline = loaded if loaded is not None else load_recording(self.path)
        self.position = 0
        self._paths = {node.uid: node for node in self.outline.nodes()}

    @property
    def transitions(self) -> int:
        """How many transitions the recording holds."""
        return len(self.replay.recording.transitions)

    def compose(self) -> ComposeResult:
        yield Static(id="replay-title", classes="pane-title")
        yield Static(id="replay-position")
        with Horizontal(classes="split"):
            with Vertical(id="replay-tree"):
                yield BehaviorTreeView(id="behavior-tree")
            with Vertical(id="replay-blackboard"):
                yield Static("Blackboard", id="replay-blackboard-title", classes="pane-title")
                yield FittedTable(
                    (
                        Column("scope", "Scope", min_width=8, weight=1, drop=1, wrap=False),
                        Column("key", "Key", min_width=8, weight=1, wrap=False),
                        Column("type", "Type", min_width=6, weight=0.5, drop=2, wrap=False),
                        Column("value", "Value", min_width=10, weight=3),
                    ),
                    id="replay-entries",
                )
        yield KeyFooter()

    def on_mount(self) -> None:
        recording = self.replay.recording
        title = Text(f"Replay of {self.outline.tree_id}", style="bold")
        title.append(f"  {self.path.name}", style="dim")
        if not self.replay.frames:
            title.append("  (no blackboard was recorded)", style="dim italic")
        if recording.trailing_bytes:
            title.append("  (the recording was cut short)", style="yellow")
        self.query_one("#replay-title", Static).update(title)
        self.query_one(BehaviorTreeView).show_outline(self.outline)
        self.show_position(0)

    def show_position(self, position: int) -> None:
        """Show the tree after the first ``position`` transitions and the blackboard at that time."""
        self.position = max(0, min(position, self.transitions))
        transitions = self.replay.recording.transitions[: self.position]
        view = self.query_one(BehaviorTreeView)
        view.reset_statuses()
        previous: dict[int, int] = {}
        updates = []
        for transition in transitions:
            node = self._paths.get(transition.uid)
            if node is None:
                continue
            status = NodeStatus(int(transition.status))
            updates.append(
                NodeStatusUpdate(
                    node.uid,
                    node.path,
                    node.type_id,
                    node.name,
                    status,
                    NodeStatus(previous.get(node.uid, 0)),
                )
            )
            previous[node.uid] = int(transition.status)
        view.apply_statuses(updates)
        t_us = transitions[-1].offset_us if transitions else 0
        self._describe(t_us)
        self._show_blackboard(t_us)
        if transitions:
            last = self._paths.get(transitions[-1].uid)
            item = view._by_uid.get(last.uid) if last is not None else None
            if item is not None:
                view.move_cursor(item)

    def _describe(self, t_us: int) -> None:
        text = Text()
        text.append(f"transition {self.position}/{self.transitions}", style="bold")
        text.append(f"   t = +{t_us / 1e6:.3f} s", style="")
        if self.position:
            transition = self.replay.recording.transitions[self.position - 1]
            node = self._paths.get(transition.uid)
            status = NodeStatus(int(transition.status))
            mark, style = STATUS_MARK[status]
            text.append("   ")
            text.append(node.path if node is not None else f"uid {transition.uid}", style="bold")
            text.append(f" → {mark} {status.name}", style=style)
        else:
            text.append("   before the first transition", style="dim")
        self.query_one("#replay-position", Static).update(text)

    def _show_blackboard(self, t_us: int) -> None:
        table = self.query_one("#replay-entries", FittedTable)
        frame = self.replay.blackboard_at(t_us) if self.position else None
        title = "Blackboard" if frame is None else f"Blackboard (snapshot at +{frame.t_us / 1e6:.3f} s)"
        self.query_one("#replay-blackboard-title", Static).update(title)
        table.set_rows(
            [
                (Text(scope), Text(key, style="bold"), Text(type_name, style="dim"), Text(value))
                for scope, key, type_name, value in (frame.entries if frame is not None else ())
            ]
        )

    def action_step(self, delta: int) -> None:
        self.show_position(self.position + delta)

    def action_go(self, position: int) -> None:
        self.show_position(self.transitions if position < 0 else position)

    def action_next_failure(self) -> None:
        transitions = self.replay.recording.transitions
        for index in range(self.position, len(transitions)):
            if int(transitions[index].status) == int(NodeStatus.FAILURE):
                self.show_position(index + 1)
                return
        self.notify("No FAILURE after this point.", severity="warning")

    def action_close(self) -> None:
        if len(self.app.screen_stack) > 1:
            self.app.pop_screen()
        else:
            self.app.exit()


class ReplayApp(App[None]):
    """``kinema ui --replay``: the replay screen on its own, without a runtime."""

    TITLE = "Kinema replay"
    CSS_PATH = Path(__file__).parent.parent / "app.tcss"
    BINDINGS = [Binding("q", "quit", "Quit", id="replay.quit")]

    def __init__(self, path: Path) -> None:
        super().__init__()
        self.path = path

    def on_mount(self) -> None:
        self.push_screen(ReplayScreen(self.path))


def load_recording(path: Path) -> tuple[Any, TreeOutline]:
    """The replay of the recording at ``path`` and its tree's outline (slow for a long run: off the UI)."""
    from kinema.runtime.recordings import load_replay
    from kinema.tui.tree_outline import build_outline

    replay = load_replay(Path(path))
    recording = replay.recording
    main = _first_tree_id(recording.tree_xml)
    return replay, build_outline(recording.tree_xml, main, filename=str(path))


def _first_tree_id(xml: str) -> str | None:
    from kinema.bt.xmlsource import parse_xml

    root = parse_xml(xml, "<recording>")
    main = root.get("main_tree_to_execute")
    if main:
        return main
    first = next(root.iter("BehaviorTree"), None)
    return first.get("ID") if first is not None else None
