"""The live blackboard table: rows are added, changed and removed one by one, never rebuilt per update."""

from __future__ import annotations

from typing import Self

from rich.markup import escape
from textual.geometry import Region
from textual.widgets import DataTable

from kinema.tui.blackboard_model import BlackboardDiff, BlackboardModel, RowKey, matches, row_id, row_key
from kinema.tui.connection import BlackboardEntry

#: Values longer than this are cut in the table (the history panel shows the whole value).
MAX_CELL = 80


class BlackboardTable(DataTable[str]):
    """Scope, key, type and value of every blackboard entry that matches the filter."""

    # Class-level: DataTable.__init__ already refreshes, before instance attributes exist.
    _batching = False
    _refresh_wanted = False

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id, cursor_type="row", zebra_stripes=True)
        self.filter_text = ""
        self.shown: set[RowKey] = set()
        self._types: dict[RowKey, str] = {}

    def on_mount(self) -> None:
        self.add_column("Scope", key="scope", width=22)
        self.add_column("Key", key="key", width=28)
        self.add_column("Type", key="type", width=14)
        self.add_column("Value", key="value")

    def rebuild(self, model: BlackboardModel, filter_text: str) -> None:
        """Show the model's entries that match ``filter_text`` (a new filter; not for live updates)."""
        self.filter_text = filter_text.strip().lower()
        self.clear()
        self.shown = set()
        self._types = {}
        self._batching = True
        try:
            for entry in model.matching(self.filter_text):
                self._add(entry)
        finally:
            self._batching = False
        self._refresh_wanted = False
        self.refresh()

    def apply(self, diff: BlackboardDiff) -> None:
        """Apply one diff: update changed cells, add new rows, remove gone ones (one repaint in all)."""
        self._batching = True
        try:
            for key in diff.removed:
                if key in self.shown:
                    self._remove(key)
            for entry in diff.added:
                if self._wanted(entry):
                    self._add(entry)
            for entry in diff.changed:
                key = row_key(entry)
                wanted = self._wanted(entry)
                if key in self.shown and wanted:
                    rid = row_id(key)
                    if self._types.get(key) != entry.type_name:
                        self._types[key] = entry.type_name
                        self.update_cell(rid, "type", escape(entry.type_name))
                    self.update_cell(rid, "value", _cell(entry.value))
                elif key in self.shown:
                    self._remove(key)
                elif wanted:
                    self._add(entry)
        finally:
            self._batching = False
        if self._refresh_wanted:
            self._refresh_wanted = False
            self.refresh()

    def refresh(
        self, *regions: Region, repaint: bool = True, layout: bool = False, recompose: bool = False
    ) -> Self:
        # update_cell() repaints the table each time; a diff of 1,000 changed values repaints once.
        if self._batching and not regions and not layout and not recompose:
            self._refresh_wanted = True
            return self
        return super().refresh(*regions, repaint=repaint, layout=layout, recompose=recompose)

    def selected_key(self) -> RowKey | None:
        """The (scope, key) under the cursor."""
        if self.row_count == 0:
            return None
        try:
            cell_key = self.coordinate_to_cell_key(self.cursor_coordinate)
        except Exception:
            return None
        value = cell_key.row_key.value
        if value is None:
            return None
        scope, _, key = value.partition("\x1f")
        return (scope, key)

    def _wanted(self, entry: BlackboardEntry) -> bool:
        return not self.filter_text or matches(entry, self.filter_text)

    def _add(self, entry: BlackboardEntry) -> None:
        key = row_key(entry)
        self.shown.add(key)
        self._types[key] = entry.type_name
        self.add_row(
            escape(entry.scope or "(root)"),
            escape(entry.key),
            escape(entry.type_name),
            _cell(entry.value),
            key=row_id(key),
        )

    def _remove(self, key: RowKey) -> None:
        self.shown.discard(key)
        self._types.pop(key, None)
        self.remove_row(row_id(key))


def _cell(value: str) -> str:
    """The value as table text: one line, cut to :data:`MAX_CELL`, markup escaped.

    Escaped text rather than a ``Text`` object: the table parses it only for the rows on screen, which
    keeps a 1,000-value update cheap, and ``[1, 2]`` still shows as written.
    """
    single = value.replace("\n", " ")
    return escape(single if len(single) <= MAX_CELL else single[: MAX_CELL - 1] + "…")
