"""A DataTable whose columns fit the width it has: the least important drop first, long cells wrap.

A stock ``DataTable`` sizes each column to its longest cell, so at 80 columns a long key pushes the value
off the right edge and the user sees ``Scope | Key`` and nothing else. Here each column says how narrow
it may get, how much of the spare width it takes, and in which order it is dropped when even the
narrowest layout does not fit; cells wider than their column wrap onto more lines of their row.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from rich.text import Text
from textual import events
from textual.widgets import DataTable


@dataclass(frozen=True)
class Column:
    """How one column gives way.

    Attributes:
        key / label: the column's key and header.
        min_width: the narrowest it gets (never wider than its widest cell needs).
        weight: its share of the width left once every column has its minimum.
        drop: dropping order when the minimums do not fit: the highest goes first; 0 is never dropped.
        wrap: a cell wider than the column wraps onto more lines; False cuts it with an ellipsis (a name
            read at a glance, such as a joint's, beside a value that must never be cut).
    """

    key: str
    label: str
    min_width: int = 8
    weight: float = 1.0
    drop: int = 0
    wrap: bool = True


#: The ports of an objective or a behavior: the description stays, the direction goes first.
PORT_COLUMNS = (
    Column("name", "Port", min_width=22, weight=1),  # an identifier: read whole, wrapped only past 22
    Column("direction", "Dir", min_width=6, weight=0, drop=3),
    Column("type", "Type", min_width=8, weight=1, drop=2),
    Column("default", "Default", min_width=8, weight=1, drop=1),
    Column("description", "Description", min_width=16, weight=3),
)


def fit_widths(columns: Sequence[Column], natural: Sequence[int], available: int, gap: int) -> list[int]:
    """Each column's width (0: dropped) for ``available`` cells, each column costing ``gap`` more.

    A column is never given more than its ``natural`` width (its widest cell); below that its cells wrap.
    """
    shown = list(range(len(columns)))
    while sum(min(columns[i].min_width, natural[i]) + gap for i in shown) > available:
        droppable = [i for i in shown if columns[i].drop > 0]
        if not droppable:
            break
        shown.remove(max(droppable, key=lambda i: (columns[i].drop, i)))
    widths = {i: max(1, min(columns[i].min_width, natural[i])) for i in shown}
    spare = available - sum(widths.values()) - gap * len(shown)
    while spare > 0:
        growing = [i for i in shown if widths[i] < natural[i] and columns[i].weight > 0]
        if not growing:
            break
        total = sum(columns[i].weight for i in growing)
        given = 0
        for i in growing:
            share = max(1, int(spare * columns[i].weight / total))
            share = min(share, natural[i] - widths[i], spare - given)
            widths[i] += share
            given += share
            if given >= spare:
                break
        if given == 0:
            break
        spare -= given
    return [widths.get(i, 0) for i in range(len(columns))]


class FittedTable(DataTable[Text]):
    """A row-cursor table of :class:`Text` cells laid out by :func:`fit_widths` whenever its width changes.

    Set its content with :meth:`set_rows` (not ``add_row``): the table re-adds the rows when it re-fits.
    """

    def __init__(self, columns: Sequence[Column], *, id: str | None = None) -> None:
        super().__init__(id=id, cursor_type="row", zebra_stripes=True)
        self.specs = tuple(columns)
        self.rows_data: list[tuple[Text, ...]] = []
        self.row_keys_data: list[str | None] = []
        self.widths: list[int] = []

    def on_mount(self) -> None:
        self._fit(force=True)

    def set_rows(
        self, rows: Sequence[Sequence[Text | str]], keys: Sequence[str | None] | None = None
    ) -> None:
        """Show ``rows`` (one cell per column), each with its key (for ``get_row`` and the cursor)."""
        self.rows_data = [tuple(c if isinstance(c, Text) else Text(c) for c in row) for row in rows]
        self.row_keys_data = list(keys) if keys is not None else [None] * len(self.rows_data)
        self._fit(force=True)

    def on_resize(self, event: events.Resize) -> None:
        self._fit()

    def shown_columns(self) -> list[str]:
        """The keys of the columns the current width shows."""
        return [spec.key for spec, width in zip(self.specs, self.widths, strict=False) if width]

    def _fit(self, *, force: bool = False) -> None:
        width = self.scrollable_content_region.width or self.size.width
        if width <= 0:  # not laid out yet (a hidden tab): natural widths until it is shown and resized
            width = 1 << 20
        natural = [
            max([len(spec.label), *(row[i].cell_len for row in self.rows_data if i < len(row))])
            for i, spec in enumerate(self.specs)
        ]
        # The vertical scrollbar, when the rows are more than fit, takes two cells.
        widths = fit_widths(self.specs, natural, width - 2, 2 * self.cell_padding)
        if widths == self.widths and not force:
            return
        self.widths = widths
        cursor = self.cursor_row
        self.clear(columns=True)
        for spec, column_width in zip(self.specs, widths, strict=True):
            if column_width:
                self.add_column(spec.label, key=spec.key, width=column_width)
        for row, key in zip(self.rows_data, self.row_keys_data, strict=True):
            cells = []
            wraps = False
            for cell, spec, column_width in zip(row, self.specs, widths, strict=True):
                if not column_width:
                    continue
                if cell.cell_len > column_width:
                    if spec.wrap:
                        wraps = True
                    else:
                        cell = cell.copy()
                        cell.truncate(column_width, overflow="ellipsis")
                cells.append(cell)
            self.add_row(*cells, key=key, height=None if wraps else 1)
        if self.row_count:
            self.move_cursor(row=min(cursor, self.row_count - 1), animate=False)
