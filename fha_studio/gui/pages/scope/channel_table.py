"""The scope's channel table: which channels the plot shows, their unit and display scale."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import pyqtgraph as pg
from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import QAbstractItemView, QDoubleSpinBox, QTableWidget, QTableWidgetItem

from fha_studio.logic.scope.channels import ScopeChannel
from fha_studio.logic.wording import unit_words


class ChannelTable(QTableWidget):
    """One row per channel: a check box (shown or not), the unit, and a scale factor."""

    sigVisibleChanged = Signal(str, bool)  # channel key, shown
    sigScaleChanged = Signal(str, float)  # channel key, factor

    def __init__(self, parent=None):
        super().__init__(0, 3, parent)
        self.setObjectName("scopeChannels")
        self.setHorizontalHeaderLabels(["Channel", "Unit", "Scale ×"])
        self.verticalHeader().setVisible(False)
        self.setSelectionMode(QAbstractItemView.SelectionMode.NoSelection)
        header = self.horizontalHeader()
        header.setSectionResizeMode(0, header.ResizeMode.Stretch)
        header.setSectionResizeMode(1, header.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(2, header.ResizeMode.Fixed)
        self.setColumnWidth(2, 78)
        self.setMinimumWidth(240)
        self.itemChanged.connect(self._item_changed)

    def fill(self, channels: Sequence[ScopeChannel], visible: Mapping[str, bool], scale: Mapping[str, float],
             color: Callable[[str], str]) -> None:
        self.blockSignals(True)
        self.setRowCount(len(channels))
        for row, c in enumerate(channels):
            name = QTableWidgetItem(c.name)
            name.setData(Qt.ItemDataRole.UserRole, c.key)
            name.setFlags(Qt.ItemFlag.ItemIsEnabled | Qt.ItemFlag.ItemIsUserCheckable)
            shown = visible.get(c.key, True)
            name.setCheckState(Qt.CheckState.Checked if shown else Qt.CheckState.Unchecked)
            name.setForeground(pg.mkColor(color(c.key)))
            self.setItem(row, 0, name)
            unit = QTableWidgetItem(unit_words(c.unit))  # as the manual prints it: °, not deg
            unit.setFlags(Qt.ItemFlag.ItemIsEnabled)
            self.setItem(row, 1, unit)
            spin = QDoubleSpinBox()
            spin.setRange(1e-4, 1e4)
            spin.setDecimals(3)
            spin.setToolTip(f"Multiply {c.name} by this factor on the plot "
                            f"(cursors read {unit_words(c.unit)})")
            spin.setValue(scale.get(c.key, 1.0))
            spin.valueChanged.connect(lambda v, k=c.key: self.sigScaleChanged.emit(k, float(v)))
            self.setCellWidget(row, 2, spin)
        self.blockSignals(False)

    def _item_changed(self, item: QTableWidgetItem) -> None:
        if item.column() == 0:
            self.sigVisibleChanged.emit(item.data(Qt.ItemDataRole.UserRole),
                                        item.checkState() == Qt.CheckState.Checked)
