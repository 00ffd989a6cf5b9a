"""The Parameters page's table: the driver's tune and parameter (system) items with their values
as known (read from the drive, else entered from its front panel), the edits not yet written, and
the editor of a value in the manual's units."""

from __future__ import annotations

from PySide6.QtCore import QAbstractTableModel, QModelIndex, Qt, Signal, Slot
from PySide6.QtGui import QBrush, QColor, QFont
from PySide6.QtWidgets import QComboBox, QLineEdit, QStyledItemDelegate

from fha_studio.gui.parameter_text import MODE_WORDS, parse_value, range_text, value_text
from fha_studio.gui.session import Session

COLUMNS = ("Mode", "No.", "Name", "Value", "Unit", "Range", "Default", "State")
COL_VALUE = 3
EDITED_BRUSH = QBrush(QColor("#fff1b8"))
DIFFERS_COLOUR = QColor("#0d47a1")
_ROOT = QModelIndex()


#: The item fields the public manual does not state, in words (the help pane names them).
ASSUMED_FIELD_WORDS = {
    "restart_required": "whether it needs a power cycle",
    "minimum": "the lowest value",
    "maximum": "the highest value",
    "default": "the default",
    "scale": "the value step",
    "unit": "the unit",
    "writable": "whether it can be written over CN3",
    "choices": "the choices",
    "number": "the item number",
    "mode": "the mode",
}


class ParameterTableModel(QAbstractTableModel):
    """Items x (mode, number, name, value, unit, range, default, state). Edits stay here until
    written; the drive's values come from the session."""

    sigRefused = Signal(str, QModelIndex)  # why, where
    sigEditsChanged = Signal(int)  # number of edited-not-written items

    def __init__(self, session: Session, parent=None):
        super().__init__(parent)
        self.session = session
        self.items: list = []
        self.edits: dict[tuple[str, int], int] = {}
        self.restart_pending: set[tuple[str, int]] = set()
        #: a drive without parameter access: the Value column holds what the front panel shows,
        #: entered by ``who`` (the front-panel worksheet)
        self.panel_mode = False
        self.who = ""
        self.reload_items()
        session.state.sigParametersChanged.connect(self._values_changed)
        session.state.sigFrontPanelChanged.connect(self._all_changed)

    def set_panel_mode(self, on: bool) -> None:
        if on != self.panel_mode:
            self.panel_mode = on
            self.edits.clear()
            self.headerDataChanged.emit(Qt.Orientation.Horizontal, COL_VALUE, COL_VALUE)
            self._all_changed()
            self.sigEditsChanged.emit(0)

    def reload_items(self) -> None:
        self.beginResetModel()
        try:
            self.items = self.session.editable_items()
        except Exception:
            self.items = []
        self.endResetModel()

    # -- Qt model API -------------------------------------------------------------------------------
    def rowCount(self, parent=_ROOT) -> int:
        return 0 if parent.isValid() else len(self.items)

    def columnCount(self, parent=_ROOT) -> int:
        return 0 if parent.isValid() else len(COLUMNS)

    def headerData(self, section, orientation, role=Qt.ItemDataRole.DisplayRole):
        if role == Qt.ItemDataRole.DisplayRole and orientation == Qt.Orientation.Horizontal:
            if section == COL_VALUE and self.panel_mode:
                return "Value on the drive's panel"
            return COLUMNS[section]
        return None

    def flags(self, index):
        base = Qt.ItemFlag.ItemIsEnabled | Qt.ItemFlag.ItemIsSelectable
        if index.column() == COL_VALUE:
            base |= Qt.ItemFlag.ItemIsEditable
        return base

    def key(self, row: int) -> tuple[str, int]:
        item = self.items[row]
        return (item.mode, item.number)

    def shown_value(self, row: int) -> int | None:
        key = self.key(row)
        if self.panel_mode:
            return self.session.state.value_of(*key)
        return self.edits.get(key, self.session.state.drive_values.get(key))

    def state_text(self, row: int) -> str:
        item = self.items[row]
        key = self.key(row)
        drive = self.session.state.drive_values.get(key)
        words = []
        panel = self.session.state.front_panel.get(key)
        if self.panel_mode and drive is None:
            words.append(f"from the panel: {panel.who}, {panel.time[11:16]}" if panel is not None
                         else f"not entered: {MODE_WORDS.get(str(item.mode), str(item.mode))} "
                         f"{item.number} on the panel")  # short: the name keeps its room
        elif key in self.edits:
            words.append("edited, not written")
        elif drive is None:
            words.append("not read")
        shown = self.shown_value(row)
        if shown is not None and item.default is not None and shown != item.default:
            words.append("≠ default")
        if key in self.restart_pending:
            # the item's nature (takes effect at power-on) is in its help, not in its state: after
            # the power cycle nothing is pending, and the State column must say so
            words.append("power cycle needed")
        return ", ".join(words)

    def data(self, index, role=Qt.ItemDataRole.DisplayRole):
        if not index.isValid():
            return None
        row, col = index.row(), index.column()
        item = self.items[row]
        key = self.key(row)
        if role in (Qt.ItemDataRole.DisplayRole, Qt.ItemDataRole.EditRole):
            if col == 0:
                return MODE_WORDS.get(str(item.mode), str(item.mode))
            if col == 1:
                return item.number
            if col == 2:
                return item.name
            if col == COL_VALUE:
                return value_text(item, self.shown_value(row))
            if col == 4:
                return item.unit
            if col == 5:
                return range_text(item)
            if col == 6:
                return value_text(item, item.default)
            if col == 7:
                return self.state_text(row)
        if role == Qt.ItemDataRole.ToolTipRole:
            tip = f"<b>{MODE_WORDS.get(str(item.mode))} {item.number}: {item.name}</b><br>{item.description}"
            if item.choices:
                tip += "<br>" + "<br>".join(f"{k}: {v}" for k, v in item.choices.items())
            tip += f"<br><i>Source: {item.source}</i>"
            if not item.certain:
                fields = ", ".join(ASSUMED_FIELD_WORDS.get(f, f.replace("_", " ")) for f in item.assumed)
                tip += f"<br><i>Not stated in the public manual ({fields}): {item.note}</i>"
            if item.restart_required:
                tip += "<br><b>Takes effect after the driver's control power is cycled.</b>"
            return tip
        if role == Qt.ItemDataRole.BackgroundRole and key in self.edits:
            return EDITED_BRUSH
        if role == Qt.ItemDataRole.FontRole and key in self.edits and col in (COL_VALUE, 7):
            font = QFont()
            font.setBold(True)
            return font
        if role == Qt.ItemDataRole.ForegroundRole and col in (COL_VALUE, 7):
            shown = self.shown_value(row)
            if shown is not None and item.default is not None and shown != item.default:
                return QBrush(DIFFERS_COLOUR)
        if role == Qt.ItemDataRole.TextAlignmentRole and col in (1, COL_VALUE, 6):
            return (
                int(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter) if not item.choices else None
            )
        if role == Qt.ItemDataRole.AccessibleDescriptionRole and col == COL_VALUE:
            return self.state_text(row)
        return None

    def setData(self, index, value, role=Qt.ItemDataRole.EditRole) -> bool:
        if role != Qt.ItemDataRole.EditRole or index.column() != COL_VALUE:
            return False
        item = self.items[index.row()]
        try:
            wire = (
                value
                if isinstance(value, int) and not isinstance(value, bool)
                else parse_value(item, str(value))
            )
            item.check(wire)
        except ValueError as exc:
            self.sigRefused.emit(f"Refused: {exc}. Allowed: {range_text(item)} {item.unit}".rstrip(), index)
            return False
        if self.panel_mode:
            if not self.who.strip():
                self.sigRefused.emit("Enter your name (Entered by) first: every value from the panel is "
                                     "recorded with who and when.", index)
                return False
            self.session.state.enter_front_panel(item.mode, item.number, wire, self.who)
            return True
        self.set_edit(item.mode, item.number, wire)
        return True

    # -- edits --------------------------------------------------------------------------------------
    def set_edit(self, mode: str, number: int, wire: int) -> None:
        key = (mode, number)
        if self.session.state.drive_values.get(key) == wire:
            self.edits.pop(key, None)
        else:
            self.edits[key] = wire
        self._row_changed(key)
        self.sigEditsChanged.emit(len(self.edits))

    def revert(self) -> None:
        self.edits.clear()
        self._all_changed()
        self.sigEditsChanged.emit(0)

    def row_of(self, key: str) -> int:
        return next(r for r, i in enumerate(self.items) if i.key == key)

    def _row_changed(self, key) -> None:
        for row, item in enumerate(self.items):
            if (item.mode, item.number) == key:
                self.dataChanged.emit(self.index(row, 0), self.index(row, len(COLUMNS) - 1))

    def _all_changed(self) -> None:
        if self.items:
            self.dataChanged.emit(self.index(0, 0), self.index(len(self.items) - 1, len(COLUMNS) - 1))

    @Slot()
    def _values_changed(self) -> None:
        # an edit equal to what the drive now holds is no longer an edit
        for key in [k for k, v in self.edits.items() if self.session.state.drive_values.get(k) == v]:
            del self.edits[key]
        self._all_changed()
        self.sigEditsChanged.emit(len(self.edits))


class ValueDelegate(QStyledItemDelegate):
    """A combo box for choice items, a line edit showing the allowed range for numbers."""

    def createEditor(self, parent, option, index):
        item = index.model().items[index.row()]
        if item.choices:
            combo = QComboBox(parent)
            for wire, meaning in item.choices.items():
                combo.addItem(f"{wire}: {meaning}", wire)
            return combo
        edit = QLineEdit(parent)
        edit.setPlaceholderText(f"{range_text(item)} {item.unit}".strip())
        edit.setToolTip(f"Allowed: {range_text(item)} {item.unit}".strip())
        return edit

    def setEditorData(self, editor, index):
        model = index.model()
        wire = model.shown_value(index.row())
        if isinstance(editor, QComboBox):
            found = editor.findData(wire)
            editor.setCurrentIndex(max(0, found))
        else:
            editor.setText(value_text(model.items[index.row()], wire))
            editor.selectAll()

    def setModelData(self, editor, model, index):
        if isinstance(editor, QComboBox):
            model.setData(index, int(editor.currentData()))
        else:
            model.setData(index, editor.text())
