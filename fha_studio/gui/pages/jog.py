"""Jog and test run: servo on/off, hold-to-run FWD/REV, move by an angle (the motion controls,
`gui/motion_controls.py`, which the scope's Move panel shows too), and the live I/O of the drive."""

from __future__ import annotations

from PySide6.QtCore import QSettings, Slot
from PySide6.QtWidgets import QFormLayout, QGroupBox, QHBoxLayout, QLabel, QVBoxLayout

from fha_studio.gui.link import DriveStatus, LinkInfo
from fha_studio.gui.motion_controls import MotionControls, MotionLayout
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

#: Where the live signals are on a drive that gives none over CN3.
CN2_HINT = ("This drive gives no live signals over CN3. While the controller moves it, watch its CN2 "
            "outputs (the encoder's A/B, IN-POS, ALARM, SPD-MON) with an oscilloscope or a logic "
            "analyzer on the <i>Scope</i> page's <i>Bench</i> tab.")


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

        self.motion = MotionControls(self.link, None, MotionLayout.PAGE)
        left.addWidget(self.motion)
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
        self.current_label.setToolTip(
            "The motor current's mean over the last 10 ms. The current itself ripples by tenths of an "
            "ampere around it (the encoder's pulses); the scope shows that ripple."
        )
        self.signal_lamps: dict[IoBit, Lamp] = {}
        for bit, caption, colour in LIVE_SIGNALS:
            lamp = Lamp(caption, colour)
            self.signal_lamps[bit] = lamp
            l_layout.addRow(lamp)
        right.addWidget(live_box)
        self.cn2_hint = QLabel(CN2_HINT)
        self.cn2_hint.setObjectName("jogCn2Hint")
        self.cn2_hint.setWordWrap(True)
        self.cn2_hint.setVisible(False)
        right.addWidget(self.cn2_hint)
        stop_hint = QLabel(
            "<b>STOP</b>: the red button in the toolbar, or the <b>Esc</b> key, on every page."
        )
        stop_hint.setWordWrap(True)
        right.addWidget(stop_hint)
        right.addStretch(1)

        self.link.sigStatus.connect(self._on_status)
        self._clear_live()
        space_jogs_only(self, (self.motion.fwd_button, self.motion.rev_button))

    # -- settings ---------------------------------------------------------------------------------
    def restore_settings(self, settings: QSettings) -> None:
        motion = self.motion
        motion.speed_spin.setValue(float(str(settings.value("jog/speed_rpm", motion.speed_spin.value()))))
        motion.angle_spin.setValue(float(str(settings.value("jog/angle_deg", motion.angle_spin.value()))))
        motion.move_speed_spin.setValue(
            float(str(settings.value("jog/move_speed_rpm", motion.move_speed_spin.value())))
        )

    def save_settings(self, settings: QSettings) -> None:
        settings.setValue("jog/speed_rpm", self.motion.speed_spin.value())
        settings.setValue("jog/angle_deg", self.motion.angle_spin.value())
        settings.setValue("jog/move_speed_rpm", self.motion.move_speed_spin.value())

    # -- actions ----------------------------------------------------------------------------------
    @Slot()
    def release_held(self) -> None:
        """Let go of a held jog (STOP does it on every page)."""
        self.motion.release_jog()

    def shutdown(self) -> None:
        self.release_held()

    # -- from the link ----------------------------------------------------------------------------
    def _clear_live(self) -> None:
        for lamp in self.signal_lamps.values():
            lamp.set_state(None)

    def link_disconnected(self, reason: str, lost: bool) -> None:
        self.motion.link_disconnected()
        self._clear_live()

    def link_connected(self, info: LinkInfo) -> None:
        self.motion.link_connected(info)
        self.cn2_hint.setVisible(not info.can_monitor)  # the panel above stays empty: where to look

    @Slot(object)
    def _on_status(self, status: DriveStatus) -> None:
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
