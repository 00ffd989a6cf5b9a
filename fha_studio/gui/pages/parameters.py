"""The parameter editor: one table of the tune and parameter (system) items of the driver."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QAbstractTableModel, QModelIndex, QPoint, QSettings, Qt, QTimer, Signal, Slot
from PySide6.QtGui import QBrush, QColor, QFont
from PySide6.QtWidgets import (
    QAbstractItemView,
    QComboBox,
    QFileDialog,
    QFrame,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QMessageBox,
    QPlainTextEdit,
    QPushButton,
    QScrollArea,
    QSizePolicy,
    QSplitter,
    QStyledItemDelegate,
    QTableView,
    QToolTip,
    QVBoxLayout,
    QWidget,
)

from fha_studio import fileio
from fha_studio.gui.diff_dialog import ParameterDiffDialog
from fha_studio.gui.link import LinkInfo, LinkReply, ParameterReadout, PowerCycle
from fha_studio.gui.pages.base import BasePage
from fha_studio.gui.parameter_text import MODE_WORDS, parse_value, range_text, value_text
from fha_studio.gui.session import Session

COLUMNS = ("Mode", "No.", "Name", "Value", "Unit", "Range", "Default", "State")
COL_VALUE = 3
EDITED_BRUSH = QBrush(QColor("#fff1b8"))
DIFFERS_COLOUR = QColor("#0d47a1")
#: Why the write buttons are off while the servo is on (the driver's rule for parameter mode).
SERVO_ON_WRITE_REASON = (
    "The servo is on: parameter-mode items can be written only with the servo off. "
    "Switch the servo off (toolbar or controller) to write them."
)
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
                         else f"not entered: {MODE_WORDS.get(str(item.mode), str(item.mode))} mode, "
                         f"item {item.number} on the panel")
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


class ParametersPage(BasePage):
    """Read, edit, write (verified), save and load the driver's parameters."""

    def __init__(self, session: Session, main_window=None):
        super().__init__()
        self.session = session
        self.link = session.link
        self.main_window = main_window
        self.model = ParameterTableModel(session, self)
        layout = QVBoxLayout(self)

        buttons = QHBoxLayout()
        self.read_button = QPushButton("&Read all")
        self.read_button.setToolTip("Read every tune and parameter item from the drive")
        self.write_changed_button = QPushButton("&Write changed")
        self.write_changed_button.setToolTip(
            "Write the edited items (yellow), each verified by reading it back"
        )
        self.write_all_button = QPushButton("Write a&ll")
        self.write_all_button.setToolTip("Write every item as shown, each verified by reading it back")
        self.revert_button = QPushButton("Re&vert edits")
        self.save_button = QPushButton("&Save file…")
        self.save_button.setToolTip("Save the drive's values (as last read) to a parameter file (TOML)")
        self.load_button = QPushButton("L&oad file…")
        self.load_button.setToolTip(
            "Compare a parameter file with the drive and the defaults; choose what to apply"
        )
        for b in (self.read_button, self.write_changed_button, self.write_all_button, self.revert_button):
            buttons.addWidget(b)
        for b in (self.write_changed_button, self.write_all_button):
            b.setProperty("plainToolTip", b.toolTip())
        self.servo_note = QLabel("")
        self.servo_note.setObjectName("servoOnWriteNote")
        self.servo_note.setWordWrap(True)
        self.servo_note.setStyleSheet("color: #8a5a00; font-weight: bold;")
        self.servo_note.setVisible(False)
        self._servo_was_on = False
        buttons.addWidget(self.servo_note, 1)
        buttons.addStretch(1)
        buttons.addWidget(self.save_button)
        buttons.addWidget(self.load_button)
        layout.addLayout(buttons)

        # the front-panel worksheet: a drive without parameter access over CN3
        self.panel_bar = QWidget()
        pb = QHBoxLayout(self.panel_bar)
        pb.setContentsMargins(6, 4, 6, 4)
        self.panel_note = QLabel(
            "This drive gives no parameter access over CN3. On its front panel, choose the mode and "
            "the item number shown in the table, read (or set) the value and type it into <b>Value on "
            "the drive's panel</b>: it is recorded with who and when, compared with the default and a "
            "parameter file, saved to files marked as entered from the panel, and goes into the report."
        )
        self.panel_note.setWordWrap(True)
        self.who_edit = QLineEdit()
        self.who_edit.setObjectName("panelWho")
        self.who_edit.setPlaceholderText("your name")
        self.who_edit.textChanged.connect(self._who_changed)
        pb.addWidget(self.panel_note, 1)
        pb.addWidget(QLabel("Entered by:"))
        pb.addWidget(self.who_edit)
        self.panel_bar.setStyleSheet("background: #e8f0fe; border-radius: 4px;")
        self.panel_bar.setVisible(False)
        layout.addWidget(self.panel_bar)

        self.restart_banner = QFrame()
        self.restart_banner.setObjectName("restartBanner")
        rb = QHBoxLayout(self.restart_banner)
        rb.setContentsMargins(6, 4, 6, 4)
        self.restart_label = QLabel("")
        self.restart_label.setWordWrap(True)
        self.power_cycle_button = QPushButton("&Power cycle the drive now")
        # the button keeps its whole text whatever the label needs
        self.power_cycle_button.setSizePolicy(QSizePolicy.Policy.Minimum, QSizePolicy.Policy.Fixed)
        rb.addWidget(self.restart_label, 1)
        rb.addWidget(self.power_cycle_button)
        # the frame only: a style on the children (label, button) would box the text and squeeze the
        # button's text out of its own frame
        self.restart_banner.setStyleSheet(
            "QFrame#restartBanner { background: #fff3cd; border: 1px solid #e0a000; border-radius: 4px; }"
        )
        self.restart_banner.setVisible(False)
        layout.addWidget(self.restart_banner)

        splitter = QSplitter(Qt.Orientation.Vertical)
        splitter.setObjectName("parametersSplitter")
        self.splitter = splitter
        self.table = QTableView()
        self.table.setObjectName("parameterTable")
        self.table.setModel(self.model)
        self.table.setItemDelegateForColumn(COL_VALUE, ValueDelegate(self.table))
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.table.setEditTriggers(
            QAbstractItemView.EditTrigger.DoubleClicked
            | QAbstractItemView.EditTrigger.EditKeyPressed
            | QAbstractItemView.EditTrigger.AnyKeyPressed
        )
        self.table.verticalHeader().setVisible(False)
        self.table.verticalHeader().setDefaultSectionSize(self.table.fontMetrics().height() + 8)
        self.table.setWordWrap(False)
        self.table.setTextElideMode(Qt.TextElideMode.ElideRight)
        self.table.setAlternatingRowColors(True)
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        # the value is what matters: it is shown whole; the name takes the room that is left
        header.setSectionResizeMode(2, QHeaderView.ResizeMode.Stretch)
        header.setMinimumSectionSize(self.table.fontMetrics().averageCharWidth() * 4)
        splitter.addWidget(self.table)
        # the manual's description beside the session log (not above it): the table keeps the height,
        # and a description longer than its room scrolls instead of losing its last lines
        log_box = QWidget()
        lb = QHBoxLayout(log_box)
        lb.setContentsMargins(0, 0, 0, 0)
        self.details = QLabel("Select an item to see the manual's description here.")
        self.details.setObjectName("parameterDetails")
        self.details.setWordWrap(True)
        self.details.setAlignment(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignTop)
        self.details.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.details.setStyleSheet("background: palette(base); padding: 4px;")
        self.details_scroll = QScrollArea()
        self.details_scroll.setObjectName("parameterDetailsScroll")
        self.details_scroll.setWidgetResizable(True)
        self.details_scroll.setWidget(self.details)
        lb.addWidget(self.details_scroll, 3)
        log_column = QVBoxLayout()
        log_column.addWidget(QLabel("Session log (every write, verified by read-back):"))
        self.log_view = QPlainTextEdit()
        self.log_view.setReadOnly(True)
        self.log_view.setObjectName("sessionLog")
        log_column.addWidget(self.log_view)
        lb.addLayout(log_column, 2)
        splitter.addWidget(log_box)
        splitter.setChildrenCollapsible(False)
        splitter.setStretchFactor(0, 3)
        splitter.setStretchFactor(1, 1)
        layout.addWidget(splitter, 1)
        self.message = QLabel("Read the drive's parameters to begin (Read all).")
        self.message.setObjectName("parameterMessage")
        self.message.setWordWrap(True)
        layout.addWidget(self.message)
        legend = QLabel(
            "<span style='background:#fff1b8'>&nbsp;yellow&nbsp;</span> edited, not written · "
            "<span style='color:#0d47a1'>blue</span> differs from the default · "
            "double-click or type on a value to edit · hover for the manual's description"
        )
        layout.addWidget(legend)

        self.table.selectionModel().currentRowChanged.connect(self._show_details)
        self.read_button.clicked.connect(self.read_all)
        self.write_changed_button.clicked.connect(self.write_changed)
        self.write_all_button.clicked.connect(self.write_all)
        self.revert_button.clicked.connect(self.model.revert)
        self.save_button.clicked.connect(lambda: self.save_file())
        self.load_button.clicked.connect(lambda: self.load_file())
        self.power_cycle_button.clicked.connect(self.power_cycle)
        self.model.sigRefused.connect(self._refused)
        self.model.sigEditsChanged.connect(self._edits_changed)
        session.state.sigWriteLogChanged.connect(self._log_changed)
        session.state.sigFrontPanelChanged.connect(self._update_buttons)
        session.sigWritesDone.connect(self._writes_done)
        session.sigParametersRead.connect(self._parameters_read)
        self.link.sigPowerCycled.connect(self._power_cycled)
        self.link.sigStatus.connect(self._on_status_for_buttons)
        self.link.sigBusyChanged.connect(lambda _b: self._update_buttons())
        self._update_buttons()

    # -- settings -----------------------------------------------------------------------------------
    def restore_settings(self, settings: QSettings) -> None:
        state = settings.value("parameters/splitter")
        if state is not None:
            self.splitter.restoreState(state)

    def save_settings(self, settings: QSettings) -> None:
        settings.setValue("parameters/splitter", self.splitter.saveState())

    # -- actions ------------------------------------------------------------------------------------
    def _servo_blocks(self, modes) -> bool:
        """Parameter-mode (system) items are written with the servo off only (the driver refuses
        them while it is on): say so before anything is sent, not after the drive refused."""
        return self.link.servo_on and any(str(m) == "system" for m in modes)

    def _update_buttons(self) -> None:
        info = self.link.info
        connected = self.link.connected and bool(info and info.can_parameters)
        self.read_button.setEnabled(connected)
        all_blocked = self._servo_blocks(["system"])
        changed_blocked = self._servo_blocks(m for m, _ in self.model.edits)
        self.write_all_button.setEnabled(connected and not all_blocked)
        self.write_changed_button.setEnabled(connected and bool(self.model.edits) and not changed_blocked)
        reason = SERVO_ON_WRITE_REASON if (all_blocked and connected) else ""
        for b in (self.write_all_button, self.write_changed_button):
            b.setToolTip(reason or b.property("plainToolTip") or "")
        self.servo_note.setText(reason if (changed_blocked and connected) else "")
        self.servo_note.setVisible(bool(changed_blocked and connected))
        self._servo_was_on = self.link.servo_on
        self.revert_button.setEnabled(bool(self.model.edits))
        self.save_button.setEnabled(bool(self.session.state.drive_values or self.session.state.front_panel))
        if self.model.panel_mode:
            reason = "This drive gives no parameter access over CN3: use its front panel"
            for b in (self.read_button, self.write_all_button, self.write_changed_button):
                b.setToolTip(reason)

    @Slot(str)
    def _who_changed(self, text: str) -> None:
        """The front-panel worksheet's entries are recorded with this name."""
        self.model.who = text

    @Slot()
    def read_all(self) -> None:
        self.message.setText("Reading …")
        self.session.read_all()

    @Slot()
    def write_changed(self) -> None:
        writes = [(m, n, v) for (m, n), v in self.model.edits.items()]
        self._write(writes)

    @Slot()
    def write_all(self) -> None:
        writes = []
        for row, item in enumerate(self.model.items):
            value = self.model.shown_value(row)
            if value is not None:
                writes.append((item.mode, item.number, value))
        if not writes:
            self.message.setText("Nothing to write: read the drive first.")
            return
        self._write(writes)

    def _write(self, writes) -> None:
        if not writes:
            return
        if self._servo_blocks(m for m, _, _ in writes):
            self.message.setText(f"Nothing written. {SERVO_ON_WRITE_REASON}")
            return
        self.message.setText(f"Writing {len(writes)} item(s) …")
        self.session.write(writes)

    @Slot(object)
    def _on_status_for_buttons(self, status) -> None:
        if status.servo_on is not None and status.servo_on != self._servo_was_on:
            self._update_buttons()

    @Slot(object)
    def _writes_done(self, entries: list) -> None:
        if not entries:
            return
        failed = [e for e in entries if not e.get("verified")]
        restart = []
        for e in entries:
            if not e.get("verified"):
                continue
            try:
                item = self.session.parameter_model.item(e["mode"], e["number"])
            except KeyError:
                continue
            if item.restart_required and e.get("old") != e.get("new"):
                restart.append(item)
                self.model.restart_pending.add((item.mode, item.number))
        ok = len(entries) - len(failed)
        text = f"{ok} of {len(entries)} written and verified by read-back."
        if failed:
            text += " Failed: " + "; ".join(f"{e['mode']} {e['number']}: {e.get('error')}" for e in failed)
        self.message.setText(text)
        self.message.setStyleSheet("color: #b00020;" if failed else "")
        if restart:
            self.show_restart_needed(restart)
        self.model._all_changed()

    def show_restart_needed(self, items) -> None:
        names = ", ".join(f"{i.name} ({MODE_WORDS.get(str(i.mode))} {i.number})" for i in items)
        sim = bool(self.link.info and self.link.info.is_simulated)
        how = (
            "Power cycle the simulated drive with the button."
            if sim
            else "Switch the driver's control power off, wait until the display is dark, "
            "and switch it on again."
        )
        self.restart_label.setText(f"<b>Takes effect after a power cycle:</b> {names}. {how}")
        self.power_cycle_button.setVisible(sim)
        self.restart_banner.setVisible(True)
        self._keep_current_row_in_view()

    def _keep_current_row_in_view(self) -> None:
        """The row being edited stays on screen when a banner takes room above the table (once the
        layout has given the table its new height)."""
        def scroll() -> None:
            current = self.table.currentIndex()
            if current.isValid():
                self.table.scrollTo(current)

        QTimer.singleShot(0, scroll)

    @Slot()
    def power_cycle(self) -> None:
        if self.link.servo_on:
            QMessageBox.information(self, "Servo is on", "Switch the servo off before the power cycle.")
            return
        self.link.send(PowerCycle(), self._power_cycle_answered)

    def _power_cycle_answered(self, result: LinkReply[None]) -> None:
        if not result.ok:
            self.message.setText(f"Power cycle failed: {result.error}")

    @Slot(object)
    def _parameters_read(self, result: LinkReply[ParameterReadout]) -> None:
        """A read of the session's (this page's, or after a power cycle, or before a backup)."""
        if result.ok:
            errors = result.answer.errors
            text = f"Read {len(result.answer.values)} item(s) from the drive."
            if errors:
                text += " Not read: " + "; ".join(f"{m} {k}: {e}" for (m, k), e in errors.items())
            self.message.setText(text)
            self.message.setStyleSheet("color: #b00020;" if errors else "")
        else:
            self.message.setText(f"Reading failed: {result.error}")
        self._update_buttons()

    @Slot()
    def _power_cycled(self) -> None:
        """Whoever asked for it: the restart-required items are in effect; read them back."""
        self.model.restart_pending.clear()
        self.restart_banner.setVisible(False)
        self.model._all_changed()  # the State column: nothing pending any more
        self.message.setText("Power cycled: the restart-required items are now in effect. Reading back …")
        self.session.read_all()

    def link_disconnected(self, reason: str, lost: bool) -> None:
        self._update_buttons()

    def link_connected(self, info: LinkInfo) -> None:
        self.model.reload_items()  # a model reset: the selection model stays the same object
        self.model.restart_pending.clear()
        self.restart_banner.setVisible(False)
        self._update_buttons()
        self.model.set_panel_mode(not info.can_parameters)
        self.panel_bar.setVisible(not info.can_parameters)
        if not info.can_parameters:
            self.message.setText(
                "This drive does not give parameter access over CN3 (it answers only the commands of "
                "its manual): read and set the parameters on its front panel, and enter them here."
            )
            self._update_buttons()
            return
        self.session.read_all()

    @Slot(QModelIndex, QModelIndex)
    def _show_details(self, current: QModelIndex, _previous: QModelIndex) -> None:
        if current.isValid():
            self.details.setText(self.model.data(current.siblingAtColumn(2), Qt.ItemDataRole.ToolTipRole))

    @Slot(str, QModelIndex)
    def _refused(self, why: str, index: QModelIndex) -> None:
        self.message.setText(why)
        self.message.setStyleSheet("color: #b00020; font-weight: bold;")
        rect = self.table.visualRect(index)
        QToolTip.showText(
            self.table.viewport().mapToGlobal(rect.bottomLeft() + QPoint(0, 2)), why, self.table
        )

    @Slot(int)
    def _item_of(self, record):
        try:
            return self.session.parameter_model.item(record.mode, record.number)
        except KeyError:
            return None

    def _edits_changed(self, n: int) -> None:
        if n:
            self.message.setText(f"{n} item(s) edited, not written yet.")
            self.message.setStyleSheet("")
        self._update_buttons()

    @Slot()
    def _log_changed(self) -> None:
        self.log_view.setPlainText("\n".join(r.line(self._item_of(r)) for r in self.session.state.writes))
        self.log_view.verticalScrollBar().setValue(self.log_view.verticalScrollBar().maximum())

    # -- files --------------------------------------------------------------------------------------
    def _default_dir(self) -> str:
        return str(QSettings().value("parameters/last_dir", str(Path.home())))

    def save_file(self, path: str | None = None) -> Path | None:
        if not (self.session.state.drive_values or self.session.state.front_panel):
            self.message.setText("Nothing to save: read the drive (or enter its panel's values) first.")
            return None
        if path is None:
            suggested = Path(self._default_dir()) / f"{self.session.state.actuator_code or 'parameters'}.toml"
            path, _ = QFileDialog.getSaveFileName(
                self, "Save parameter file", str(suggested), "Parameter files (*.toml);;All files (*)"
            )
            if not path:
                return None
        target = Path(path)
        try:
            fileio.write_text(target, self.session.parameter_file_text())
        except fileio.FileProblem as exc:
            self.message.setText(f"Not saved: {exc}")
            self.message.setStyleSheet("color: #b00020; font-weight: bold;")
            return None
        QSettings().setValue("parameters/last_dir", str(target.parent))
        panel = (" (values entered from the front panel are marked so)"
                 if self.session.state.front_panel else "")
        self.message.setText(f"Saved the drive's values to {target}{panel}")
        self.message.setStyleSheet("")
        return target

    def load_file(self, path: str | None = None, exec_dialog: bool = True):
        """Reads a parameter file and shows the three-way comparison; nothing is applied until the
        user confirms. Returns the dialog (tests drive it) or None when the file was refused."""
        from fha_studio.logic.paramfile import ParameterFileError, load_parameter_file

        if path is None:
            path, _ = QFileDialog.getOpenFileName(
                self, "Load parameter file", self._default_dir(), "Parameter files (*.toml);;All files (*)"
            )
            if not path:
                return None
        source = Path(path)
        try:
            loaded = load_parameter_file(source, self.session.parameter_model)
        except ParameterFileError as exc:
            self.message.setText(f"File refused, nothing loaded: {exc}")
            self.message.setStyleSheet("color: #b00020; font-weight: bold;")
            if exec_dialog:
                QMessageBox.warning(self, "Parameter file refused", f"Nothing was loaded.\n\n{exc}")
            return None
        QSettings().setValue("parameters/last_dir", str(source.parent))
        dialog = ParameterDiffDialog(self.session, loaded, source.name, self)
        dialog.accepted.connect(lambda: self.apply_choices(dialog.chosen_values()))
        if exec_dialog:
            dialog.open()
        return dialog

    def apply_choices(self, values: dict) -> None:
        """Puts the chosen values as edits and writes the ones that differ from the drive. On a
        drive without parameter access nothing can be written: it lists what to set on the panel."""
        if self.model.panel_mode:
            todo = []
            for (mode, number), wire in sorted(values.items()):
                if self.session.state.value_of(mode, number) != wire:
                    item = self.session.parameter_model.item(mode, number)
                    where = f"{MODE_WORDS.get(str(mode), mode)} {number} ({item.name})"
                    todo.append(f"{where} = {value_text(item, wire)}")
            self.message.setText(
                ("Set on the drive's front panel, then enter here: " + "; ".join(todo)) if todo
                else "The panel's values (as entered) already match the chosen values."
            )
            return
        for (mode, number), wire in values.items():
            self.model.set_edit(mode, number, wire)
        if self.link.connected and self.model.edits:
            self.write_changed()
        elif self.model.edits:
            self.message.setText(
                f"{len(self.model.edits)} item(s) taken from the file; connect and write them."
            )
        else:
            self.message.setText("The drive already holds the chosen values: nothing to write.")
