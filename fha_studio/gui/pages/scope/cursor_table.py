"""The scope's cursor table: the time of cursors A and B, and for every channel on show its value
at A and at B, the difference B − A and the slope between them."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import pyqtgraph as pg
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QAbstractItemView, QHeaderView, QTableWidget, QTableWidgetItem

from fha_studio.logic.wording import fixed_words

COLUMNS = ("Channel", "At A", "At B", "Δ (B − A)", "Slope")
#: Rows on show before the table scrolls (the plots keep the rest of the height).
MAX_VISIBLE_ROWS = 6


@dataclass(frozen=True)
class CursorRow:
    """One channel between the cursors: values at A and B and the slope [unit/s] (None: Δt = 0)."""

    name: str
    unit: str
    color: str
    at_a: float
    at_b: float
    slope_per_s: float | None


def _number(value: float, unit: str) -> str:
    return fixed_words(value, unit)  # "0.325 A" and "12.000 A": the digits line up, no exponent


class CursorTable(QTableWidget):
    """A row for the time, then one row per channel on show."""

    def __init__(self, parent=None):
        super().__init__(0, len(COLUMNS), parent)
        self.setObjectName("scopeCursorTable")
        self.setHorizontalHeaderLabels(COLUMNS)
        self.verticalHeader().setVisible(False)
        self.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.setSelectionMode(QAbstractItemView.SelectionMode.NoSelection)
        rows = self.verticalHeader()
        rows.setSectionResizeMode(QHeaderView.ResizeMode.Fixed)
        rows.setDefaultSectionSize(self.fontMetrics().height() + 6)
        header = self.horizontalHeader()
        header.setSectionResizeMode(0, QHeaderView.ResizeMode.Stretch)
        for column in range(1, len(COLUMNS)):
            header.setSectionResizeMode(column, QHeaderView.ResizeMode.ResizeToContents)

    def show_rows(self, t_a_s: float, t_b_s: float, rows: Sequence[CursorRow],
                  time_name: str = "Time") -> None:
        """The cursors at ``t_a_s`` and ``t_b_s`` as the time axis reads them, and ``rows``."""
        dt = t_b_s - t_a_s
        table = [(time_name, "", _number(t_a_s, "s"), _number(t_b_s, "s"), _number(dt * 1000, "ms"),
                  f"1/Δt = {_number(1 / abs(dt), 'Hz')}" if dt else "—")]
        for r in rows:
            slope = "—" if r.slope_per_s is None else _number(r.slope_per_s, f"{r.unit}/s")
            table.append((r.name, r.color, _number(r.at_a, r.unit), _number(r.at_b, r.unit),
                           _number(r.at_b - r.at_a, r.unit), slope))
        self._fill(table)

    def show_message(self, text: str) -> None:
        self._fill([(text, "", "", "", "", "")])

    def _fill(self, table: list[tuple[str, str, str, str, str, str]]) -> None:
        self.setRowCount(len(table))
        for row, (name, color, *cells) in enumerate(table):
            item = QTableWidgetItem(name)
            if color:
                item.setForeground(pg.mkColor(color))
            self.setItem(row, 0, item)
            for column, text in enumerate(cells, start=1):
                cell = QTableWidgetItem(text)
                cell.setTextAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
                self.setItem(row, column, cell)
        rows_shown = min(len(table), MAX_VISIBLE_ROWS)
        height = self.horizontalHeader().height() + 2 * self.frameWidth()
        height += sum(self.rowHeight(r) for r in range(rows_shown))
        self.setFixedHeight(height)

    def cell_text(self, row: int, column: int) -> str:
        item = self.item(row, column)
        return item.text() if item is not None else ""
