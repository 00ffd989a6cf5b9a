"""The embedded simulated drive's panel: what a real drive gets from outside CN3.

On a real HA-655 the servo-ON input and the command pulses come from the controller through CN2,
and the technician turns the output by hand for the encoder and sensor checks. The embedded
simulated drive (``sim://``) has no controller and no hands, so this toolbar plays them: shown
for an embedded drive only, never for a real one. Everything goes through the link thread
(``SimPanelRequest``); the result comes back as a message.
"""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal, Slot
from PySide6.QtWidgets import QCheckBox, QDoubleSpinBox, QLabel, QPushButton, QToolBar, QWidget

from fha_studio.gui.link import LinkController, LinkReply, SimPanelAction, SimPanelRequest
from fha_studio.gui.messages import Level

#: The angle of one controller command and one hand turn, output degrees (defaults).
COMMAND_DEG = 10.0
TURN_DEG = 5.0


class SimPanelBar(QToolBar):
    """Servo-ON (CN2), a FWD / REV command from the controller, turning by hand, the brake's 24 V."""

    sigMessage = Signal(str, object)  # text, Level

    def __init__(self, link: LinkController, parent: QWidget | None = None):
        super().__init__("Simulated controller and hands", parent)
        self.setObjectName("simPanel")
        self.setMovable(False)
        self.link = link
        title = QLabel("  Simulated drive — controller (CN2): ")
        title.setToolTip("The embedded simulated drive has no controller: these play its CN2 inputs "
                         "and your hands. A real drive gets them from outside FHA Studio.")
        self.addWidget(title)
        self.servo_check = QCheckBox("Servo-ON input")
        self.servo_check.setObjectName("simServoOn")
        self.servo_check.setToolTip("The controller's servo-ON signal on CN2")
        self.servo_check.toggled.connect(self._servo_toggled)
        self.addWidget(self.servo_check)
        self.command_spin = _angle_spin(COMMAND_DEG, 0.1, 360.0)
        self.command_spin.setToolTip("Angle of one command pulse train from the controller (output)")
        self.fwd_button = QPushButton("FWD command")
        self.rev_button = QPushButton("REV command")
        for button, sign in ((self.fwd_button, 1.0), (self.rev_button, -1.0)):
            button.setToolTip("A short command from the controller (needs the servo on)")
            button.clicked.connect(lambda _=False, s=sign: self._send(SimPanelAction.COMMAND,
                                                                       s * self.command_spin.value()))
            self.addWidget(button)
        self.addWidget(self.command_spin)
        self.addSeparator()
        self.addWidget(QLabel(" Hands: "))
        self.turn_spin = _angle_spin(TURN_DEG, -360.0, 360.0)
        self.turn_spin.setToolTip("Turn the output flange by hand by this angle, CW positive seen from "
                                  "the flange (servo off, brake released)")
        self.addWidget(self.turn_spin)
        self.turn_button = QPushButton("Turn by hand")
        self.turn_button.setObjectName("simTurn")
        self.turn_button.clicked.connect(lambda: self._send(SimPanelAction.TURN_BY_HAND,
                                                            self.turn_spin.value()))
        self.addWidget(self.turn_button)
        self.brake_check = QCheckBox("Brake released (24 V)")
        self.brake_check.toggled.connect(lambda on: self._send(SimPanelAction.BRAKE_RELEASED, on))
        self.addWidget(self.brake_check)
        link.sigStatus.connect(self._on_status)
        self.set_available(False)

    def set_available(self, available: bool) -> None:
        """Shown for an embedded simulated drive of the documented profile only (never a real drive)."""
        self.setVisible(available)
        self.setEnabled(available)

    def _send(self, action: SimPanelAction, value: float | bool) -> None:
        self.link.send(SimPanelRequest(action, value), self._on_reply)

    @Slot(bool)
    def _servo_toggled(self, on: bool) -> None:
        self._send(SimPanelAction.SERVO, on)

    @Slot(object)
    def _on_status(self, status) -> None:
        if status.servo_on is not None and status.servo_on != self.servo_check.isChecked():
            self.servo_check.blockSignals(True)
            self.servo_check.setChecked(status.servo_on)
            self.servo_check.blockSignals(False)
        self.turn_button.setEnabled(not status.servo_on)
        self.turn_button.setToolTip("Switch the servo off to turn the axis by hand" if status.servo_on
                                    else "Turn the output flange by hand (servo off, brake released)")

    def _on_reply(self, result: LinkReply[str]) -> None:
        if result.ok:
            self.sigMessage.emit(f"Simulated drive: {result.value}.", Level.INFO)
        else:
            self.sigMessage.emit(f"Simulated drive: {result.error}.", Level.WARNING)


def _angle_spin(value: float, minimum: float, maximum: float) -> QDoubleSpinBox:
    spin = QDoubleSpinBox()
    spin.setRange(minimum, maximum)
    spin.setDecimals(1)
    spin.setSuffix(" °")
    spin.setValue(value)
    spin.setAlignment(Qt.AlignmentFlag.AlignRight)
    return spin
