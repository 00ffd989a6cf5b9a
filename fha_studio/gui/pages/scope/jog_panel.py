"""A compact servo / jog / move / STOP panel, docked where the axis is watched (the scope), so
that a technician can move the axis and watch it at once. Same behaviour as the Jog page: jog is
hold-to-run (release, focus loss, hiding or another window stop it), nothing moves without
servo on, STOP is the main window's (the toolbar's STOP, shown again)."""

from __future__ import annotations

from PySide6.QtCore import QEvent, Slot
from PySide6.QtWidgets import QDoubleSpinBox, QGridLayout, QGroupBox, QHBoxLayout, QLabel, QPushButton

from fha_studio.gui.link import Cmd, CommandResult, DriveStatus, LinkController, LinkInfo
from fha_studio.gui.pages.jog import HoldButton
from fha_studio.gui.widgets import AMBER, Lamp, StopButton

#: Why the panel is disabled on a drive that answers only the documented CN3 commands.
CANNOT_MOVE_TEXT = ("This drive answers only the documented CN3 commands: servo, jog and moves come "
                    "from its CN2 connector, not from FHA Studio.")
NOT_CONNECTED_TEXT = "No drive connected."
SERVO_OFF_TEXT = "Servo OFF: switch it ON to jog or move."


class JogPanel(QGroupBox):
    """Servo ON/OFF, hold-to-run REV/FWD at a speed, move by an angle, STOP.

    ``window_stop``: the window's STOP (its toolbar's), which the panel's STOP follows: the same
    words, and what it does (the main window's ``stop_axis`` releases every held jog too; a
    machine window's stops every axis)."""

    def __init__(self, link: LinkController, window_stop: StopButton | None, parent=None):
        super().__init__("Move (hold to jog)", parent)
        self.setObjectName("jogPanel")
        self.link = link
        grid = QGridLayout(self)
        grid.setContentsMargins(6, 6, 6, 6)
        grid.setVerticalSpacing(4)
        self.servo_lamp = Lamp("Servo", AMBER)
        self.servo_on_button = QPushButton("Servo ON")
        self.servo_off_button = QPushButton("Servo OFF")
        servo_row = QHBoxLayout()
        for w in (self.servo_on_button, self.servo_off_button, self.servo_lamp):
            servo_row.addWidget(w)
        grid.addLayout(servo_row, 0, 0, 1, 2)
        self.speed_spin = QDoubleSpinBox()
        self.speed_spin.setDecimals(1)
        self.speed_spin.setRange(0.1, 100.0)
        self.speed_spin.setValue(5.0)
        self.speed_spin.setSuffix(" r/min")
        self.speed_spin.setToolTip("Output speed of a jog and of a move (output side, r/min)")
        grid.addWidget(QLabel("Speed"), 1, 0)
        grid.addWidget(self.speed_spin, 1, 1)
        self.rev_button = HoldButton("◀ REV")
        self.fwd_button = HoldButton("FWD ▶")
        for b in (self.rev_button, self.fwd_button):
            b.setMinimumHeight(36)
            b.setToolTip("Hold (mouse or Space key) to jog; release to stop")
        grid.addWidget(self.rev_button, 2, 0)
        grid.addWidget(self.fwd_button, 2, 1)
        self.angle_spin = QDoubleSpinBox()
        self.angle_spin.setRange(-999.99, 999.99)  # the MOV value field: 5 digits of 0.01 deg
        self.angle_spin.setDecimals(2)
        self.angle_spin.setValue(90.0)
        self.angle_spin.setSuffix(" °")
        self.angle_spin.setToolTip("Output angle to move by (+ = FWD), at the speed above")
        self.move_button = QPushButton("Move by")
        self.move_button.setToolTip("Move the output by the angle (+ = FWD) at the speed, then hold")
        grid.addWidget(self.move_button, 3, 0)
        grid.addWidget(self.angle_spin, 3, 1)
        self.stop_button = StopButton()
        if window_stop is not None:
            self.stop_button.follow(window_stop)
        else:  # a panel outside a window: STOP goes to the drive itself
            self.stop_button.clicked.connect(link.stop_now)
        grid.addWidget(self.stop_button, 4, 0, 1, 2)
        self.message = QLabel("")
        self.message.setObjectName("jogPanelMessage")
        self.message.setWordWrap(True)
        grid.addWidget(self.message, 5, 0, 1, 2)
        grid.setColumnStretch(0, 1)
        grid.setColumnStretch(1, 1)

        self.servo_on_button.clicked.connect(lambda: self.link.send(Cmd.SERVO, True))
        self.servo_off_button.clicked.connect(lambda: self.link.send(Cmd.SERVO, False))
        self.fwd_button.sigHeld.connect(lambda: self._jog(+1))
        self.rev_button.sigHeld.connect(lambda: self._jog(-1))
        self.fwd_button.sigReleased.connect(self._released)
        self.rev_button.sigReleased.connect(self._released)
        self.move_button.clicked.connect(self.move_by)
        link.sigStatus.connect(self._on_status)
        link.sigResult.connect(self._on_result)
        self._set_enabled(link.connected, link.servo_on)

    # -- actions ----------------------------------------------------------------------------------
    def _jog(self, sign: int) -> None:
        if not self.link.servo_on:
            self.message.setText("Switch the servo ON first: nothing moves without it.")
            return
        self.link.jog_press(sign * self.speed_spin.value())

    @Slot()
    def _released(self) -> None:
        if self.link.connected:
            self.link.jog_release()

    @Slot()
    def release_jog(self) -> None:
        """Let go of a held jog (also when STOP was pressed or the panel is hidden)."""
        held = self.fwd_button.held or self.rev_button.held
        for b in (self.fwd_button, self.rev_button):
            b._held = False
            if b.isDown():
                b.setDown(False)
        if held and self.link.connected:
            self.link.jog_release()

    @Slot()
    def move_by(self) -> None:
        if not self.link.servo_on:
            self.message.setText("Switch the servo ON first: nothing moves without it.")
            return
        self.link.send(Cmd.SET_MOVE_SPEED, self.speed_spin.value())
        self.link.send(Cmd.MOVE_BY, self.angle_spin.value())

    # -- from the link ----------------------------------------------------------------------------
    def _set_enabled(self, connected: bool, servo_on: bool) -> None:
        can_move = connected and bool(self.link.info and self.link.info.can_move)
        self.servo_on_button.setEnabled(can_move and not servo_on)
        self.servo_off_button.setEnabled(can_move and servo_on)
        for w in (self.fwd_button, self.rev_button, self.move_button, self.speed_spin, self.angle_spin):
            w.setEnabled(can_move and servo_on)
        if not connected:
            reason = NOT_CONNECTED_TEXT
        elif not can_move:
            reason = CANNOT_MOVE_TEXT
        else:
            reason = "" if servo_on else SERVO_OFF_TEXT
        if reason or self.message.text() in (NOT_CONNECTED_TEXT, CANNOT_MOVE_TEXT, SERVO_OFF_TEXT):
            self.message.setText(reason)
        if not connected:
            self.servo_lamp.set_state(None)

    def link_connected(self, info: LinkInfo) -> None:
        self._set_enabled(True, False)

    def link_disconnected(self) -> None:
        self.release_jog()
        self._set_enabled(False, False)

    @Slot(object)
    def _on_status(self, status: DriveStatus) -> None:
        self._set_enabled(self.link.connected, bool(status.servo_on))
        self.servo_lamp.set_state(status.servo_on)

    @Slot(object)
    def _on_result(self, result: CommandResult) -> None:
        if result.cmd in (Cmd.JOG, Cmd.MOVE_BY, Cmd.SERVO, Cmd.SET_MOVE_SPEED) and not result.ok:
            self.message.setText(f"The drive refused: {result.error}")
            if result.cmd is Cmd.JOG:
                self.release_jog()

    def changeEvent(self, event) -> None:
        # a held jog stops when the window loses activation (another window, a dialog)
        if (event.type() == QEvent.Type.ActivationChange and not self.isActiveWindow()
                and (self.fwd_button.held or self.rev_button.held)):
            self.release_jog()
        super().changeEvent(event)
