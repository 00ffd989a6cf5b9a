"""The DGR checks page: what a drive of the manual's commands can check with its absolute position.

A real HA-655 answers over CN3 only ``DGR`` (the absolute position: servo off, absolute encoder)
and ``OWW`` (clear the multi-turn data). With them, and the technician's hands and the
controller, four checks are possible; each is recorded with who and when:

- encoder check: turn the output by hand by a stated angle; the counts change by ratio x 8192
  per motor turn, in the same sense;
- rotary direction (FHA-C manual 1-10): read, let the controller give a short FWD command with
  the servo on, read again: the sign says CW or CCW, compared with parameter 8 as entered;
- sensor dogs (4-7-2): turn by hand to where each sensor switches; DGR gives the angle, checked
  against the movable range of 4-7-3;
- absolute origin: OWW with the manual's conditions (servo off, absolute encoder, ``q`` about
  5 s later), the position read back and recorded.

A drive that answers ``x`` to DGR has an incremental encoder: the checks then ask the technician
for what they saw and record it as given by hand, saying why.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from functools import partial
from typing import Any

from PySide6.QtCore import Qt, Signal, Slot
from PySide6.QtWidgets import (
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QPushButton,
    QSplitter,
    QTableWidget,
    QTableWidgetItem,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from fha_studio.gui.link import SERVO_ON_NOTE, Call, DriveStatus, LinkInfo, LinkReply
from fha_studio.gui.pages.base import BasePage
from fha_studio.gui.session import data_dir
from fha_studio.gui.widgets import scrolling
from fha_studio.hardware.api import CommandNotSupported, CommandRejected, ServoOnRefused
from fha_studio.hardware.protocol import ABSOLUTE_COUNTS_PER_TURN, Command
from fha_studio.logic import absolute as ab
from fha_studio.logic.procedures.sensor_dogs import SENSOR_NAMES, SENSORS, angle_problem

INCREMENTAL_NOTE = (
    "This drive answers x to DGR: an incremental encoder gives no absolute position over CN3. "
    "Do the checks by eye (or with the panel's monitor items) and enter what you saw: it is "
    "recorded as given by hand."
)


def _read_position(api) -> int:
    return api.absolute_position()


def _set_origin(ratio: int | None, api) -> ab.OriginResult:
    return ab.set_absolute_origin(api, ratio)


def _wrap(label: QLabel) -> QLabel:
    label.setWordWrap(True)
    label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
    return label


class AbsolutePage(BasePage):
    """Checks with DGR and OWW, for a drive that answers only its manual's commands."""

    sigRecorded = Signal(object)  # DgrCheckRecord

    def __init__(self, gui_session, main_window=None):
        super().__init__()
        self.setObjectName("absolutePage")
        self.gui_session = gui_session
        self.link = gui_session.link
        self.records: list[ab.DgrCheckRecord] = []
        self.servo_on: bool | None = None
        self.encoder: str = "unknown"  # "absolute" | "incremental" | "unknown"
        self.last_counts: int | None = None
        self._encoder_start: int | None = None
        self._direction_start: int | None = None
        self._origin_token: int | None = None  # an OWW on its way
        self.dog_angles: dict[str, float] = {}
        self._build()
        self.link.sigStatus.connect(self._on_status)
        gui_session.state.sigActuatorChanged.connect(lambda _code: self._refresh())
        gui_session.state.sigFrontPanelChanged.connect(self._panel_value_changed)
        gui_session.state.sigParametersChanged.connect(self._panel_value_changed)
        self._refresh()

    # -- building ------------------------------------------------------------------------------
    def _build(self) -> None:
        outer = QVBoxLayout(self)
        self.summary_label = _wrap(QLabel(""))
        self.summary_label.setObjectName("absoluteSummary")
        outer.addWidget(self.summary_label)
        top = QHBoxLayout()
        self.position_label = QLabel("Position (DGR, servo off): not read yet")
        self.position_label.setObjectName("dgrPosition")
        self.read_button = QPushButton("Read the &position (DGR)")
        self.read_button.clicked.connect(lambda: self._read(self._show_position))
        self.who_edit = QLineEdit()
        self.who_edit.setPlaceholderText("your name (goes into every record)")
        # the hint whole: a field cut to "your name (goes …" no longer says why it is asked
        self.who_edit.setMinimumWidth(
            self.who_edit.fontMetrics().horizontalAdvance(self.who_edit.placeholderText()) + 16)
        top.addWidget(self.position_label, 1)
        top.addWidget(self.read_button)
        top.addWidget(QLabel("Technician:"))
        top.addWidget(self.who_edit)
        outer.addLayout(top)
        self.reason_label = _wrap(QLabel(""))
        self.reason_label.setObjectName("absoluteReason")
        self.reason_label.setStyleSheet("color: #8a5a00;")
        outer.addWidget(self.reason_label)

        split = QSplitter(Qt.Orientation.Vertical)
        self.tabs = QTabWidget()
        self.tabs.setObjectName("dgrChecks")
        # each check scrolls where the records below leave it too little height (1024 x 600):
        # its wrapped steps are never squeezed under its buttons
        self.tabs.addTab(scrolling(self._build_encoder(), 0), "Encoder check")
        self.tabs.addTab(scrolling(self._build_direction(), 0), "Rotary direction (1-10)")
        self.tabs.addTab(scrolling(self._build_dogs(), 0), "Sensor dogs (4-7-2)")
        self.tabs.addTab(scrolling(self._build_origin(), 0), "Absolute origin (OWW)")
        split.addWidget(self.tabs)
        self.history = QTableWidget(0, 5)
        self.history.setObjectName("dgrHistory")
        self.history.setHorizontalHeaderLabels(["Check", "Result", "What was seen", "Who", "When"])
        header = self.history.horizontalHeader()
        for column in (0, 1, 3, 4):
            header.setSectionResizeMode(column, QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(2, QHeaderView.ResizeMode.Stretch)
        self.history.setWordWrap(True)
        self.history.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        split.addWidget(self.history)
        split.setSizes([420, 200])
        outer.addWidget(split, 1)

    def _build_encoder(self) -> QWidget:
        w = QWidget()
        v = QVBoxLayout(w)
        v.addWidget(_wrap(QLabel(
            "With the servo off (and the brake released), turn the output flange by hand by the angle "
            "below, CW seen from the flange for a positive angle. The absolute position must change by "
            f"ratio x {ABSOLUTE_COUNTS_PER_TURN} counts per motor turn, in the same sense.")))
        form = QFormLayout()
        self.encoder_angle = QDoubleSpinBox()
        self.encoder_angle.setRange(-360.0, 360.0)
        self.encoder_angle.setDecimals(1)
        self.encoder_angle.setSuffix(" °")
        self.encoder_angle.setValue(10.0)
        form.addRow("Turn by hand by:", self.encoder_angle)
        v.addLayout(form)
        row = QHBoxLayout()
        self.encoder_start_button = QPushButton("1. Read the start position")
        self.encoder_start_button.clicked.connect(lambda: self._read(self._encoder_started))
        self.encoder_end_button = QPushButton("2. Read after turning")
        self.encoder_end_button.clicked.connect(lambda: self._read(self._encoder_done))
        row.addWidget(self.encoder_start_button)
        row.addWidget(self.encoder_end_button)
        row.addStretch(1)
        v.addLayout(row)
        self.encoder_hand = QGroupBox("By hand (the drive cannot tell)")
        h = QHBoxLayout(self.encoder_hand)
        self.encoder_seen = QComboBox()
        self.encoder_seen.addItems(["the output turned as expected", "it turned the wrong way",
                                    "it did not turn or the panel showed nothing"])
        self.encoder_hand_button = QPushButton("Record what I saw")
        self.encoder_hand_button.clicked.connect(self._encoder_by_hand)
        h.addWidget(self.encoder_seen, 1)
        h.addWidget(self.encoder_hand_button)
        v.addWidget(self.encoder_hand)
        self.encoder_result = _wrap(QLabel(""))
        self.encoder_result.setObjectName("encoderResult")
        v.addWidget(self.encoder_result)
        v.addStretch(1)
        return w

    def _build_direction(self) -> QWidget:
        w = QWidget()
        v = QVBoxLayout(w)
        v.addWidget(_wrap(QLabel(
            "FHA-C manual 1-10: a FWD command turns the output clockwise seen from the flange when "
            "[parameter mode] → [8: rotary direction] is 0 (the default), counter-clockwise when it is 1. "
            "This drive takes servo-ON and the FWD command from the controller (CN2), so:")))
        form = QFormLayout()
        self.direction_param = QComboBox()
        self.direction_param.addItems(["not entered", "0: FWD command turns CW (default)",
                                       "1: FWD command turns CCW"])
        self.direction_param.setToolTip("What the drive's panel shows in parameter mode, item 8")
        form.addRow("Parameter 8 on the drive's panel:", self.direction_param)
        v.addLayout(form)
        steps = QVBoxLayout()
        self.direction_start_button = QPushButton("1. Read the position (servo off)")
        self.direction_start_button.clicked.connect(lambda: self._read(self._direction_started))
        steps.addWidget(self.direction_start_button)
        self.direction_step2 = _wrap(QLabel(
            "2. At the controller: switch the servo ON, give a short FWD command (a few degrees), "
            "switch the servo OFF. FHA Studio sends nothing meanwhile but its probe, which the drive "
            "answers with s."))
        steps.addWidget(self.direction_step2)
        self.direction_end_button = QPushButton("3. Read the position again (servo off)")
        self.direction_end_button.clicked.connect(lambda: self._read(self._direction_done))
        steps.addWidget(self.direction_end_button)
        v.addLayout(steps)
        self.direction_hand = QGroupBox("By hand (the drive cannot tell)")
        h = QHBoxLayout(self.direction_hand)
        self.direction_seen = QComboBox()
        self.direction_seen.addItems(["CW", "CCW", "did not turn"])
        self.direction_hand_button = QPushButton("Record: the FWD command turned the output …")
        self.direction_hand_button.clicked.connect(self._direction_by_hand)
        h.addWidget(self.direction_hand_button)
        h.addWidget(self.direction_seen)
        v.addWidget(self.direction_hand)
        self.direction_result = _wrap(QLabel(""))
        self.direction_result.setObjectName("directionResult")
        v.addWidget(self.direction_result)
        v.addStretch(1)
        return w

    def _build_dogs(self) -> QWidget:
        w = QWidget()
        v = QVBoxLayout(w)
        v.addWidget(_wrap(QLabel(
            "FHA-C manual 4-7-2, with the servo off: loosen the dog, turn the axis by hand to where the "
            "sensor switches (watch the sensor's indicator or the controller's input: this drive does "
            "not report its inputs over CN3), then record the angle. Angles come from the absolute "
            "position (0° = turn 0, single-turn count 0: set the absolute origin with the axis at the "
            "actuator's origin first) and are checked against the movable range of 4-7-3.")))
        row = QHBoxLayout()
        self.dog_sensor = QComboBox()
        for sensor in SENSORS:
            self.dog_sensor.addItem(SENSOR_NAMES[sensor], sensor)
        self.dog_record_button = QPushButton("Record the angle here (DGR)")
        self.dog_record_button.clicked.connect(lambda: self._read(self._dog_read))
        row.addWidget(QLabel("Sensor:"))
        row.addWidget(self.dog_sensor, 1)
        row.addWidget(self.dog_record_button)
        v.addLayout(row)
        self.dog_hand = QGroupBox("By hand (the drive cannot tell)")
        h = QHBoxLayout(self.dog_hand)
        self.dog_angle = QDoubleSpinBox()
        self.dog_angle.setRange(-360.0, 360.0)
        self.dog_angle.setDecimals(2)
        self.dog_angle.setSuffix(" °")
        self.dog_hand_button = QPushButton("Record this angle (read on the scale)")
        self.dog_hand_button.clicked.connect(lambda: self._record_dog(self.dog_angle.value(), by_hand=True))
        h.addWidget(self.dog_angle)
        h.addWidget(self.dog_hand_button)
        v.addWidget(self.dog_hand)
        self.dog_result = _wrap(QLabel(""))
        self.dog_result.setObjectName("dogResult")
        v.addWidget(self.dog_result)
        v.addStretch(1)
        return w

    def _build_origin(self) -> QWidget:
        w = QWidget()
        v = QVBoxLayout(w)
        v.addWidget(_wrap(QLabel(
            "Set the absolute origin: clear the multi-turn data (OWW, HA-655 manual p.21). The drive "
            "accepts it only with the servo off and an absolute encoder, and acknowledges about 5 s "
            "later. Put the axis where turn 0 shall be first.")))
        self.origin_conditions = _wrap(QLabel(""))
        self.origin_conditions.setObjectName("originConditions")
        v.addWidget(self.origin_conditions)
        self.origin_button = QPushButton("Clear the multi-turn data (OWW) and read back")
        self.origin_button.setObjectName("originButton")
        self.origin_button.clicked.connect(self._origin_clicked)
        v.addWidget(self.origin_button)
        self.origin_result = _wrap(QLabel(""))
        self.origin_result.setObjectName("originResult")
        v.addWidget(self.origin_result)
        v.addStretch(1)
        return w

    # -- state ---------------------------------------------------------------------------------
    @property
    def who(self) -> str:
        return self.who_edit.text().strip()

    @property
    def ratio(self) -> int | None:
        info = self.link.info
        return self.gui_session.state.ratio or ab.ratio_of(info.adjusted_for if info else None)

    def link_connected(self, info: LinkInfo) -> None:
        self.encoder = {True: "absolute", False: "incremental", None: "unknown"}[info.absolute_position]
        self._refresh()

    def link_disconnected(self, reason: str, lost: bool) -> None:
        self.servo_on = None
        self._refresh()

    @Slot(object)
    def _on_status(self, status: DriveStatus) -> None:
        changed = status.servo_on != self.servo_on
        self.servo_on = status.servo_on
        if status.absolute_counts is not None:
            self.encoder = "absolute"
            self._set_position(status.absolute_counts, polled=True)
        elif status.note and "refuses DGR" in status.note:
            self.encoder = "incremental"
        if changed:
            self._refresh()

    def why_not(self) -> str:
        """Why DGR cannot be read now ('' when it can)."""
        if not self.link.connected:
            return "Not connected: connect to the drive first (Ctrl+K)."
        if self.encoder == "incremental":
            return INCREMENTAL_NOTE
        if self.servo_on:
            return f"The {SERVO_ON_NOTE}: switch the servo off at the controller to read the position."
        return ""

    def _refresh(self) -> None:
        info = self.link.info
        ratio = self.ratio
        if info is None:
            self.summary_label.setText("Not connected.")
        else:
            what = ("This drive answers only the manual's commands: the absolute position (DGR) with the "
                    "servo off, and clearing the multi-turn data (OWW)." if info.documented_only else
                    "This drive has FHA Studio's extension commands too; these checks use only DGR and OWW, "
                    "as on a real HA-655.")
            code = self.gui_session.state.actuator_code or info.adjusted_for
            scale = (f" Angles use the ratio {ratio} of {code}."
                     if ratio else " Enter the actuator's model code on the Connection page: its ratio "
                     "scales the angles.")
            self.summary_label.setText(what + scale)
        reason = self.why_not()
        self.reason_label.setText(reason)
        can_read = not reason
        incremental = self.encoder == "incremental"
        for button in (self.read_button, self.encoder_start_button, self.dog_record_button):
            button.setEnabled(can_read)
            button.setToolTip(reason)
        self.encoder_end_button.setEnabled(can_read and self._encoder_start is not None and ratio is not None)
        self.encoder_end_button.setToolTip(reason or ("" if self._encoder_start is not None
                                                       else "Read the start position first"))
        self.direction_start_button.setEnabled(can_read)
        self.direction_start_button.setToolTip(reason)
        self.direction_end_button.setEnabled(can_read and self._direction_start is not None)
        before_first = "" if self._direction_start is not None else "Read the position before the FWD command"
        self.direction_end_button.setToolTip(reason or before_first)
        connected = self.link.connected
        for group in (self.encoder_hand, self.direction_hand, self.dog_hand):
            group.setVisible(incremental)
            group.setEnabled(connected)
        origin_reason = reason
        if incremental:
            origin_reason = ("An incremental encoder has no multi-turn data: there is nothing to clear "
                             "(OWW needs an absolute encoder). The origin comes from the origin sensor "
                             "and the controller's homing.")
        self.origin_button.setEnabled(not origin_reason and not self._pending_origin())
        self.origin_button.setToolTip(origin_reason)
        servo = {True: "on: NOT met", False: "off: met", None: "not known"}[self.servo_on]
        encoder = {"absolute": "absolute: met", "incremental": "incremental: NOT met",
                   "unknown": "not known yet"}[self.encoder]
        self.origin_conditions.setText(f"Conditions: servo {servo}; encoder {encoder}."
                                       + (f" {origin_reason}" if origin_reason else ""))

    def _pending_origin(self) -> bool:
        return self._origin_token is not None

    # -- reading -------------------------------------------------------------------------------
    def _read(self, then: Callable[[int], None]) -> None:
        if self.why_not():
            self._refresh()
            return
        self.link.send(Call(_read_position), partial(self._position_answer, then))

    def _position_answer(self, then: Callable[[int], None], result: LinkReply[int]) -> None:
        if result.ok:
            self.encoder = "absolute"
            self._set_position(result.answer)
            then(result.answer)
        elif result.failed_with(ServoOnRefused):
            self.servo_on = True
            self.reason_label.setText(f"The {SERVO_ON_NOTE}: nothing read.")
        elif result.failed_with(CommandRejected) or result.failed_with(CommandNotSupported):
            self.encoder = "incremental"
            self._refresh()
        else:
            self.reason_label.setText(f"The position could not be read: {result.error}")
            return
        self._refresh()

    def _set_position(self, counts: int, polled: bool = False) -> None:
        self.last_counts = counts
        ratio = self.ratio
        text = ab.position_text(counts, ab.output_deg(counts, ratio) if ratio else None)
        self.position_label.setText(f"Position (DGR, servo off): {text}")

    def _show_position(self, counts: int) -> None:
        pass  # _set_position has shown it

    # -- the checks ----------------------------------------------------------------------------
    def _record(self, check: str, values: dict[str, Any], passed: bool | None, detail: str,
                by_hand: bool = False) -> ab.DgrCheckRecord:
        record = ab.DgrCheckRecord(check, self.who or "not given", ab.now_text(), values, passed, detail,
                                by_hand)
        self.records.append(record)
        self._save(record)
        row = self.history.rowCount()
        self.history.insertRow(row)
        verdict = {True: "pass", False: "FAIL", None: "recorded"}[passed]
        when = record.at[11:19] if len(record.at) >= 19 else record.at  # the time; the date in the tooltip
        for column, text in enumerate((ab.CHECK_TITLES[check], verdict + (" (by hand)" if by_hand else ""),
                                       detail, record.who, when)):
            item = QTableWidgetItem(text)
            item.setToolTip(record.at if column == 4 else text)
            self.history.setItem(row, column, item)
        self.history.resizeRowToContents(row)
        self.sigRecorded.emit(record)
        return record

    def record_bench_checks(self, checks: list) -> None:
        """Checks of a move taken from CN2 on a bench instrument (the Scope's Bench tab, servo on),
        recorded beside the DGR checks with where their figures came from."""
        for check in checks:
            self._record(check.check, dict(check.values), check.passed, check.detail)

    def _save(self, record: ab.DgrCheckRecord) -> None:
        folder = data_dir() / "checks"
        folder.mkdir(parents=True, exist_ok=True)
        with (folder / "dgr-checks.jsonl").open("a", encoding="utf-8") as f:
            f.write(json.dumps(record.as_dict()) + "\n")

    def _encoder_started(self, counts: int) -> None:
        self._encoder_start = counts
        self.encoder_result.setText(f"Start: {counts} counts. Now turn the output by hand by "
                                    f"{self.encoder_angle.value():+g}°, then read again.")
        self._refresh()

    def _encoder_done(self, counts: int) -> None:
        ratio = self.ratio
        if self._encoder_start is None or ratio is None:
            return
        turned = self.encoder_angle.value()
        passed, detail, values = ab.encoder_check(self._encoder_start, counts, turned, ratio)
        self._encoder_start = None
        self.encoder_result.setText(("PASS: " if passed else "FAIL: ") + detail)
        self._record("encoder", values, passed, detail)
        self._refresh()

    def _encoder_by_hand(self) -> None:
        seen = self.encoder_seen.currentText()
        passed = self.encoder_seen.currentIndex() == 0
        detail = f"turned {self.encoder_angle.value():+g}° by hand: {seen} (the drive gives no position)"
        self.encoder_result.setText(detail)
        self._record("encoder", {"turned_deg": self.encoder_angle.value(), "seen": seen}, passed, detail,
                     by_hand=True)

    def _panel_value_changed(self) -> None:
        """Parameter 8 as known (read, or entered from the panel on the Rotary direction or
        Parameters page) preselects the 1-10 check's comparison."""
        item = self.gui_session.parameter_model.by_key("rotary_direction")
        value = self.gui_session.state.value_of(item.mode, item.number)
        if value in (0, 1):
            self.direction_param.setCurrentIndex(value + 1)

    def parameter_8(self) -> int | None:
        index = self.direction_param.currentIndex()
        return None if index == 0 else index - 1

    def _direction_started(self, counts: int) -> None:
        self._direction_start = counts
        self.direction_result.setText(f"Before: {counts} counts. Now step 2 at the controller, then step 3.")
        self._refresh()

    def _direction_done(self, counts: int) -> None:
        if self._direction_start is None:
            return
        passed, detail, values = ab.rotary_direction_check(self._direction_start, counts, self.parameter_8(),
                                                           self.ratio)
        self._direction_start = None
        prefix = {True: "PASS: ", False: "FAIL: ", None: ""}[passed]
        self.direction_result.setText(prefix + detail)
        self._record("rotary_direction", values, passed, detail)
        self._refresh()

    def _direction_by_hand(self) -> None:
        seen = self.direction_seen.currentText()
        parameter_8 = self.parameter_8()
        if seen == "did not turn":
            passed: bool | None = False
        elif parameter_8 is None:
            passed = None
        else:
            passed = seen == ("CW" if parameter_8 == 0 else "CCW")
        detail = f"the FWD command turned the output {seen} (seen by the technician); parameter 8 = " + (
            "not entered" if parameter_8 is None else str(parameter_8))
        self.direction_result.setText(detail)
        self._record("rotary_direction", {"turned": seen, "rotary_direction": parameter_8}, passed, detail,
                     by_hand=True)

    def _dog_read(self, counts: int) -> None:
        ratio = self.ratio
        if ratio is None:
            self.dog_result.setText("Enter the actuator's model code on the Connection page: the ratio "
                                    "turns counts into an angle.")
            return
        self._record_dog(ab.wrap_deg(ab.output_deg(counts, ratio)), counts=counts)

    def _record_dog(self, angle_deg: float, counts: int | None = None, by_hand: bool = False) -> None:
        sensor = self.dog_sensor.currentData()
        problem = ""
        context = self._context()
        if context is not None:
            problem = angle_problem(sensor, angle_deg, context, self.dog_angles)
        name = SENSOR_NAMES[sensor]
        detail = f"{name} switches at {angle_deg:+.2f}°" + (f": {problem}" if problem else
                                                             (" (within the movable range of 4-7-3)"
                                                              if context is not None else ""))
        if not problem:
            self.dog_angles[sensor] = angle_deg
        self.dog_result.setText(detail)
        values: dict[str, Any] = {"sensor": sensor, "angle_deg": round(angle_deg, 3)}
        if counts is not None:
            values["counts"] = counts
        self._record("sensor_dog", values, not problem, detail, by_hand=by_hand)

    def _context(self) -> dict | None:
        code = self.gui_session.state.actuator_code or (self.link.info.adjusted_for if self.link.info else "")
        if not code:
            return None
        from fha_studio.logic.procedures.context import build_context

        try:
            return build_context(code)
        except ValueError:
            return None

    def _origin_clicked(self) -> None:
        if self.why_not() or self.encoder == "incremental":
            self._refresh()
            return
        self._origin_token = self.link.send(Call(partial(_set_origin, self.ratio)), self._origin_done)
        self.origin_result.setText("OWW sent: waiting for the drive's acknowledgement (about 5 s) …")
        self._refresh()

    def _origin_done(self, result: LinkReply[ab.OriginResult]) -> None:
        self._origin_token = None
        if result.ok:
            origin = result.answer
            self._set_position(origin.after_counts)
            detail = (f"multi-turn data cleared (acknowledged after {origin.oww_s:.1f} s); position before "
                      f"{origin.before_counts} counts, read back "
                      + ab.position_text(origin.after_counts, origin.after_deg))
            self.origin_result.setText("DONE: " + detail)
            self._record("absolute_origin", origin.as_dict(), True, detail)
        elif result.failed_with(ServoOnRefused):
            self.origin_result.setText(f"Nothing cleared: the {SERVO_ON_NOTE}.")
        elif result.failed_with(CommandRejected):
            text = ab.refusal_text(CommandRejected(""), Command.OWW)
            self.origin_result.setText(f"Nothing cleared: {text}.")
        else:
            self.origin_result.setText(f"OWW failed: {result.error}. Whether the drive cleared the "
                                       "multi-turn data is not known: read the position.")
        self._refresh()
