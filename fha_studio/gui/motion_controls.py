"""The controls that move an axis: servo ON/OFF, hold-to-run REV/FWD at a speed, move by an angle,
and (where the window's toolbar is not beside them) STOP. One widget, shown by the Jog page and,
docked beside the plot, by the scope's Move panel, so both move the axis by the same rules:

- jog is hold-to-run: a jog goes out while a button is held (the link worker repeats it only while
  the GUI renews the lease) and stops on release, focus loss, dragging off the button, hiding,
  disabling, or when the window loses activation;
- nothing moves without servo ON, and the controls say why they are disabled;
- STOP is always reachable: the toolbar's STOP (Esc) on every page, and the panel's STOP is a
  second view of it (``StopButton.follow``);
- on a drive that answers only its manual's commands (no servo, jog or moves over CN3) every
  control is disabled and says where motion comes from (CN2)."""

from __future__ import annotations

from enum import Enum

from PySide6.QtCore import QEvent, Signal, Slot
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

from fha_studio.gui.link import (
    DriveStatus,
    Jog,
    LinkController,
    LinkInfo,
    LinkReply,
    MoveBy,
    Servo,
    SetMoveSpeed,
)
from fha_studio.gui.widgets import AMBER, Lamp, StopButton

#: Why the controls are disabled, one reason at a time.
NOT_CONNECTED_TEXT = "No drive connected."
CANNOT_MOVE_TEXT = ("This drive answers only the documented CN3 commands: servo, jog and moves come "
                    "from its CN2 connector, not from FHA Studio.")
SERVO_OFF_TEXT = "Servo OFF: switch it ON to jog or move."
SERVO_FIRST_TEXT = "Switch the servo ON first: nothing moves without it."
_REASONS = (NOT_CONNECTED_TEXT, CANNOT_MOVE_TEXT, SERVO_OFF_TEXT, SERVO_FIRST_TEXT)

HOLD_TIP = "Hold (mouse or Space key) to jog; release to stop"
MOVE_TIP = "Move the output by the angle (+ = FWD) at the speed, then hold"


class HoldButton(QPushButton):
    """A hold-to-run button: `sigHeld` on press, `sigReleased` on release or when it loses the
    mouse or the keyboard focus, is hidden (its page left) or disabled, or its window is no longer
    the active one (so that a jog, or the Tuning page's excitation, never outlives the finger on
    the button)."""

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
        """Let go, as the finger leaving the button does (`sigReleased` if it was held)."""
        if self.isDown():
            self.setDown(False)
        self._release()

    def event(self, event) -> bool:
        if event.type() in (
            QEvent.Type.FocusOut,
            QEvent.Type.Hide,
            QEvent.Type.EnabledChange,
            QEvent.Type.Leave,  # dragging off the button stops, as letting go does
            QEvent.Type.WindowDeactivate,  # another window or a dialog came to the front
        ):
            self.release()
        return super().event(event)


class MotionLayout(Enum):
    """How the controls are laid out; what they do is the same."""

    #: The Jog page: servo, jog and move each in a box, Alt+letters, a speed of its own for moves;
    #: STOP is the toolbar's above the page.
    PAGE = "page"
    #: Docked beside a plot (the scope): one compact box, one speed for jog and move, no Alt+letters
    #: (the page around it has its own), a STOP of its own that follows the window's.
    PANEL = "panel"


def _speed_spin(value_rpm: float, tip: str) -> QDoubleSpinBox:
    spin = QDoubleSpinBox()
    spin.setDecimals(1)
    spin.setRange(0.1, 100.0)
    spin.setValue(value_rpm)
    spin.setSuffix(" r/min")
    spin.setToolTip(tip)
    return spin


def _angle_spin() -> QDoubleSpinBox:
    spin = QDoubleSpinBox()
    spin.setRange(-999.99, 999.99)  # the MOV value field: 5 digits of 0.01 deg
    spin.setDecimals(2)
    spin.setValue(90.0)
    spin.setSuffix(" °")
    spin.setToolTip("Output angle to move by (+ = FWD)")
    return spin


class MotionControls(QWidget):
    """Servo ON/OFF, hold-to-run REV/FWD at a speed, move by an angle (and STOP in a panel).

    ``window_stop``: the window's STOP (its toolbar's), which a panel's STOP follows: the same
    words, and what it does (the main window's ``stop_axis`` releases every held jog too; a
    machine window's stops every axis). Without one a panel's STOP goes to the link itself.
    The page around the controls passes on ``link_connected`` and ``link_disconnected``."""

    def __init__(self, link: LinkController, window_stop: StopButton | None = None,
                 layout: MotionLayout = MotionLayout.PAGE, parent: QWidget | None = None):
        super().__init__(parent)
        self.link = link
        self.motion_layout = layout
        page = layout is MotionLayout.PAGE

        def words(text: str) -> str:  # Alt+letters on the page only
            return text if page else text.replace("&", "")

        self.servo_on_button = QPushButton(words("Servo &ON"))
        self.servo_off_button = QPushButton(words("Servo O&FF"))
        self.servo_lamp = Lamp("Servo", AMBER)
        self.rev_button = HoldButton(words("◀  &REV"))
        self.fwd_button = HoldButton(words("F&WD  ▶"))
        for b in (self.rev_button, self.fwd_button):
            b.setMinimumHeight(56 if page else 36)
            b.setToolTip(HOLD_TIP)
        self.angle_spin = _angle_spin()
        self.move_button = QPushButton(words("&Move"))
        self.move_button.setToolTip(MOVE_TIP)
        self.message = QLabel("")
        self.message.setWordWrap(True)
        self.stop_button: StopButton | None = None
        outer = QVBoxLayout(self)
        outer.setContentsMargins(0, 0, 0, 0)
        if page:
            self.speed_spin = _speed_spin(5.0, "Output speed while a jog button is held (output side, r/min)")
            self.move_speed_spin = _speed_spin(10.0, "Output speed of a move (output side, r/min)")
            self._lay_out_page(outer)
        else:
            self.speed_spin = _speed_spin(5.0, "Output speed of a jog and of a move (output side, r/min)")
            self.move_speed_spin = self.speed_spin  # one speed for both in the compact panel
            self.stop_button = StopButton()
            if window_stop is not None:
                self.stop_button.follow(window_stop)
            else:  # a panel outside a window: STOP goes to the drive itself
                self.stop_button.clicked.connect(link.stop_now)
            self._lay_out_panel(outer)

        self.servo_on_button.clicked.connect(lambda: self.link.send(Servo(True), self._on_reply))
        self.servo_off_button.clicked.connect(lambda: self.link.send(Servo(False), self._on_reply))
        self.fwd_button.sigHeld.connect(lambda: self._jog(+1))
        self.rev_button.sigHeld.connect(lambda: self._jog(-1))
        self.fwd_button.sigReleased.connect(self._released)
        self.rev_button.sigReleased.connect(self._released)
        self.move_button.clicked.connect(self.move_by)
        link.sigStatus.connect(self._on_status)
        self._set_enabled(link.connected, link.servo_on)

    def _lay_out_page(self, outer: QVBoxLayout) -> None:
        servo_box = QGroupBox("Servo")
        s_layout = QHBoxLayout(servo_box)
        for w in (self.servo_on_button, self.servo_off_button, self.servo_lamp):
            s_layout.addWidget(w)
        s_layout.addStretch(1)
        s_layout.addWidget(QLabel("Nothing moves without an explicit servo ON."))
        outer.addWidget(servo_box)

        jog_box = QGroupBox("Jog (hold to run, release to stop)")
        j_layout = QGridLayout(jog_box)
        speed_label = QLabel("Jog &speed:")
        speed_label.setBuddy(self.speed_spin)
        j_layout.addWidget(speed_label, 0, 0)
        j_layout.addWidget(self.speed_spin, 0, 1)
        j_layout.addWidget(self.rev_button, 1, 0)
        j_layout.addWidget(self.fwd_button, 1, 1)
        outer.addWidget(jog_box)

        move_box = QGroupBox("Move by an angle")
        m_layout = QFormLayout(move_box)
        m_layout.addRow("&Angle (output, + = FWD):", self.angle_spin)
        m_layout.addRow("Sp&eed:", self.move_speed_spin)
        m_layout.addRow(self.move_button)
        outer.addWidget(move_box)
        outer.addWidget(self.message)

    def _lay_out_panel(self, outer: QVBoxLayout) -> None:
        assert self.stop_button is not None
        box = QGroupBox("Move (hold to jog)")
        box.setObjectName("jogPanel")
        self.message.setObjectName("jogPanelMessage")
        grid = QGridLayout(box)
        grid.setContentsMargins(6, 6, 6, 6)
        grid.setVerticalSpacing(4)
        servo_row = QHBoxLayout()
        for w in (self.servo_on_button, self.servo_off_button, self.servo_lamp):
            servo_row.addWidget(w)
        grid.addLayout(servo_row, 0, 0, 1, 2)
        grid.addWidget(QLabel("Speed"), 1, 0)
        grid.addWidget(self.speed_spin, 1, 1)
        grid.addWidget(self.rev_button, 2, 0)
        grid.addWidget(self.fwd_button, 2, 1)
        self.move_button.setText("Move by")
        grid.addWidget(self.move_button, 3, 0)
        grid.addWidget(self.angle_spin, 3, 1)
        grid.addWidget(self.stop_button, 4, 0, 1, 2)
        grid.addWidget(self.message, 5, 0, 1, 2)
        grid.setColumnStretch(0, 1)
        grid.setColumnStretch(1, 1)
        outer.addWidget(box)

    # -- actions ----------------------------------------------------------------------------------
    @property
    def jog_held(self) -> bool:
        return self.fwd_button.held or self.rev_button.held

    def _jog(self, sign: int) -> None:
        if not self.link.servo_on:
            self.message.setText(SERVO_FIRST_TEXT)
            return
        if self.message.text() == SERVO_FIRST_TEXT:
            self.message.setText("")
        self.link.jog_press(sign * self.speed_spin.value(), self._on_reply)

    @Slot()
    def _released(self) -> None:
        if self.link.connected:
            self.link.jog_release()

    @Slot()
    def release_jog(self) -> None:
        """Let go of a held jog (also when STOP was pressed, the link went, or the page closes)."""
        for b in (self.fwd_button, self.rev_button):
            b.release()  # a held one says so: the jog is released once per button held

    @Slot()
    def move_by(self) -> None:
        if not self.link.servo_on:
            self.message.setText(SERVO_FIRST_TEXT)
            return
        self.link.send(SetMoveSpeed(self.move_speed_spin.value()), self._on_reply)
        self.link.send(MoveBy(self.angle_spin.value()), self._on_reply)

    # -- from the link ----------------------------------------------------------------------------
    def _set_enabled(self, connected: bool, servo_on: bool) -> None:
        can_move = connected and bool(self.link.info and self.link.info.can_move)
        self.servo_on_button.setEnabled(can_move and not servo_on)
        self.servo_off_button.setEnabled(can_move and servo_on)
        for w in (self.fwd_button, self.rev_button, self.move_button, self.speed_spin,
                  self.move_speed_spin, self.angle_spin):
            w.setEnabled(can_move and servo_on)
        if not connected:
            reason = NOT_CONNECTED_TEXT
        elif not can_move:
            reason = CANNOT_MOVE_TEXT
        else:
            reason = "" if servo_on else SERVO_OFF_TEXT
        if reason or self.message.text() in _REASONS:
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

    def _on_reply(self, result: LinkReply) -> None:
        """The reply to one of these controls' requests: a refusal is said under them."""
        if not result.ok:
            self.message.setText(f"The drive refused: {result.error}")
            if isinstance(result.request, Jog):
                self.release_jog()
        elif isinstance(result.request, Servo) and self.message.text().startswith("The drive refused"):
            self.message.setText("")

    def changeEvent(self, event) -> None:
        # a held jog stops when the window loses activation (another window, a dialog)
        if event.type() == QEvent.Type.ActivationChange and not self.isActiveWindow() and self.jog_held:
            self.release_jog()
        super().changeEvent(event)


__all__ = ["HoldButton", "MotionControls", "MotionLayout"]
