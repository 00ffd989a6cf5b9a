"""Rotary direction: [parameter mode] -> [8: rotary direction] (FHA-C manual 1-10), drawn, explained,
written (verified), and checked live by jogging FWD and asking which way the flange turned."""

from __future__ import annotations

from PySide6.QtCore import Qt, QTimer, Slot
from PySide6.QtWidgets import (
    QButtonGroup,
    QComboBox,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QRadioButton,
    QVBoxLayout,
)

from fha_studio.catalog.tables import default_rotary_direction, rotary_direction_setting
from fha_studio.gui.link import DriveStatus, LinkInfo, LinkReply, PowerCycle
from fha_studio.gui.pages.base import BasePage, PageId
from fha_studio.gui.session import Session
from fha_studio.gui.widgets import FlangeWidget, space_jogs_only
from fha_studio.logic.procedures.direction_check import DirectionCheck

KEY = "rotary_direction"
#: How long the live check jogs FWD, in ms, and at what output speed, in r/min.
CHECK_JOG_MS = 1500
CHECK_SPEED_RPM = 5.0

CONSEQUENCE = {
    0: (
        "<b>0 (default): a FWD command turns the output flange clockwise</b>, seen from the flange. "
        "FWD pulses, a positive speed command, jog FWD and a positive move all turn it CW."
    ),
    1: (
        "<b>1 (reversed): a FWD command turns the output flange counter-clockwise</b>, seen from the flange. "
        "Every FWD command (pulses, speed command, jog FWD, a positive move) now turns it CCW; "
        "the controller's idea of + and − is reversed with it. Check the limit switches and the origin "
        "search direction of the machine afterwards."
    ),
}


def _fwd_words(value: int) -> str:
    """Where a FWD command turns the flange with rotary direction ``value`` (the 1-10 table)."""
    try:
        return "clockwise" if rotary_direction_setting(value).fwd_turns_cw else "counter-clockwise"
    except ValueError:
        return "(a value the manual does not list)"


class DirectionPage(BasePage):
    """Set and check the rotary direction."""

    def __init__(self, session: Session, main_window=None):
        super().__init__()
        self.session = session
        self.link = session.link
        self.main_window = main_window
        self.last_check: DirectionCheck | None = None  # the check confirmed last (the report takes it)
        self._check_running = False
        self._check_start_pulse: int | None = None
        self._check_end_pulse: int | None = None
        self._last_pulse: int | None = None
        layout = QHBoxLayout(self)
        self.flange = FlangeWidget()
        layout.addWidget(self.flange, 1)
        right = QVBoxLayout()
        layout.addLayout(right, 1)

        intro = QLabel(
            "The manual (1-10): the forward direction is <b>clockwise seen from the output flange</b> "
            "when the "
            "driver gets a FWD command. [parameter mode] → [8: rotary direction] reverses it."
        )
        intro.setWordWrap(True)
        right.addWidget(intro)

        box = QGroupBox("Rotary direction (parameter 8)")
        b_layout = QVBoxLayout(box)
        self.drive_label = QLabel("On the drive: not read")
        b_layout.addWidget(self.drive_label)
        self.cw_radio = QRadioButton("0 — FWD turns the flange &clockwise (default)")
        self.ccw_radio = QRadioButton("1 — FWD turns the flange counter-clock&wise (reversed)")
        self.group = QButtonGroup(self)
        self.group.addButton(self.cw_radio, 0)
        self.group.addButton(self.ccw_radio, 1)
        b_layout.addWidget(self.cw_radio)
        b_layout.addWidget(self.ccw_radio)
        self.consequence = QLabel("")
        self.consequence.setWordWrap(True)
        # word-wrapped labels in a group box get too little height: reserve five lines
        self.consequence.setMinimumHeight(self.consequence.fontMetrics().lineSpacing() * 5)
        self.consequence.setAlignment(Qt.AlignmentFlag.AlignTop | Qt.AlignmentFlag.AlignLeft)
        b_layout.addWidget(self.consequence)
        row = QHBoxLayout()
        self.write_button = QPushButton("&Write to the drive")
        self.power_cycle_button = QPushButton("&Power cycle (simulated drive)")
        self.power_cycle_button.setVisible(False)
        row.addWidget(self.write_button)
        row.addWidget(self.power_cycle_button)
        row.addStretch(1)
        b_layout.addLayout(row)
        self.status_label = QLabel("")
        self.status_label.setWordWrap(True)
        b_layout.addWidget(self.status_label)
        right.addWidget(box)

        check = QGroupBox("Live check: does FWD turn the way it should?")
        c_layout = QVBoxLayout(check)
        c_layout.addWidget(
            QLabel(
                f"Servo on, then press the button: the axis jogs FWD for {CHECK_JOG_MS / 1000:g} s at "
                f"{CHECK_SPEED_RPM:g} r/min. Watch the output flange and say which way it turned."
            )
        )
        crow = QHBoxLayout()
        self.check_button = QPushButton("&Jog FWD briefly")
        crow.addWidget(self.check_button)
        crow.addStretch(1)
        c_layout.addLayout(crow)
        arow = QHBoxLayout()
        self.seen_cw = QPushButton("I saw it turn C&W")
        self.seen_ccw = QPushButton("I saw it turn CC&W")
        self.seen_none = QPushButton("It did &not move")
        for b in (self.seen_cw, self.seen_ccw, self.seen_none):
            b.setEnabled(False)
            arow.addWidget(b)
        arow.addStretch(1)
        c_layout.addLayout(arow)
        self.check_result = QLabel("")
        self.check_result.setWordWrap(True)
        c_layout.addWidget(self.check_result)
        # a drive of the manual's commands: no jog over CN3; the 1-10 check goes with DGR and the
        # controller's servo-ON and FWD command (the DGR checks page)
        self.documented_box = QGroupBox("This drive: check with the controller and DGR")
        d_layout = QVBoxLayout(self.documented_box)
        self.documented_note = QLabel(
            "This drive takes no jog and gives no parameter access over CN3. Read [parameter mode] → "
            "[8: rotary direction] on the drive's front panel, then check 1-10 on the <b>DGR checks</b> "
            "page: the position is read with the servo off, the controller switches the servo on and "
            "gives a short FWD command, and the change of the position says CW or CCW."
        )
        self.documented_note.setWordWrap(True)
        d_layout.addWidget(self.documented_note)
        prow = QHBoxLayout()
        prow.addWidget(QLabel("Item 8 on the drive's panel:"))
        self.panel_combo = QComboBox()
        self.panel_combo.setObjectName("panelRotaryDirection")
        self.panel_combo.addItems(["0 (FWD turns CW)", "1 (FWD turns CCW)"])
        prow.addWidget(self.panel_combo)
        prow.addWidget(QLabel("entered by"))
        self.panel_who = QLineEdit()
        self.panel_who.setPlaceholderText("your name")
        prow.addWidget(self.panel_who)
        self.panel_enter_button = QPushButton("Enter")
        self.panel_enter_button.clicked.connect(self.enter_from_panel)
        prow.addWidget(self.panel_enter_button)
        prow.addStretch(1)
        d_layout.addLayout(prow)
        self.open_dgr_button = QPushButton("Open the DGR checks: rotary direction")
        self.open_dgr_button.clicked.connect(self._open_dgr_check)
        d_layout.addWidget(self.open_dgr_button)
        self.documented_box.setVisible(False)
        right.addWidget(self.documented_box)
        right.addWidget(check)
        right.addStretch(1)

        self.group.idToggled.connect(self._choice_changed)
        self.write_button.clicked.connect(self.write)
        self.power_cycle_button.clicked.connect(self._power_cycle)
        self.check_button.clicked.connect(self.start_check)
        self.seen_cw.clicked.connect(lambda: self.answer("cw"))
        self.seen_ccw.clicked.connect(lambda: self.answer("ccw"))
        self.seen_none.clicked.connect(lambda: self.answer("none"))
        session.state.sigParametersChanged.connect(self._values_changed)
        session.state.sigFrontPanelChanged.connect(self._values_changed)
        session.sigWritesDone.connect(self._writes_done)
        self.link.sigPowerCycled.connect(self._power_cycled)
        self.link.sigStatus.connect(self._on_status)
        self._stop_timer = QTimer(self)
        self._stop_timer.setSingleShot(True)
        self._stop_timer.timeout.connect(self._end_check_jog)
        self.group.button(default_rotary_direction().value).setChecked(True)
        self._update()
        space_jogs_only(self, ())  # "Jog FWD briefly" moves: only a deliberate click starts it

    # -- state --------------------------------------------------------------------------------------
    def _key(self) -> tuple[str, int]:
        item = self.session.item(KEY)
        return (item.mode, item.number)

    def enter_from_panel(self) -> bool:
        """Record item 8 as the drive's front panel shows it (who and when kept)."""
        mode, number = self._key()
        try:
            self.session.state.enter_front_panel(mode, number, self.panel_combo.currentIndex(),
                                                 self.panel_who.text())
        except ValueError:
            self.status_label.setText("Enter your name first: a value from the panel is recorded with who "
                                      "and when.")
            return False
        self.status_label.setText("")
        return True

    def drive_value(self) -> int | None:
        """Item 8 as known: read over the link, else as entered from the front panel."""
        try:
            return self.session.state.value_of(*self._key())
        except Exception:
            return None

    def chosen(self) -> int:
        return max(0, self.group.checkedId())

    def _update(self) -> None:
        value = self.drive_value()
        connected = self.link.connected
        if value is None:
            self.drive_label.setText(
                "On the drive: not read yet" if connected else "On the drive: not connected"
            )
        else:
            self.drive_label.setText(
                f"On the drive: <b>{value}</b> — FWD turns the flange {_fwd_words(value)}"
            )
        info = self.link.info
        no_parameters = connected and info is not None and not info.can_parameters
        no_jog = connected and info is not None and not info.can_move
        if no_parameters and value is None:
            self.drive_label.setText("On the drive: read it on the front panel, [parameter mode] → item 8 "
                                     "(no parameter access over CN3), and enter it below")
        elif no_parameters and value is not None:
            entry = self.session.state.front_panel.get(self._key())
            by = f" (entered from the panel by {entry.who} at {entry.time[11:16]})" if entry else ""
            self.drive_label.setText(f"On the drive's panel: <b>{value}</b> — FWD turns the flange "
                                     f"{_fwd_words(value)}{by}")
        self.write_button.setEnabled(connected and value is not None and self.chosen() != value
                                     and not no_parameters)
        self.write_button.setToolTip(
            "This drive gives no parameter access over CN3: set item 8 in parameter mode on its front panel"
            if no_parameters else "")
        self.check_button.setEnabled(connected and self.link.servo_on and not self._check_running
                                     and not no_jog)
        self.check_button.setToolTip(
            "This drive takes no jog over CN3: use the DGR checks page with the controller" if no_jog else "")
        for b in (self.seen_cw, self.seen_ccw, self.seen_none):
            b.setToolTip("Jog FWD briefly first" if not no_jog else
                         "This drive takes no jog over CN3: use the DGR checks page")
        self.documented_box.setVisible(bool(no_jog or no_parameters))

    @Slot(int, bool)
    def _choice_changed(self, button_id: int, checked: bool) -> None:
        if not checked:
            return
        self.flange.set_clockwise(rotary_direction_setting(button_id).fwd_turns_cw)
        self.consequence.setText(
            CONSEQUENCE[button_id] + " Takes effect after the driver's control power is cycled."
        )
        self._update()

    @Slot()
    def _values_changed(self) -> None:
        value = self.drive_value()
        if value in (0, 1) and not self.write_button.isEnabled():
            (self.cw_radio if value == 0 else self.ccw_radio).setChecked(True)
        self._update()

    # -- writing ------------------------------------------------------------------------------------
    @Slot()
    def write(self) -> None:
        mode, number = self._key()
        self.status_label.setText("Writing …")
        self.session.write([(mode, number, self.chosen())])

    @Slot(object)
    def _writes_done(self, entries: list) -> None:
        mode, number = self._key()
        mine = [e for e in entries if (e["mode"], e["number"]) == (mode, number)]
        if not mine:
            return
        entry = mine[-1]
        if entry.get("verified"):
            sim = bool(self.link.info and self.link.info.is_simulated)
            self.status_label.setText(
                f"Written and verified: {entry['new']}. <b>It takes effect after a power cycle</b> "
                "of the driver's "
                "control power" + (": use the button." if sim else " (switch it off, wait, switch it on).")
            )
            self.power_cycle_button.setVisible(sim)
        else:
            self.status_label.setText(f"Not written: {entry.get('error')}")
        self._update()

    @Slot()
    def _power_cycle(self) -> None:
        if self.link.servo_on:
            self.status_label.setText("Switch the servo off before the power cycle.")
            return
        self.link.send(PowerCycle())

    @Slot()
    def _power_cycled(self) -> None:
        """Whoever asked for it: the new rotary direction is in effect now."""
        self.power_cycle_button.setVisible(False)
        self.status_label.setText("Power cycled: the new rotary direction is in effect. Check it live below.")

    def _check_jog_answered(self, result: LinkReply[float]) -> None:
        if not result.ok and self._check_running:
            self._stop_timer.stop()
            self._check_running = False
            self.check_result.setText(f"The drive refused the jog: {result.error}")
            self._update()

    # -- the live check -----------------------------------------------------------------------------
    @Slot()
    def start_check(self) -> None:
        if not self.link.servo_on:
            self.check_result.setText("Switch the servo ON first (toolbar or the Jog page).")
            return
        self._check_running = True
        self._check_start_pulse = self._last_pulse
        self.check_result.setText("Jogging FWD … watch the flange.")
        for b in (self.seen_cw, self.seen_ccw, self.seen_none):
            b.setEnabled(False)
        self.link.jog_press(CHECK_SPEED_RPM, self._check_jog_answered)
        self._stop_timer.start(CHECK_JOG_MS)
        self._update()

    @Slot()
    def _end_check_jog(self) -> None:
        self.link.jog_release()
        self._check_running = False
        self._check_end_pulse = self._last_pulse
        self.check_result.setText("Which way did the output flange turn, seen from the flange?")
        for b in (self.seen_cw, self.seen_ccw, self.seen_none):
            b.setEnabled(True)
        self.seen_cw.setFocus()
        self._update()

    def answer(self, seen: str) -> bool | None:
        """The technician's observation. True: as the parameter says; False: not; None: no motion."""
        for b in (self.seen_cw, self.seen_ccw, self.seen_none):
            b.setEnabled(False)
        value = self.drive_value()
        setting = default_rotary_direction() if value is None else rotary_direction_setting(value)
        expected = setting.fwd_direction.lower()
        if seen == "none":
            self.check_result.setText(
                "No motion seen: check that the servo is on, no inhibit or limit switch is active, "
                "and no alarm."
            )
            return None
        ok = seen == expected
        from fha_studio.logic.procedures.session import utc_now

        # kept for the commissioning report: a check confirmed here is the 1-10 procedure done
        self.last_check = DirectionCheck(
            parameter_value=setting.value, expected=expected.upper(), seen=seen.upper(), who="",
            at_utc=utc_now(),
        )
        if ok:
            self.check_result.setText(
                f"<span style='color:#2e7d32'><b>Confirmed</b>: FWD turns the flange {seen.upper()}, "
                f"as rotary direction = {setting.value} says.</span>"
            )
        else:
            self.check_result.setText(
                f"<span style='color:#b00020'><b>Mismatch</b>: rotary direction = {value} means FWD "
                "should turn "
                f"{expected.upper()}, but you saw {seen.upper()}. Was the last change power-cycled? "
                "Is the motor wired as the manual shows?</span>"
            )
        return ok

    @Slot(object)
    def _on_status(self, status: DriveStatus) -> None:
        if status.position_pulse is not None:
            self._last_pulse = status.position_pulse
            ppr = self._ppr()
            if ppr:
                sign = 1 if self.drive_value() in (0, None) else -1  # draw what the flange does
                self.flange.set_angle_deg(sign * status.position_pulse * 360.0 / ppr)
        if not self._check_running:
            can_jog = bool(self.link.info and self.link.info.can_move)
            self.check_button.setEnabled(self.link.connected and bool(status.servo_on) and can_jog)

    def _ppr(self) -> int | None:
        """Position pulses per output revolution of the axis's actuator (None: not given)."""
        return self.session.state.output_resolution_ppr

    def link_connected(self, info: LinkInfo) -> None:
        self._update()

    def _open_dgr_check(self) -> None:
        if self.main_window is not None:
            page = self.main_window.show_page(PageId.ABSOLUTE)
            page.tabs.setCurrentIndex(1)

    def link_disconnected(self, reason: str, lost: bool) -> None:
        self._update()

    def shutdown(self) -> None:
        if self._check_running:
            self._stop_timer.stop()
            self.link.jog_release()
