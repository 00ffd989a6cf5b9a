"""Jog and test run: servo on/off, hold-to-run FWD/REV, move by an angle, live inputs."""

from __future__ import annotations

from PySide6.QtCore import QEvent, QSettings, Qt, Signal, Slot
from PySide6.QtWidgets import (
    QDoubleSpinBox,
    QFormLayout,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from fha_studio.gui.link import Cmd, CommandResult, DriveStatus, LinkInfo
from fha_studio.gui.pages.base import BasePage
from fha_studio.gui.session import Session
from fha_studio.gui.widgets import AMBER, GREEN, RED, Lamp, space_jogs_only
from fha_studio.hardware.protocol import IoBit

#: (I/O bit, caption, colour when on) of the inputs and outputs shown live.
LIVE_SIGNALS = (
    (IoBit.READY, "Ready", GREEN),
    (IoBit.IN_POSITION, "In position", GREEN),
    (IoBit.MOVING, "Moving", AMBER),
    (IoBit.BRAKE_RELEASED, "Brake released", AMBER),
    (IoBit.FWD_INHIBIT, "FWD inhibit", RED),
    (IoBit.REV_INHIBIT, "REV inhibit", RED),
    (IoBit.LIMIT_SWITCH_2, "Limit switch 2 (CW end)", RED),
    (IoBit.LIMIT_SWITCH_1, "Limit switch 1 (CCW end)", RED),
    (IoBit.ORIGIN_SENSOR, "Origin sensor", AMBER),
    (IoBit.ALARM, "Alarm output", RED),
)


class HoldButton(QPushButton):
    """A hold-to-run button: `sigHeld` on press, `sigReleased` on release or when it loses the
    mouse or the keyboard focus (so that a jog never outlives the finger on the button)."""

    sigHeld = Signal()
    sigReleased = Signal()

    def __init__(self, text: str, parent: QWidget | None = None):
        super().__init__(text, parent)
        self.setAutoRepeat(False)
        self._held = False
        self.pressed.connect(self._press)
        self.released.connect(self._release)

    @property
    def held(self) -> bool:
        return self._held

    def _press(self) -> None:
        if not self._held:
            self._held = True
            self.sigHeld.emit()

    def _release(self) -> None:
        if self._held:
            self._held = False
            self.sigReleased.emit()

    def release(self) -> None:
        if self.isDown():
            self.setDown(False)
        self._release()

    def event(self, event) -> bool:
        if event.type() in (
            QEvent.Type.FocusOut,
            QEvent.Type.Hide,
            QEvent.Type.EnabledChange,
            QEvent.Type.Leave,  # dragging off the button stops, as letting go does
        ):
            self.release()
        return super().event(event)


class JogPage(BasePage):
    """Servo, jog, move-by and the live I/O of the drive."""

    def __init__(self, session: Session, main_window=None):
        super().__init__()
        self.session = session
        self.link = session.link
        self.main_window = main_window
        layout = QHBoxLayout(self)
        left = QVBoxLayout()
        layout.addLayout(left, 3)

        servo_box = QGroupBox("Servo")
        s_layout = QHBoxLayout(servo_box)
        self.servo_on_button = QPushButton("Servo &ON")
        self.servo_off_button = QPushButton("Servo O&FF")
        self.servo_lamp = Lamp("Servo", AMBER)
        for w in (self.servo_on_button, self.servo_off_button, self.servo_lamp):
            s_layout.addWidget(w)
        s_layout.addStretch(1)
        note = QLabel("Nothing moves without an explicit servo ON.")
        s_layout.addWidget(note)
        left.addWidget(servo_box)

        jog_box = QGroupBox("Jog (hold to run, release to stop)")
        j_layout = QGridLayout(jog_box)
        self.speed_spin = QDoubleSpinBox()
        self.speed_spin.setDecimals(1)
        self.speed_spin.setRange(0.1, 100.0)
        self.speed_spin.setValue(5.0)
        self.speed_spin.setSuffix(" r/min")
        self.speed_spin.setToolTip("Output speed while a jog button is held (output side, r/min)")
        speed_label = QLabel("Jog &speed:")
        speed_label.setBuddy(self.speed_spin)
        self.rev_button = HoldButton("◀  &REV")
        self.fwd_button = HoldButton("F&WD  ▶")
        for b in (self.rev_button, self.fwd_button):
            b.setMinimumHeight(56)
            b.setToolTip("Hold (mouse or Space key) to jog; release to stop")
        j_layout.addWidget(speed_label, 0, 0)
        j_layout.addWidget(self.speed_spin, 0, 1)
        j_layout.addWidget(self.rev_button, 1, 0)
        j_layout.addWidget(self.fwd_button, 1, 1)
        left.addWidget(jog_box)

        move_box = QGroupBox("Move by an angle")
        m_layout = QFormLayout(move_box)
        self.angle_spin = QDoubleSpinBox()
        self.angle_spin.setRange(-999.99, 999.99)  # the MOV value field: 5 digits of 0.01 deg
        self.angle_spin.setDecimals(2)
        self.angle_spin.setValue(90.0)
        self.angle_spin.setSuffix(" °")
        self.move_speed_spin = QDoubleSpinBox()
        self.move_speed_spin.setRange(0.1, 100.0)
        self.move_speed_spin.setDecimals(1)
        self.move_speed_spin.setValue(10.0)
        self.move_speed_spin.setSuffix(" r/min")
        self.move_button = QPushButton("&Move")
        self.move_button.setToolTip("Move the output by the angle (+ = FWD) at the speed, then hold")
        m_layout.addRow("&Angle (output, + = FWD):", self.angle_spin)
        m_layout.addRow("Sp&eed:", self.move_speed_spin)
        m_layout.addRow(self.move_button)
        left.addWidget(move_box)
        self.message = QLabel("")
        self.message.setWordWrap(True)
        left.addWidget(self.message)
        left.addStretch(1)

        right = QVBoxLayout()
        layout.addLayout(right, 2)
        live_box = QGroupBox("Live from the drive")
        l_layout = QFormLayout(live_box)
        self.position_label = QLabel("—")
        self.speed_label = QLabel("—")
        self.current_label = QLabel("—")
        for label in (self.position_label, self.speed_label, self.current_label):
            label.setMinimumWidth(120)
        l_layout.addRow("Output position:", self.position_label)
        l_layout.addRow("Output speed:", self.speed_label)
        l_layout.addRow("Motor current:", self.current_label)
        self.signal_lamps: dict[IoBit, Lamp] = {}
        for bit, caption, colour in LIVE_SIGNALS:
            lamp = Lamp(caption, colour)
            self.signal_lamps[bit] = lamp
            l_layout.addRow(lamp)
        right.addWidget(live_box)
        stop_hint = QLabel(
            "<b>STOP</b>: the red button in the toolbar, or the <b>Esc</b> key, on every page."
        )
        stop_hint.setWordWrap(True)
        right.addWidget(stop_hint)
        right.addStretch(1)

        self.servo_on_button.clicked.connect(lambda: self.link.send(Cmd.SERVO, True))
        self.servo_off_button.clicked.connect(lambda: self.link.send(Cmd.SERVO, False))
        self.fwd_button.sigHeld.connect(lambda: self._jog(+1))
        self.rev_button.sigHeld.connect(lambda: self._jog(-1))
        self.fwd_button.sigReleased.connect(self.release_jog)
        self.rev_button.sigReleased.connect(self.release_jog)
        self.move_button.clicked.connect(self.move_by)
        self.link.sigStatus.connect(self._on_status)
        self.link.sigResult.connect(self._on_result)
        self._set_enabled(False, False)
        space_jogs_only(self, (self.fwd_button, self.rev_button))

    # -- settings ---------------------------------------------------------------------------------
    def restore_settings(self, settings: QSettings) -> None:
        self.speed_spin.setValue(float(str(settings.value("jog/speed_rpm", self.speed_spin.value()))))
        self.angle_spin.setValue(float(str(settings.value("jog/angle_deg", self.angle_spin.value()))))
        self.move_speed_spin.setValue(
            float(str(settings.value("jog/move_speed_rpm", self.move_speed_spin.value())))
        )

    def save_settings(self, settings: QSettings) -> None:
        settings.setValue("jog/speed_rpm", self.speed_spin.value())
        settings.setValue("jog/angle_deg", self.angle_spin.value())
        settings.setValue("jog/move_speed_rpm", self.move_speed_spin.value())

    # -- actions ----------------------------------------------------------------------------------
    def _jog(self, sign: int) -> None:
        if not self.link.servo_on:
            self.message.setText("Switch the servo ON first: nothing moves without it.")
            return
        self.message.setText("")
        self.link.jog_press(sign * self.speed_spin.value())

    @Slot()
    def release_jog(self) -> None:
        for b in (self.fwd_button, self.rev_button):
            b._held = False
            if b.isDown():
                b.setDown(False)
        if self.link.connected:
            self.link.jog_release()

    @Slot()
    def move_by(self) -> None:
        if not self.link.servo_on:
            self.message.setText("Switch the servo ON first: nothing moves without it.")
            return
        self.link.send(Cmd.SET_MOVE_SPEED, self.move_speed_spin.value())
        self.link.send(Cmd.MOVE_BY, self.angle_spin.value())

    def shutdown(self) -> None:
        self.release_jog()

    # -- from the link ----------------------------------------------------------------------------
    def _set_enabled(self, connected: bool, servo_on: bool) -> None:
        can_move = connected and bool(self.link.info and self.link.info.can_move)
        self.servo_on_button.setEnabled(can_move and not servo_on)
        self.servo_off_button.setEnabled(can_move and servo_on)
        for w in (self.fwd_button, self.rev_button, self.move_button):
            w.setEnabled(can_move and servo_on)
        if not connected:
            for lamp in self.signal_lamps.values():
                lamp.set_state(None)
            self.servo_lamp.set_state(None)

    def link_disconnected(self, reason: str, lost: bool) -> None:
        self._set_enabled(False, False)

    def link_connected(self, info: LinkInfo) -> None:
        self._set_enabled(True, False)
        if not info.can_move:
            self.message.setText(
                "This drive answers only the documented CN3 commands: servo, jog and moves come from "
                "its CN2 connector, not from FHA Studio."
            )

    @Slot(object)
    def _on_status(self, status: DriveStatus) -> None:
        self._set_enabled(True, bool(status.servo_on))
        self.servo_lamp.set_state(status.servo_on)
        for bit, lamp in self.signal_lamps.items():
            lamp.set_state(status.bit(bit))
        if status.position_pulse is not None:
            text = f"{status.position_pulse:,} pulse"
            ppr = self.session.state.output_resolution_ppr  # the axis's actuator, at every status
            if ppr:
                text = f"{status.position_pulse * 360.0 / ppr:.2f} °   ({text})"
            self.position_label.setText(text)
        if status.speed_rpm is not None:
            self.speed_label.setText(f"{status.speed_rpm:.2f} r/min")
        if status.current_a is not None:
            self.current_label.setText(f"{status.current_a:.2f} A")
        if status.refused:
            self.position_label.setText("servo on: the drive does not report")

    @Slot(object)
    def _on_result(self, result: CommandResult) -> None:
        if result.cmd in (Cmd.JOG, Cmd.MOVE_BY, Cmd.SERVO, Cmd.SET_MOVE_SPEED) and not result.ok:
            self.message.setText(f"The drive refused: {result.error}")
            if result.cmd is Cmd.JOG:
                self.release_jog()
        elif result.cmd is Cmd.SERVO and result.ok:
            self.message.setText("")

    def changeEvent(self, event) -> None:
        # a held jog stops when the window loses activation (another window, a dialog)
        if (
            event.type() == QEvent.Type.ActivationChange
            and not self.isActiveWindow()
            and (self.fwd_button.held or self.rev_button.held)
        ):
            self.release_jog()
        super().changeEvent(event)


_ = Qt
