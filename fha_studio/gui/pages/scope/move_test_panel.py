"""The scope's Tests tab: move and step tests with their results, and what recordings record."""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from fha_studio.gui.unit_spacing import units_kept
from fha_studio.logic.scope.acquisition import MoveTestResult
from fha_studio.logic.wording import plain_number, unit_words, with_unit

RESULTS = (("overshoot", "Overshoot"), ("rise", "Rise time 10-90 %"), ("settling", "Settling time"),
           ("in_position", "In-position after command end"), ("final_error", "Final error"),
           ("method", "Captured by"))


def _ms(seconds: float | None) -> str:
    return "not reached" if seconds is None else f"{seconds * 1000:.1f} ms"


class MoveTestPanel(QWidget):
    """Move by / speed / step, the buttons, the result table, the actuator and load inertia."""

    sigRun = Signal(str)  # "move" or "step"
    sigAbort = Signal()

    def __init__(self, actuator: str, max_speed_rpm: float, load_inertia_kgm2: float, parent=None):
        super().__init__(parent)
        lay = QVBoxLayout(self)
        form = QFormLayout()
        self.test_angle = QDoubleSpinBox()
        self.test_angle.setRange(-3600.0, 3600.0)
        self.test_angle.setDecimals(2)
        self.test_angle.setValue(90.0)
        self.test_angle.setSuffix(unit_words("deg"))
        form.addRow("Move by", self.test_angle)
        self.test_speed = QDoubleSpinBox()
        self.test_speed.setRange(0.1, max_speed_rpm)
        self.test_speed.setValue(min(30.0, max_speed_rpm))
        self.test_speed.setSuffix(" r/min")
        form.addRow("Speed", self.test_speed)
        self.step_angle = QDoubleSpinBox()
        self.step_angle.setRange(-10.0, 10.0)
        self.step_angle.setDecimals(3)
        self.step_angle.setValue(0.5)
        self.step_angle.setSuffix(unit_words("deg"))
        form.addRow("Step", self.step_angle)
        lay.addLayout(form)
        row = QHBoxLayout()
        self.move_test_button = QPushButton("Move test")
        self.move_test_button.clicked.connect(lambda: self.sigRun.emit("move"))
        self.step_test_button = QPushButton("Step test")
        self.step_test_button.clicked.connect(lambda: self.sigRun.emit("step"))
        abort = QPushButton("Abort")
        abort.clicked.connect(self.sigAbort)
        for b in (self.move_test_button, self.step_test_button, abort):
            row.addWidget(b)
        lay.addLayout(row)
        box = QGroupBox("Result")
        res = QFormLayout(box)
        res.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapLongRows)  # fits the side panel's width
        self.result_labels: dict[str, QLabel] = {}
        for key, text in RESULTS:
            label = QLabel("—")
            label.setObjectName(f"scopeResult_{key}")
            label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
            label.setWordWrap(True)
            self.result_labels[key] = label
            res.addRow(text, label)
        lay.addWidget(box)
        files = QGroupBox("Recordings")
        ff = QFormLayout(files)
        ff.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapLongRows)
        self.actuator_label = QLabel(actuator)
        self.actuator_label.setWordWrap(True)
        ff.addRow("Actuator", self.actuator_label)
        self.load_inertia = QDoubleSpinBox()
        self.load_inertia.setObjectName("scopeLoadInertia")
        self.load_inertia.setRange(0.0, 1e4)
        self.load_inertia.setDecimals(4)
        self.load_inertia.setKeyboardTracking(False)
        self.load_inertia.setValue(load_inertia_kgm2)
        self.load_inertia.setSuffix(" kg·m²")
        self.load_inertia.setToolTip("The declared load inertia of the axis, written into recordings (the "
                                     "model check needs it); the same value as on the Sizing and Model check "
                                     "pages")
        ff.addRow("Load inertia", self.load_inertia)
        lay.addWidget(files)
        self.test_message = QLabel("The servo must be on. The axis moves.")
        self.test_message.setWordWrap(True)
        lay.addWidget(self.test_message)
        lay.addStretch(1)

    def set_actuator(self, actuator: str, max_speed_rpm: float) -> None:
        self.actuator_label.setText(actuator)
        self.test_speed.setMaximum(max_speed_rpm)

    def angle_deg(self, kind: str) -> float:
        return self.step_angle.value() if kind == "step" else self.test_angle.value()

    def started(self, kind: str, angle_deg: float, speed_rpm: float) -> None:
        angle = with_unit(f"{angle_deg:g}", "deg")
        self._say(f"{kind} test running: {angle} at {speed_rpm:g} r/min …")
        for label in self.result_labels.values():
            label.setText("…")

    def set_message(self, text: str) -> None:
        self._say(text)

    def _say(self, text: str) -> None:
        """The tab's message line, its figures kept with their units where it wraps."""
        self.test_message.setText(units_kept(text))

    def show_result(self, result: MoveTestResult) -> None:
        m = result.metrics
        if m is None:
            for label in self.result_labels.values():
                label.setText("—")
            self._say(result.describe())
        else:
            overshoot = f"{m.overshoot_percent:.2f} % ({with_unit(plain_number(m.overshoot), 'deg')})"
            self.result_labels["overshoot"].setText(overshoot)
            self.result_labels["rise"].setText(_ms(m.rise_time_s))
            band = f" (band ±{with_unit(f'{m.settling_band:.3g}', 'deg')})"
            self.result_labels["settling"].setText(_ms(m.settling_time_s) + band)
            window = result.in_position_range_deg
            inpos = "" if window is None else f" (±{with_unit(f'{window:.3g}', 'deg')})"
            self.result_labels["in_position"].setText(_ms(m.in_position_time_s) + inpos)
            self.result_labels["final_error"].setText(with_unit(plain_number(m.final_error), "deg"))
            self._say(f"{result.kind} test of {with_unit(f'{result.angle_deg:g}', 'deg')} at "
                      f"{result.speed_rpm:g} r/min done.")
        c = result.capture
        if c is not None:
            self.result_labels["method"].setText(
                f"{'drive trace' if c.method == 'trace' else 'polling'}, {len(c.t_s)} samples"
                + (f" at {c.sample_rate_hz:.0f} Hz" if c.method == "trace" else ""))
