"""The live blackboard table, drawn line by line from the model: only the rows on screen cost anything.

A stock ``DataTable`` keeps its own copy of every cell and measures every new row, so showing 1,000 keys
(or re-filtering them) stalls the terminal for a good part of a second. This table keeps only the sorted
list of keys that pass the filter; each frame renders the visible lines straight from the
:class:`~kinema.tui.blackboard_model.BlackboardModel`, and a diff only edits the key list and asks for
one repaint.
"""

from __future__ import annotations

from bisect import bisect_left, insort

from rich.segment import Segment
from rich.style import Style
from textual import events
from textual.binding import Binding
from textual.geometry import Size
from textual.message import Message
from textual.reactive import reactive
from textual.scroll_view import ScrollView
from textual.strip import Strip

from kinema.tui.blackboard_model import BlackboardDiff, BlackboardModel, RowKey, matches, row_key

#: (title, widest) of the fixed columns; the value takes the rest of the line.
COLUMNS: tuple[tuple[str, int], ...] = (("Scope", 22), ("Key", 28), ("Type", 14))
MIN_VALUE_WIDTH = 10
#: Below this width the scope column is left out (the history panel names the selected key's scope).
SCOPE_FROM_WIDTH = 100


def column_widths(width: int) -> tuple[int, int, int]:
    """Scope, key and type widths for a table ``width`` cells wide (scope 0: not shown); the value gets
    the rest, never less than about 40% of the line: at 80 columns the values are what a user reads."""
    available = width - 1
    scope = COLUMNS[0][1] if width >= SCOPE_FROM_WIDTH else 0
    key = min(COLUMNS[1][1], max(10, int(available * 0.28)))
    type_ = min(COLUMNS[2][1], max(6, int(available * 0.14)))
    return scope, key, type_


class BlackboardTable(ScrollView, can_focus=True):
    """Scope, key, type and value of every blackboard entry that matches the filter."""

    BINDINGS = [
        Binding("up", "move(-1)", "Up", show=False, id="blackboard.up", tooltip="Previous key"),
        Binding("down", "move(1)", "Down", show=False, id="blackboard.down", tooltip="Next key"),
        Binding("pageup", "page(-1)", "Page up", show=False, id="blackboard.pageup", tooltip="A page up"),
        Binding(
            "pagedown", "page(1)", "Page down", show=False, id="blackboard.pagedown", tooltip="A page down"
        ),
        Binding("home", "jump(0)", "First", show=False, id="blackboard.home", tooltip="The first key"),
        Binding("end", "jump(-1)", "Last", show=False, id="blackboard.end", tooltip="The last key"),
    ]
    COMPONENT_CLASSES = {
        "blackboard-table--header",
        "blackboard-table--cursor",
        "blackboard-table--odd",
        "blackboard-table--scope",
    }
    DEFAULT_CSS = """
    BlackboardTable { height: 1fr; }
    BlackboardTable > .blackboard-table--header { text-style: bold; color: $text-accent; }
    BlackboardTable > .blackboard-table--cursor { background: $block-cursor-blurred-background; }
    BlackboardTable:focus > .blackboard-table--cursor {
        background: $block-cursor-background; color: $block-cursor-foreground;
    }
    BlackboardTable > .blackboard-table--odd { background: $surface-lighten-1 20%; }
    BlackboardTable > .blackboard-table--scope { color: $text-muted; }
    """

    cursor_row: reactive[int] = reactive(0, init=False)

    class KeyHighlighted(Message):
        """The cursor moved to another key (None: the table is empty)."""

        def __init__(self, key: RowKey | None) -> None:
            super().__init__()
            self.key = key

    def __init__(self, model: BlackboardModel, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self.model = model
        self.filter_text = ""
        self.keys: list[RowKey] = []

    # -- what is shown -------------------------------------------------------------------------------

    @property
    def shown(self) -> set[RowKey]:
        """The keys that pass the filter."""
        return set(self.keys)

    def rebuild(self, filter_text: str) -> None:
        """Show the model's entries that match ``filter_text`` (a new filter or a new model)."""
        self.filter_text = filter_text.strip().lower()
        self.keys = [row_key(entry) for entry in self.model.matching(self.filter_text)]
        self._changed(keep=self.selected_key())

    def apply(self, diff: BlackboardDiff) -> None:
        """Apply one diff to the key list (values are read from the model when drawn), then repaint."""
        selected = self.selected_key()
        for key in diff.removed:
            index = bisect_left(self.keys, key)
            if index < len(self.keys) and self.keys[index] == key:
                del self.keys[index]
        for entry in (*diff.added, *diff.changed):
            key = row_key(entry)
            index = bisect_left(self.keys, key)
            present = index < len(self.keys) and self.keys[index] == key
            wanted = not self.filter_text or matches(entry, self.filter_text)
            if wanted and not present:
                insort(self.keys, key)
            elif present and not wanted:
                del self.keys[index]
        self._changed(keep=selected)

    def selected_key(self) -> RowKey | None:
        """The (scope, key) under the cursor."""
        if 0 <= self.cursor_row < len(self.keys):
            return self.keys[self.cursor_row]
        return None

    def row_texts(self) -> list[tuple[str, str, str, str]]:
        """Scope, key, type and value of every shown row, as drawn (for tests and copy-out)."""
        out = []
        for key in self.keys:
            entry = self.model.entries.get(key)
            if entry is not None:
                out.append((entry.scope or "(root)", entry.key, entry.type_name, _one_line(entry.value)))
        return out

    def _changed(self, keep: RowKey | None) -> None:
        self.virtual_size = Size(self.size.width, len(self.keys) + 1)
        if keep is not None:
            index = bisect_left(self.keys, keep)
            if index < len(self.keys) and self.keys[index] == keep:
                self.set_cursor(index, announce=False)
                self.refresh()
                return
        self.set_cursor(min(self.cursor_row, max(0, len(self.keys) - 1)))
        self.refresh()

    # -- cursor ---------------------------------------------------------------------------------------

    def set_cursor(self, row: int, *, announce: bool = True) -> None:
        """Put the cursor on ``row`` (clamped) and scroll it into view."""
        row = max(0, min(row, len(self.keys) - 1)) if self.keys else 0
        moved = row != self.cursor_row
        self.cursor_row = row
        visible = max(1, self.size.height - 1)
        top = round(self.scroll_offset.y)
        if row < top:
            self.scroll_to(y=row, animate=False)
        elif row >= top + visible:
            self.scroll_to(y=row - visible + 1, animate=False)
        self.refresh()
        if announce or moved:
            self.post_message(self.KeyHighlighted(self.selected_key()))

    def action_move(self, step: int) -> None:
        self.set_cursor(self.cursor_row + step)

    def action_page(self, direction: int) -> None:
        self.set_cursor(self.cursor_row + direction * max(1, self.size.height - 2))

    def action_jump(self, row: int) -> None:
        self.set_cursor(row if row >= 0 else len(self.keys) - 1)

    def on_click(self, event: events.Click) -> None:
        if event.y >= 1:
            self.set_cursor(round(self.scroll_offset.y) + event.y - 1)

    def on_resize(self, event: events.Resize) -> None:
        self.virtual_size = Size(event.size.width, len(self.keys) + 1)

    # -- drawing --------------------------------------------------------------------------------------

    def render_line(self, y: int) -> Strip:
        width = self.size.width
        base = self.rich_style
        if y == 0:
            header = self.get_component_rich_style("blackboard-table--header")
            cells = [title for title, _ in COLUMNS] + ["Value"]
            return self._strip(cells, width, base + header, base + header)
        index = round(self.scroll_offset.y) + y - 1
        if index >= len(self.keys):
            return Strip.blank(width, base)
        entry = self.model.entries.get(self.keys[index])
        if entry is None:
            return Strip.blank(width, base)
        style = base
        if index % 2:
            style += self.get_component_rich_style("blackboard-table--odd")
        if index == self.cursor_row:
            style += self.get_component_rich_style("blackboard-table--cursor")
        scope_style = style + self.get_component_rich_style("blackboard-table--scope")
        cells = [entry.scope or "(root)", entry.key, entry.type_name, _one_line(entry.value)]
        return self._strip(cells, width, style, scope_style)

    @staticmethod
    def _strip(cells: list[str], width: int, style: Style, first_style: Style) -> Strip:
        segments = [Segment(" ", style)]
        used = 1
        for column_width, text, cell_style in zip(
            column_widths(width), cells, (first_style, style, style), strict=False
        ):
            if not column_width:
                continue
            segments.append(Segment(_fit(text, column_width), cell_style))
            segments.append(Segment(" ", style))
            used += column_width + 1
        value_width = max(MIN_VALUE_WIDTH, width - used - 1)
        segments.append(Segment(_fit(cells[-1], value_width), style))
        used += value_width
        if used < width:
            segments.append(Segment(" " * (width - used), style))
        return Strip(segments).crop(0, width)


def _one_line(value: str) -> str:
    return value.replace("\n", " ")


def _fit(text: str, width: int) -> str:
    """``text`` cut with an ellipsis or padded to exactly ``width`` cells."""
    if len(text) > width:
        return text[: max(0, width - 1)] + "…"
    return text.ljust(width)
