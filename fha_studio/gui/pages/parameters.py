"""The parameter editor: one table of the tune and parameter (system) items of the driver (the
table's model and its value editor: ``parameter_table.py``), read, written, saved and loaded."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QModelIndex, QPoint, QSettings, Qt, QTimer, Slot
from PySide6.QtWidgets import (
    QAbstractItemView,
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
    QTableView,
    QToolTip,
    QVBoxLayout,
    QWidget,
)

from fha_studio import fileio
from fha_studio.gui.diff_dialog import ParameterDiffDialog
from fha_studio.gui.link import LinkInfo, LinkReply, ParameterReadout, PowerCycle
from fha_studio.gui.pages.base import BasePage
from fha_studio.gui.pages.parameter_table import COL_VALUE, ParameterTableModel, ValueDelegate
from fha_studio.gui.pages.parameter_table import COLUMNS as COLUMNS  # the table's columns, by name
from fha_studio.gui.parameter_text import MODE_WORDS, value_text
from fha_studio.gui.session import Session

#: The session log before its first write (on a drive of the manual's commands nothing is ever
#: written over CN3: the values entered from its panel are in the table).
LOG_EMPTY = ("Nothing written yet. Each write comes here with its read-back. On a drive without "
             "parameter access over CN3 nothing is written: the values entered from its front panel "
             "are in the table, with who entered them and when.")
#: Why the write buttons are off while the servo is on (the driver's rule for parameter mode).
SERVO_ON_WRITE_REASON = (
    "The servo is on: parameter-mode items can be written only with the servo off. "
    "Switch the servo off (toolbar or controller) to write them."
)


def items(n: int) -> str:
    """``"1 item"``, ``"3 items"``: a count as a sentence says it."""
    return f"{n} item" if n == 1 else f"{n} items"


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
        # who enters the panel's values: beside the buttons (a field beside the wrapped note
        # read as part of its sentence on a small screen)
        self.who_box = QWidget()
        wb = QHBoxLayout(self.who_box)
        wb.setContentsMargins(0, 0, 0, 0)
        buttons.addWidget(self.who_box)
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
            "the drive's panel</b>: it is recorded with who (<i>Entered by</i>) and when, compared with "
            "the default and a parameter file, saved to files marked as entered from the panel, and goes "
            "into the report."
        )
        self.panel_note.setWordWrap(True)
        self.who_edit = QLineEdit()
        self.who_edit.setObjectName("panelWho")
        self.who_edit.setPlaceholderText("your name")
        self.who_edit.textChanged.connect(self._who_changed)
        pb.addWidget(self.panel_note, 1)
        who_label = QLabel("Entered by:")
        wb.addWidget(who_label)
        wb.addWidget(self.who_edit)
        self.who_box.setVisible(False)
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
        # the name and the value are what matter: both are shown whole; the default takes the room
        # that is left (a long choice such as "0: FWD turns CW (seen from the flange)" is elided
        # there, and the row's tooltip lists every choice)
        header.setSectionResizeMode(6, QHeaderView.ResizeMode.Stretch)
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
        self.log_view.setPlaceholderText(LOG_EMPTY)
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
        self.message.setText(f"Writing {items(len(writes))} …")
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
            text = f"Read {items(len(result.answer.values))} from the drive."
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
        self.who_box.setVisible(not info.can_parameters)
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
            self.message.setText(f"{items(n)} edited, not written yet.")
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
                f"{items(len(self.model.edits))} taken from the file; connect and write them."
            )
        else:
            self.message.setText("The drive already holds the chosen values: nothing to write.")
