"""The Procedures page's record of what was answered: every value whole, the selected record in full.

A narrow pane beside the step: the table wraps each value onto as many lines as it needs (the row
grows); the step's text asks for two lines at most (elided: it is whole in its tooltip and below);
pass / FAIL; who, the day and the time to the minute on lines of their own. Below the table the
selected record in full: the step's section and text, the value, the result, who and when, and
where the value came from. The newest record is selected as it comes, so the last answer is
readable without a click.
"""

from __future__ import annotations

import html
from collections.abc import Sequence

from PySide6.QtCore import QSize, Qt
from PySide6.QtGui import QBrush, QColor, QFont
from PySide6.QtWidgets import (
    QAbstractItemView,
    QHeaderView,
    QLabel,
    QScrollArea,
    QSplitter,
    QStyledItemDelegate,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from fha_studio.logic.procedures.report import value_text, when_minutes
from fha_studio.logic.procedures.session import CheckRecord
from fha_studio.logic.register.words import when_text

HEADERS = ("Step", "Value", "Result", "Who, when (UTC)")
STEP_LINES = 2
FAIL_COLOUR = "#b00000"
EMPTY_TEXT = "No answer recorded yet: each one comes here in full."
PICK_TEXT = "Select a record to read it in full."


class _AtMostLines(QStyledItemDelegate):
    """A wrapped cell that asks for ``lines`` lines at most (the rest is elided, whole elsewhere)."""

    def __init__(self, lines: int, parent: QWidget | None = None):
        super().__init__(parent)
        self.lines = lines

    def sizeHint(self, option, index) -> QSize:
        hint = super().sizeHint(option, index)
        cap = option.fontMetrics.lineSpacing() * self.lines + 2 * 3  # the cell's margins
        return QSize(hint.width(), min(hint.height(), cap))


class RecordHistory(QWidget):
    """The table of records (:attr:`table`) over the selected record in full (:attr:`details`)."""

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        table = self.table = QTableWidget(0, len(HEADERS))
        table.setObjectName("history")
        table.setHorizontalHeaderLabels(list(HEADERS))
        table.setWordWrap(True)
        table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        table.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        table.setVerticalScrollMode(QAbstractItemView.ScrollMode.ScrollPerPixel)
        table.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)  # every column in view
        table.setItemDelegateForColumn(0, _AtMostLines(STEP_LINES, table))
        header = table.horizontalHeader()
        header.setSectionResizeMode(0, QHeaderView.ResizeMode.Stretch)
        header.setSectionResizeMode(1, QHeaderView.ResizeMode.Stretch)
        header.setSectionResizeMode(2, QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(3, QHeaderView.ResizeMode.ResizeToContents)
        # rows as tall as their wrapped values, again whenever the columns change width
        table.verticalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        table.verticalHeader().hide()  # the rows are in the order they were recorded
        header.sectionResized.connect(lambda *_: table.resizeRowsToContents())
        table.itemSelectionChanged.connect(self._show_selected)

        self.details = QLabel("")
        self.details.setObjectName("history_details")
        self.details.setWordWrap(True)
        self.details.setTextFormat(Qt.TextFormat.RichText)
        self.details.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.details.setAlignment(Qt.AlignmentFlag.AlignTop | Qt.AlignmentFlag.AlignLeft)
        self.details.setContentsMargins(4, 4, 4, 4)
        scroll = QScrollArea()
        scroll.setWidgetResizable(True)
        scroll.setWidget(self.details)

        split = QSplitter(Qt.Orientation.Vertical, self)
        split.addWidget(table)
        split.addWidget(scroll)
        split.setStretchFactor(0, 3)
        split.setStretchFactor(1, 1)
        split.setSizes([300, 140])
        split.setChildrenCollapsible(False)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(split)
        self._records: list[CheckRecord] = []

    def show_records(self, records: Sequence[CheckRecord]) -> None:
        """The records, oldest first; the newest selected (its whole text below the table)."""
        self._records = list(records)
        table = self.table
        table.setRowCount(len(self._records))
        bold = QFont(table.font())
        bold.setBold(True)
        for row, r in enumerate(self._records):
            value = value_text(r)
            # who, the day and the time (to the minute, as the report gives it) on lines of their own
            when = when_minutes(r.at_utc).replace(" ", "\n", 1)
            cells = (r.text, value, "pass" if r.passed else "FAIL", f"{r.who}\n{when}")
            tips = (f"{r.section}: {r.text}" if r.section else r.text, r.detail or value, cells[2], cells[3])
            for column, (text, tip) in enumerate(zip(cells, tips, strict=True)):
                item = QTableWidgetItem(text)
                item.setToolTip(tip)
                if column == 2 and not r.passed:
                    item.setForeground(QBrush(QColor(FAIL_COLOUR)))
                    item.setFont(bold)
                table.setItem(row, column, item)
        if self._records:
            table.selectRow(len(self._records) - 1)
            table.scrollToBottom()
        self._show_selected()

    def _show_selected(self) -> None:
        rows = self.table.selectionModel().selectedRows()
        if not rows or not 0 <= rows[0].row() < len(self._records):
            hint = PICK_TEXT if self._records else EMPTY_TEXT
            self.details.setText(f'<span style="color: #666;">{hint}</span>')
            return
        self.details.setText(record_html(self._records[rows[0].row()]))


def record_html(r: CheckRecord) -> str:
    """One record in full, as the pane below the table shows it."""
    result = ("pass" if r.passed
              else f'<span style="color: {FAIL_COLOUR}; font-weight: bold;">FAIL</span>')
    section = f"{html.escape(r.section)} · " if r.section else ""
    lines = [
        f"<b>{section}{html.escape(r.text)}</b>",
        f"{html.escape(value_text(r)) or '(no value)'} — {result}",
        f"{html.escape(r.who)}, {html.escape(when_text(r.at_utc))} UTC",
    ]
    if r.detail:
        lines.append(html.escape(r.detail))
    return "<br>".join(lines)
