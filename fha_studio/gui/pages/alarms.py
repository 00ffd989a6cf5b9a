"""Alarms: the current alarm with the manual's cause and remedy, the history, clear, acknowledge."""

from __future__ import annotations

import time

from PySide6.QtCore import Qt, Signal, Slot
from PySide6.QtGui import QColor, QFont
from PySide6.QtWidgets import (
    QGroupBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
)

from fha_studio.gui.link import Cmd, CommandResult, DriveStatus, LinkInfo
from fha_studio.gui.pages.base import BasePage
from fha_studio.gui.session import Session
from fha_studio.hardware.api import AlarmRecord

_TABLES: dict[str, object] = {}


def alarm_text(code: int, driver: str = "HA-655") -> dict:
    """name, cause, remedy, clearable and source of an alarm code, from the driver's alarm table."""
    from fha_studio.hardware.parameters import load_alarm_table

    if driver not in _TABLES:
        _TABLES[driver] = load_alarm_table(driver)
    alarm = _TABLES[driver].get(code)
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
        self.clear_button.clicked.connect(lambda: self.link.send(Cmd.CLEAR_ALARM))
        self.power_cycle_button.clicked.connect(lambda: self.link.send(Cmd.POWER_CYCLE))
        self.refresh_button.clicked.connect(lambda: self.link.send(Cmd.ALARM_HISTORY))
        self.link.sigStatus.connect(self._on_status)
        self.link.sigResult.connect(self._on_result)
        self._show(None)

    # -- from the link ----------------------------------------------------------------------------
    def link_connected(self, info: LinkInfo) -> None:
        self._seen_at.clear()
        self.power_cycle_button.setVisible(info.is_simulated)
        self.link.send(Cmd.ALARM_HISTORY)

    def link_disconnected(self, reason: str, lost: bool) -> None:
        self.current_code = None
        self._show(None)

    @Slot(object)
    def _on_status(self, status: DriveStatus) -> None:
        code = status.alarm_code
        if code is None or code == self.current_code:
            return
        previous, self.current_code = self.current_code, code
        if code:
            self._appeared_at[code] = time.time() if previous is not None else 0.0
            self.unacknowledged = code
            self.sigAlarmAttention.emit(code, True)
            self.link.send(Cmd.ALARM_HISTORY)
        self._show(code)

    @Slot(object)
    def _on_result(self, result: CommandResult) -> None:
        if result.cmd is Cmd.ALARM_HISTORY and result.ok:
            self._fill_history(result.value)
        elif result.cmd is Cmd.CLEAR_ALARM:
            if result.ok:
                left = result.value
                self.result_label.setText("Alarm cleared." if not left else f"Alarm {left} is still active.")
            else:
                self.result_label.setText(
                    f"The drive did not clear the alarm ({result.error}). Only alarms 20 and 60 clear "
                    "without a power cycle: remove the cause, then switch the driver's control power "
                    "off and on."
                )
        elif result.cmd is Cmd.POWER_CYCLE:
            self.result_label.setText("Power cycled." if result.ok else f"Power cycle failed: {result.error}")

    # -- showing ----------------------------------------------------------------------------------
    def _show(self, code: int | None) -> None:
        attention = self.unacknowledged is not None and self.unacknowledged == code and bool(code)
        self.ack_button.setEnabled(attention)
        self.clear_button.setEnabled(bool(code))
        if code is None:
            self.code_label.setText("—  (not connected)")
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
                "with <i>Clear alarm</i> once the cause is gone."
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
