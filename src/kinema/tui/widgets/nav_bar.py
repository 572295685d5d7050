"""The row of screen tabs at the top; clicking one switches screens (the number keys do the same)."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.widget import Widget
from textual.widgets import Tab, Tabs

from kinema.tui.messages import ModeSelected

#: (mode, label, key) in display order.
SCREENS: tuple[tuple[str, str, str], ...] = (
    ("configs", "Configs", "1"),
    ("objectives", "Objectives", "2"),
    ("blackboard", "Blackboard", "3"),
    ("behaviors", "Behaviors", "4"),
    ("logs", "Logs", "5"),
    ("waypoints", "Waypoints", "6"),
)


class _NavTabs(Tabs, can_focus=False):
    """Tabs that never take the keyboard focus (the number keys switch screens; the mouse still works)."""


class NavBar(Widget):
    """Tabs naming every screen, with ``active`` selected."""

    DEFAULT_CSS = """
    NavBar { height: 2; dock: top; }
    NavBar Tabs { height: 2; }
    """

    def __init__(self, active: str) -> None:
        super().__init__()
        self.active = active

    def compose(self) -> ComposeResult:
        tabs = [Tab(f"{key} {label}", id=f"nav-{mode}") for mode, label, key in SCREENS]
        yield _NavTabs(*tabs, active=f"nav-{self.active}")

    def on_tabs_tab_activated(self, event: Tabs.TabActivated) -> None:
        event.stop()
        mode = (event.tab.id or "").removeprefix("nav-")
        if mode and mode != self.active:
            self.query_one(Tabs).active = f"nav-{self.active}"  # the app switches, then this screen hides
            self.post_message(ModeSelected(mode))
