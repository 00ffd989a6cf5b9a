"""Alarms: the current alarm with the manual's cause and remedy, the history, clear, acknowledge."""

from __future__ import annotations

import time

from PySide6.QtCore import Qt, Signal, Slot
from PySide6.QtGui import QColor, QFont
from PySide6.QtWidgets import (
    QCheckBox,
    QGroupBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
)

from fha_studio import clock
from fha_studio.gui.link import ClearAlarm, DriveStatus, LinkInfo, LinkReply, PowerCycle, ReadAlarmHistory
from fha_studio.gui.pages.base import BasePage
from fha_studio.gui.session import Session
from fha_studio.hardware.api import AlarmRecord

_TABLES: dict[str, object] = {}


def _alarm_table(driver: str):
    from fha_studio.hardware.parameters import load_alarm_table

    if driver not in _TABLES:
        _TABLES[driver] = load_alarm_table(driver)
    return _TABLES[driver]


def alarm_text(code: int, driver: str = "HA-655") -> dict:
    """name, cause, remedy, clearable and source of an alarm code, from the driver's alarm table."""
    alarm = _alarm_table(driver).get(code)
    if alarm is None:
        return {
            "name": "unknown code",
            "cause": "The driver's alarm table has no such code.",
            "remedy": "",
            "clearable": False,
            "source": "",
            "certain": False,
        }
    return {
        "name": alarm.name,
        "cause": alarm.cause,
        "remedy": alarm.remedy,
        "clearable": alarm.clearable,
        "source": alarm.source,
        "certain": alarm.certain,
    }


class AlarmsPage(BasePage):
    """Alarm state, always current while connected."""

    sigAlarmAttention = Signal(int, bool)  # code, True while a new alarm waits for acknowledgement

    def __init__(self, session: Session, main_window=None):
        super().__init__()
        self.session = session
        self.link = session.link
        self.current_code: int | None = None
        self.reports_alarms = True
        self.unacknowledged: int | None = None
        self._appeared_at: dict[int, float] = {}
        self._seen_at: dict[tuple[int, int], float | None] = {}
        layout = QVBoxLayout(self)

        current_box = QGroupBox("Current alarm")
        c_layout = QVBoxLayout(current_box)
        self.code_label = QLabel("—")
        self.code_label.setObjectName("alarmCode")
        font = QFont(self.code_label.font())
        font.setPointSizeF(font.pointSizeF() * 1.8)
        font.setBold(True)
        self.code_label.setFont(font)
        c_layout.addWidget(self.code_label)
        self.cause_label = QLabel("")
        self.cause_label.setWordWrap(True)
        self.cause_label.setTextFormat(Qt.TextFormat.RichText)
        self.cause_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        c_layout.addWidget(self.cause_label)
        row = QHBoxLayout()
        self.ack_button = QPushButton("Ac&knowledge")
        self.ack_button.setToolTip(
            "I have seen this alarm (the highlight goes; the alarm itself stays until cleared)"
        )
        self.clear_button = QPushButton("&Clear alarm")
        self.clear_button.setToolTip(
            "Alarms 20 (overload) and 60 (error counter overflow) clear without a power cycle"
        )
        self.power_cycle_button = QPushButton("&Power cycle (simulated drive)")
        self.power_cycle_button.setToolTip(
            "The other alarms need the driver's control power switched off and on"
        )
        for w in (self.ack_button, self.clear_button, self.power_cycle_button):
            row.addWidget(w)
        row.addStretch(1)
        c_layout.addLayout(row)
        self.result_label = QLabel("")
        self.result_label.setWordWrap(True)
        c_layout.addWidget(self.result_label)
        layout.addWidget(current_box)

        # a drive that does not report alarms over CN3 (a real HA-655): the technician reads the
        # front panel's 2-digit code (and the ALM-A..D outputs, if at hand) and types them here
        self.panel_box = QGroupBox("Alarm on the drive's front panel")
        self.panel_box.setObjectName("alarmPanelEntry")
        p_layout = QVBoxLayout(self.panel_box)
        hint = QLabel(
            "This drive does not report alarms over CN3. Read the 2-digit code on its front panel "
            "(and the ALM-A..D outputs on CN2 if you can see them) and enter them: FHA Studio shows the "
            "manual's cause and remedy and keeps the entry in the history."
        )
        hint.setWordWrap(True)
        p_layout.addWidget(hint)
        row = QHBoxLayout()
        row.addWidget(QLabel("Code on the panel:"))
        self.panel_code_edit = QLineEdit()
        self.panel_code_edit.setObjectName("panelAlarmCode")
        self.panel_code_edit.setMaxLength(2)
        self.panel_code_edit.setPlaceholderText("e.g. 60")
        self.panel_code_edit.setMaximumWidth(70)
        row.addWidget(self.panel_code_edit)
        row.addWidget(QLabel("  ALM lamps on:"))
        self.alm_checks: dict[str, QCheckBox] = {}
        for name in ("D", "C", "B", "A"):
            check = QCheckBox(f"ALM-{name}")
            check.setTristate(False)
            self.alm_checks[name] = check
            row.addWidget(check)
        self.alm_read_check = QCheckBox("lamps read")
        self.alm_read_check.setToolTip("Tick when you read the ALM outputs; unticked they are not compared")
        row.addWidget(self.alm_read_check)
        self.panel_button = QPushButton("Look &up and record")
        self.panel_button.clicked.connect(self.enter_from_panel)
        row.addWidget(self.panel_button)
        row.addStretch(1)
        p_layout.addLayout(row)
        self.panel_result = QLabel("")
        self.panel_result.setObjectName("panelAlarmResult")
        self.panel_result.setWordWrap(True)
        p_layout.addWidget(self.panel_result)
        self.panel_box.setVisible(False)
        layout.addWidget(self.panel_box)
        self.panel_entries: list[dict] = []  # code, alm bits or None, when, who

        history_box = QGroupBox("Alarm history (newest first)")
        h_layout = QVBoxLayout(history_box)
        self.history_table = QTableWidget(0, 4)
        self.history_table.setHorizontalHeaderLabels(
            ["Code", "Name", "After power-on", "Seen by FHA Studio at"]
        )
        self.history_table.horizontalHeader().setSectionResizeMode(1, QHeaderView.ResizeMode.Stretch)
        self.history_table.verticalHeader().setVisible(False)
        self.history_table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.history_table.setSelectionBehavior(QTableWidget.SelectionBehavior.SelectRows)
        h_layout.addWidget(self.history_table)
        self.refresh_button = QPushButton("&Read history")
        hr = QHBoxLayout()
        hr.addWidget(self.refresh_button)
        hr.addStretch(1)
        h_layout.addLayout(hr)
        layout.addWidget(history_box, 1)

        self.ack_button.clicked.connect(self.acknowledge)
        self.clear_button.clicked.connect(lambda: self.link.send(ClearAlarm(), self._cleared))
        self.power_cycle_button.clicked.connect(lambda: self.link.send(PowerCycle(), self._power_cycled))
        self.refresh_button.clicked.connect(self._read_history)
        self.link.sigStatus.connect(self._on_status)
        self.link.sigPowerCycled.connect(lambda: self.result_label.setText("Power cycled."))
        self._show(None)

    # -- from the link ----------------------------------------------------------------------------
    def link_connected(self, info: LinkInfo) -> None:
        self._seen_at.clear()
        self.power_cycle_button.setVisible(info.is_simulated)
        self.reports_alarms = not info.documented_only
        self.panel_box.setVisible(not self.reports_alarms)
        reason = ("" if self.reports_alarms
                  else "This drive does not report alarms over CN3: use its front panel")
        for button in (self.refresh_button, self.clear_button):
            button.setToolTip(reason or button.toolTip())
        self.refresh_button.setEnabled(self.reports_alarms)
        if self.reports_alarms:
            self._read_history()
        self._show(self.current_code)

    def link_disconnected(self, reason: str, lost: bool) -> None:
        self.current_code = None
        self.reports_alarms = True
        self.panel_box.setVisible(bool(self.panel_entries))
        self._show(None)

    @Slot()
    def enter_from_panel(self) -> bool:
        """Look up the code typed from the front panel, compare the ALM lamps, keep it in the
        history. False (with the reason beside the button) for a code that is not a number."""
        text = self.panel_code_edit.text().strip()
        if not text.isdigit():
            self.panel_result.setText("Enter the 2-digit code the panel shows (e.g. 60).")
            return False
        code = int(text)
        bits = None
        if self.alm_read_check.isChecked():
            bits = sum(1 << i for i, name in enumerate("ABCD") if self.alm_checks[name].isChecked())
        table = _alarm_table(self.session.driver)
        alarm = table.get(code)
        lines = []
        if alarm is None:
            lines.append(f"{code} is not an alarm code of the {self.session.driver}'s manual: read the "
                         "display again (a dot or a monitor item can look like a code).")
        elif bits is not None and bits != alarm.alm_bits:
            same = [a.code for a in table if a.alm_bits == bits]
            lines.append(f"The lamps (D C B A = {bits:04b}) do not match alarm {code} ({alarm.alm_code}); "
                         f"they belong to {', '.join(map(str, same)) or 'no alarm of the table'}. "
                         "Read both again.")
        entry = {"code": code, "alm_bits": bits, "time": clock.now_s()}
        self.panel_entries.insert(0, entry)
        self.current_code = code
        self._show(code)
        self.panel_result.setText(" ".join(lines) or f"Alarm {code} recorded (entered from the panel).")
        self._fill_panel_history()
        return True

    def _fill_panel_history(self) -> None:
        self.history_table.setRowCount(len(self.panel_entries))
        for row, entry in enumerate(self.panel_entries):
            code = entry["code"]
            lamps = "" if entry["alm_bits"] is None else f", lamps D C B A = {entry['alm_bits']:04b}"
            name = alarm_text(code, self.session.driver)["name"]
            cells = [str(code), name + lamps, "entered from the panel",
                     time.strftime("%H:%M:%S", time.localtime(entry["time"]))]
            for col, text in enumerate(cells):
                self.history_table.setItem(row, col, QTableWidgetItem(text))
        for col in (0, 2, 3):
            self.history_table.resizeColumnToContents(col)

    @Slot(object)
    def _on_status(self, status: DriveStatus) -> None:
        code = status.alarm_code
        if code is None or code == self.current_code:
            return
        previous, self.current_code = self.current_code, code
        if code:
            self._appeared_at[code] = clock.now_s() if previous is not None else 0.0
            self.unacknowledged = code
            self.sigAlarmAttention.emit(code, True)
            self._read_history()
        self._show(code)

    @Slot()
    def _read_history(self) -> None:
        self.link.send(ReadAlarmHistory(), self._history_read)

    def _history_read(self, result: LinkReply[list[AlarmRecord]]) -> None:
        if result.ok:
            self._fill_history(result.answer)

    def _cleared(self, result: LinkReply[int]) -> None:
        if result.ok:
            left = result.value
            self.result_label.setText("Alarm cleared." if not left else f"Alarm {left} is still active.")
        else:
            self.result_label.setText(
                f"The drive did not clear the alarm ({result.error}). Only alarms 20 and 60 clear "
                "without a power cycle: remove the cause, then switch the driver's control power "
                "off and on."
            )

    def _power_cycled(self, result: LinkReply[None]) -> None:
        if not result.ok:  # done: sigPowerCycled says so, whoever asked
            self.result_label.setText(f"Power cycle failed: {result.error}")

    # -- showing ----------------------------------------------------------------------------------
    def _show(self, code: int | None) -> None:
        attention = self.unacknowledged is not None and self.unacknowledged == code and bool(code)
        self.ack_button.setEnabled(attention)
        self.clear_button.setEnabled(bool(code) and self.reports_alarms)
        if code is None:
            connected = self.link.connected
            self.code_label.setText("—  (read the code on the drive's front panel)" if connected
                                    and not self.reports_alarms else "—  (not connected)")
            self.code_label.setStyleSheet("")
            self.cause_label.setText("")
            return
        if code == 0:
            self.code_label.setText("No alarm")
            self.code_label.setStyleSheet("color: #2e7d32;")
            self.cause_label.setText("")
            if self.unacknowledged is not None:
                self.unacknowledged = None
                self.sigAlarmAttention.emit(0, False)
            return
        text = alarm_text(code, self.session.driver)
        self.code_label.setText(f"Alarm {code}: {text['name']}")
        style = (
            "background: #b00020; color: white; padding: 6px;"
            if attention
            else "color: #b00020; padding: 6px;"
        )
        self.code_label.setStyleSheet(style)
        parts = []
        if text["cause"]:
            parts.append(f"<b>Cause:</b> {text['cause']}")
        if text["remedy"]:
            parts.append(f"<b>Remedy:</b> {text['remedy']}")
        parts.append(
            "<b>Clear:</b> "
            + (
                ("with <i>Clear alarm</i> once the cause is gone." if self.reports_alarms else
                 "once the cause is gone, with the driver's alarm-clear input (CN2) or a power cycle.")
                if text["clearable"]
                else "needs the driver's control power switched off and on."
            )
        )
        if text["source"]:
            uncertain = (
                ""
                if text["certain"]
                else " (cause and remedy are this project's reading; the public manual is silent)"
            )
            parts.append(f"<i>Source: {text['source']}{uncertain}</i>")
        self.cause_label.setText("<br>".join(parts))
        self.result_label.setText("")

    @Slot()
    def acknowledge(self) -> None:
        code = self.unacknowledged
        self.unacknowledged = None
        self.sigAlarmAttention.emit(code or 0, False)
        self._show(self.current_code)

    def _fill_history(self, history: list[AlarmRecord]) -> None:
        self.history_table.setRowCount(len(history))
        for row, entry in enumerate(history):
            code, seconds = entry.code, entry.seconds_since_power_on
            key = (code, seconds)
            if key not in self._seen_at:
                # the drive keeps time since its power-on only; the PC's clock is known for alarms
                # FHA Studio saw appear, and only for the newest entry of that code
                pending = self._appeared_at.pop(code, None)
                self._seen_at[key] = pending if row == 0 and pending else None
            wall = self._seen_at[key]
            when = time.strftime("%H:%M:%S", time.localtime(wall)) if wall else "before this session"
            cells = [str(code), alarm_text(code, self.session.driver)["name"], _duration(seconds), when]
            for col, text in enumerate(cells):
                item = QTableWidgetItem(text)
                if row == 0 and code == self.current_code:
                    item.setForeground(QColor("#b00020"))
                self.history_table.setItem(row, col, item)
        self.history_table.resizeColumnToContents(0)
        self.history_table.resizeColumnToContents(2)
        self.history_table.resizeColumnToContents(3)


def _duration(seconds: int) -> str:
    h, rest = divmod(seconds, 3600)
    m, s = divmod(rest, 60)
    return f"{h} h {m:02d} min {s:02d} s" if h else f"{m} min {s:02d} s"
