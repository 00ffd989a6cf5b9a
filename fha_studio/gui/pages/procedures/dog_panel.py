"""The sensor-dog wizard panel (option L, FHA-C manual 4-7-2 / 4-7-3): the output angle and the three
sensors live, slow jog and move buttons that refuse to pass the movable range, and on the
simulated drive the dogs and the origin disk can be turned (as by hand on a real actuator)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from PySide6.QtCore import Signal, Slot
from PySide6.QtWidgets import (
    QCheckBox,
    QDoubleSpinBox,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from fha_studio.gui.link import Call, DriveStatus, LinkReply, MoveBy, Servo, SetInputs, SetMoveSpeed
from fha_studio.gui.widgets import AMBER, Lamp
from fha_studio.hardware.api import IoState
from fha_studio.logic.procedures.sensor_dogs import SENSOR_NAMES, MoveRefused, SensorDogWizard

#: Output speed of the jog buttons (r/min): low, as 4-7-2 (4) asks for finding the origin.
JOG_SPEED_RPM = 1.0
MOVE_SPEED_RPM = 2.0
_DOG_OF = {"limit_switch_1": "ls1", "limit_switch_2": "ls2", "origin_sensor": "origin"}


class SensorDogPanel(QWidget):
    """Live sensors and output angle for one sensor_angle step; ``sigRecord(angle)`` records it."""

    sigRecord = Signal(float)
    sigMessage = Signal(str)

    def __init__(self, link, parent: QWidget | None = None):
        super().__init__(parent)
        self.link = link
        self.wizard: SensorDogWizard | None = None
        self.output_ppr = 0
        self.sensor = "limit_switch_2"
        self._jogging = 0
        self.watching = True  # the drive reports its inputs (else the angle comes from DGR)
        layout = QVBoxLayout(self)

        live = QGroupBox("Live")
        grid = QGridLayout(live)
        self.angle_label = QLabel("Output angle: —")
        self.angle_label.setObjectName("output_angle")
        grid.addWidget(self.angle_label, 0, 0, 1, 3)
        self.lamps = {
            "limit_switch_1": Lamp("LS1 (CCW end)", AMBER),
            "origin_sensor": Lamp("Origin"),
            "limit_switch_2": Lamp("LS2 (CW end)", AMBER),
        }
        for column, lamp in enumerate(self.lamps.values()):
            grid.addWidget(lamp, 1, column)
        self.range_label = QLabel("")
        self.range_label.setWordWrap(True)
        grid.addWidget(self.range_label, 2, 0, 1, 3)
        layout.addWidget(live)

        motion = QGroupBox("Move the output (slowly)")
        m = QHBoxLayout(motion)
        self.jog_ccw_button = QPushButton("◀ Jog CCW")
        self.jog_cw_button = QPushButton("Jog CW ▶")
        self.jog_ccw_button.pressed.connect(lambda: self.jog(-1))
        self.jog_cw_button.pressed.connect(lambda: self.jog(+1))
        self.jog_ccw_button.released.connect(self.release)
        self.jog_cw_button.released.connect(self.release)
        self.target_spin = QDoubleSpinBox()
        self.target_spin.setRange(-360.0, 360.0)
        self.target_spin.setDecimals(2)
        self.target_spin.setSuffix(" °")
        self.move_button = QPushButton("Move to")
        self.move_button.clicked.connect(lambda: self.move_to(self.target_spin.value()))
        for w in (self.jog_ccw_button, self.jog_cw_button, QLabel("or"), self.target_spin, self.move_button):
            m.addWidget(w)
        self.motion_reason = QLabel("")
        self.motion_reason.setObjectName("motion_reason")
        self.motion_reason.setWordWrap(True)
        self.motion_reason.setStyleSheet("color: #8a5a00;")
        m.addWidget(self.motion_reason, 1)
        layout.addWidget(motion)

        self.sim_box = QGroupBox("Simulated actuator: turn the dog / disk by hand")
        s = QHBoxLayout(self.sim_box)
        self.brake_check = QCheckBox("Brake 24 V on (released)")
        self.brake_check.toggled.connect(self._brake_toggled)
        self.set_dog_button = QPushButton("Set it to switch here")
        self.set_dog_button.setToolTip(
            "Turn the dog (or the origin disk) so that its sensor switches at the present angle"
        )
        self.set_dog_button.clicked.connect(self.set_dog_here)
        s.addWidget(self.brake_check)
        s.addWidget(self.set_dog_button)
        layout.addWidget(self.sim_box)

        record_row = QHBoxLayout()
        self.found_label = QLabel("Not switched yet")
        self.found_label.setObjectName("found_angle")
        self.record_button = QPushButton("Record this angle")
        self.record_button.setObjectName("record_angle")
        self.record_button.clicked.connect(self.record)
        record_row.addWidget(self.found_label, 1)
        record_row.addWidget(self.record_button)
        layout.addLayout(record_row)
        # A drive that reports no position (a real HA-655 with the servo on answers nothing on CN3):
        # the angle read elsewhere (the controller, a scale on the flange) is typed in.
        typed_row = QHBoxLayout()
        self.typed_spin = QDoubleSpinBox()
        self.typed_spin.setRange(-360.0, 360.0)
        self.typed_spin.setDecimals(2)
        self.typed_spin.setSuffix(" °")
        self.typed_button = QPushButton("Record the typed angle")
        self.typed_button.clicked.connect(lambda: self.sigRecord.emit(self.typed_spin.value()))
        typed_row.addWidget(QLabel("Angle read elsewhere:"))
        typed_row.addWidget(self.typed_spin)
        typed_row.addWidget(self.typed_button)
        layout.addLayout(typed_row)
        layout.addStretch(1)
        link.sigStatus.connect(self.on_status)
        self.ratio = 0

    # -- set up for a step --------------------------------------------------------------------
    def start(self, sensor: str, context: Mapping[str, Any]) -> None:
        """Watch for ``sensor`` (limit_switch_1, limit_switch_2, origin_sensor) on this actuator."""
        previous = self.wizard
        self.wizard = SensorDogWizard.for_context(context)
        if previous is not None and previous.angle_deg is not None:
            self.wizard.observe(previous.angle_deg, previous.states)
        self.output_ppr = int(context["actuator"]["output_resolution_ppr"])
        self.sensor = sensor
        self.range_label.setText(
            f"Movable range {self.wizard.ccw_limit_deg:+g}° … {self.wizard.cw_limit_deg:+g}° (4-7-3): "
            "moves past it are refused."
        )
        self.ratio = int(context["actuator"].get("ratio", 0) or 0)
        info = self.link.info
        self.sim_box.setVisible(bool(info and info.is_simulated))
        self.watching = bool(info and info.can_monitor)
        can_move = bool(info and info.can_move)
        for button in (self.jog_ccw_button, self.jog_cw_button, self.move_button):
            button.setEnabled(can_move)
        self.motion_reason.setText(
            "" if can_move else "This drive takes no motion commands over CN3: with the servo off, turn "
            "the axis by hand (or move it from the controller)."
        )
        if self.watching:
            self.found_label.setText(f"Watching {SENSOR_NAMES[sensor]}: not switched yet")
            self.record_button.setText("Record this angle")
        else:
            for lamp in self.lamps.values():
                lamp.set_state(None)
            self.angle_label.setText("Output angle: not reported over CN3 (read it with DGR)")
            self.found_label.setText(
                f"This drive does not report its inputs over CN3: watch the indicator of "
                f"{SENSOR_NAMES[sensor]} (or the controller's input) while you turn the axis by hand, "
                "stop where it switches, then record: the angle comes from the absolute position (DGR)."
            )
            self.found_label.setWordWrap(True)
            self.record_button.setText("Record the angle here (DGR)")

    # -- live ---------------------------------------------------------------------------------
    @Slot(object)
    def on_status(self, status: DriveStatus) -> None:
        if (
            self.wizard is None
            or status.position_pulse is None
            or status.io_bits is None
            or not self.output_ppr
        ):
            return
        angle = status.position_pulse * 360.0 / self.output_ppr
        self.observe(angle, status.io_bits)

    def observe(self, angle_deg: float, io_bits: int) -> None:
        io = IoState(io_bits)
        states = {
            "limit_switch_1": io.limit_switch_1,
            "limit_switch_2": io.limit_switch_2,
            "origin_sensor": io.origin_sensor,
        }
        switched = self.wizard.observe(angle_deg, states)
        self.angle_label.setText(f"Output angle: {angle_deg:+.2f}°")
        for name, lamp in self.lamps.items():
            lamp.set_state(states[name])
        if self.brake_check.isVisible():
            self.brake_check.blockSignals(True)
            self.brake_check.setChecked(io.brake_released)
            self.brake_check.blockSignals(False)
        if self.sensor in switched:
            self.found_label.setText(f"{SENSOR_NAMES[self.sensor]} switched on at {angle_deg:+.2f}°")
        if self._jogging:
            try:
                self.wizard.check_jog(self._jogging)
            except MoveRefused as exc:
                self.release()
                self.sigMessage.emit(str(exc))

    # -- motion -------------------------------------------------------------------------------
    def jog(self, direction: int) -> None:
        try:
            if self.wizard is None:
                raise MoveRefused("no sensor step is open")
            self.wizard.check_jog(direction)
        except MoveRefused as exc:
            self.sigMessage.emit(str(exc))
            return
        if not self.link.servo_on:
            self.link.send(Servo(True))
        self._jogging = direction
        self.link.jog_press(direction * JOG_SPEED_RPM)

    def release(self) -> None:
        if self._jogging:
            self._jogging = 0
            self.link.jog_release()

    def move_to(self, target_deg: float) -> bool:
        """Move the output to ``target_deg`` at low speed; False (and a message) when refused."""
        try:
            if self.wizard is None or self.wizard.angle_deg is None:
                raise MoveRefused("the output angle is not known yet")
            self.wizard.check_move(target_deg)
        except MoveRefused as exc:
            self.sigMessage.emit(str(exc))
            return False
        if not self.link.servo_on:
            self.link.send(Servo(True))
        self.link.send(SetMoveSpeed(MOVE_SPEED_RPM))
        self.link.send(MoveBy(target_deg - self.wizard.angle_deg))
        return True

    # -- simulated drive ----------------------------------------------------------------------
    @Slot(bool)
    def _brake_toggled(self, on: bool) -> None:
        self.link.send(SetInputs({"brake_released": on}))

    def set_dog_here(self) -> None:
        """Simulated drive: turn the dog (or disk) of the watched sensor to the present angle."""
        if self.wizard is None or self.wizard.angle_deg is None:
            return
        which, angle = _DOG_OF[self.sensor], self.wizard.angle_deg
        self.link.send(Call(lambda client: client.set_sensor_angle(which, angle)))

    # -- record -------------------------------------------------------------------------------
    def found_angle(self) -> float | None:
        """The angle to record: where the sensor last switched on, else now if it is on now."""
        if self.wizard is None:
            return None
        found = self.wizard.found(self.sensor)
        if found is None and self.wizard.states.get(self.sensor) and self.wizard.angle_deg is not None:
            found = self.wizard.angle_deg
        return found

    def record(self) -> None:
        if not self.watching:
            self._record_from_dgr()
            return
        angle = self.found_angle()
        if angle is None:
            self.sigMessage.emit(f"{SENSOR_NAMES[self.sensor]} has not switched on yet: nothing to record")
            return
        self.sigRecord.emit(angle)

    def _record_from_dgr(self) -> None:
        """A drive that does not report its inputs: the technician stopped where the sensor
        switched; DGR (servo off) gives the angle, recorded like a live one."""
        if not self.ratio:
            self.sigMessage.emit("The actuator's ratio is not known: the counts cannot become an angle")
            return
        self.link.send(Call(lambda client: client.absolute_position()), self._dgr_answered)

    def _dgr_answered(self, result: LinkReply[int]) -> None:
        if not result.ok:
            from fha_studio.gui.link import SERVO_ON_NOTE
            from fha_studio.hardware.api import ServoOnRefused

            why = SERVO_ON_NOTE if result.failed_with(ServoOnRefused) else result.error
            self.sigMessage.emit(f"The angle could not be read: {why}. Enter an angle read elsewhere below.")
            return
        from fha_studio.logic.absolute import output_deg, wrap_deg

        angle = wrap_deg(output_deg(result.answer, self.ratio))
        self.angle_label.setText(f"Output angle (DGR, servo off): {angle:+.2f}°")
        self.sigRecord.emit(angle)

    def shutdown(self) -> None:
        self.release()
