"""The scope's trigger tab: what a drive-side trace captures and when, Arm / Cancel, its state."""

from __future__ import annotations

from collections.abc import Sequence

from PySide6.QtCore import Signal
from PySide6.QtWidgets import (
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSpinBox,
    QWidget,
)

from fha_studio.hardware import protocol as p
from fha_studio.hardware.parameters import MonitorItem
from fha_studio.logic.scope.acquisition import TraceSettings, Trigger
from fha_studio.logic.scope.channels import ScopeChannel
from fha_studio.logic.wording import unit_words

TRIGGERS = (
    ("Immediate", p.TriggerKind.IMMEDIATE),
    ("Level rises through", p.TriggerKind.RISING_LEVEL),
    ("Level falls through", p.TriggerKind.FALLING_LEVEL),
    ("I/O bit rises", p.TriggerKind.IO_BIT_RISES),
    ("I/O bit falls", p.TriggerKind.IO_BIT_FALLS),
    ("Alarm", p.TriggerKind.ALARM),
)
DEFAULT_TRACE_CHANNELS = ("feedback_position", "command_position", "output_speed", "motor_current")
_LEVELS = (p.TriggerKind.RISING_LEVEL, p.TriggerKind.FALLING_LEVEL)
_EDGES = (p.TriggerKind.IO_BIT_RISES, p.TriggerKind.IO_BIT_FALLS)


class TriggerPanel(QWidget):
    """Trace channels, rate, length, pre-trigger and trigger; ``trace_settings()`` reads them."""

    sigArm = Signal()
    sigCancel = Signal()

    def __init__(self, channels: Sequence[ScopeChannel], parent=None):
        super().__init__(parent)
        form = QFormLayout(self)
        self.trace_channels: list[QComboBox] = []
        for k in range(p.TRACE_MAX_CHANNELS):
            box = QComboBox()
            self.trace_channels.append(box)
            form.addRow(f"Channel {k + 1}", box)
        self.trace_rate = QDoubleSpinBox()
        self.trace_rate.setRange(1.0, 5000.0)
        self.trace_rate.setDecimals(0)
        self.trace_rate.setValue(1000.0)
        self.trace_rate.setSuffix(" Hz")
        form.addRow("Sample rate", self.trace_rate)
        self.trace_samples = QSpinBox()
        self.trace_samples.setRange(16, p.TRACE_MAX_SAMPLES)
        self.trace_samples.setValue(2048)
        form.addRow("Samples", self.trace_samples)
        self.trace_pre = QSpinBox()
        self.trace_pre.setRange(0, 90)
        self.trace_pre.setValue(10)
        self.trace_pre.setSuffix(" %")
        form.addRow("Pre-trigger", self.trace_pre)
        self.trigger_kind = QComboBox()
        for text, kind in TRIGGERS:
            self.trigger_kind.addItem(text, kind)
        self.trigger_kind.currentIndexChanged.connect(self._trigger_kind_changed)
        form.addRow("Trigger", self.trigger_kind)
        self.trigger_channel = QComboBox()
        form.addRow("on", self.trigger_channel)
        self.trigger_level = QDoubleSpinBox()
        self.trigger_level.setRange(-1e6, 1e6)
        self.trigger_level.setDecimals(3)
        form.addRow("Level", self.trigger_level)
        row = QHBoxLayout()
        self.arm_button = QPushButton("Arm")
        self.arm_button.clicked.connect(self.sigArm)
        cancel = QPushButton("Cancel")
        cancel.clicked.connect(self.sigCancel)
        row.addWidget(self.arm_button)
        row.addWidget(cancel)
        form.addRow(row)
        self.trace_state = QLabel("idle")
        self.trace_state.setObjectName("scopeTraceState")
        self.trace_state.setWordWrap(True)
        form.addRow("State", self.trace_state)
        self.set_channels(channels)

    def set_channels(self, channels: Sequence[ScopeChannel]) -> None:
        """The channels a trace may capture (another actuator changes their scales)."""
        self._channels = list(channels)
        bits = [c for c in channels if c.is_bit]
        bits.append(ScopeChannel("moving", "Moving", "bit", MonitorItem.IO_STATE, 1.0, p.IoBit.MOVING))
        self._bits = bits
        analog = [c for c in channels if not c.is_bit]
        for k, box in enumerate(self.trace_channels):
            wanted = box.currentData() if box.count() else DEFAULT_TRACE_CHANNELS[k]
            box.clear()
            box.addItem("—", None)
            for c in analog + [c for c in bits if c.key != "moving"]:
                box.addItem(c.name, c.key)
            box.setCurrentIndex(max(0, box.findData(wanted)))
        self._trigger_kind_changed()

    def _trigger_kind_changed(self, *_args) -> None:
        kind = self.trigger_kind.currentData()
        wanted = self.trigger_channel.currentData()
        self.trigger_channel.clear()
        if kind in _LEVELS:
            for c in self._channels:
                if not c.is_bit:
                    self.trigger_channel.addItem(f"{c.name} [{unit_words(c.unit)}]", c.key)
        elif kind in _EDGES:
            for c in self._bits:
                self.trigger_channel.addItem(c.name, c.key)
        if wanted is not None and self.trigger_channel.findData(wanted) >= 0:
            self.trigger_channel.setCurrentIndex(self.trigger_channel.findData(wanted))
        self.trigger_channel.setEnabled(self.trigger_channel.count() > 0)
        self.trigger_level.setEnabled(kind in _LEVELS)

    def trace_settings(self) -> TraceSettings:
        by_key = {c.key: c for c in self._channels + self._bits}
        keys = [b.currentData() for b in self.trace_channels if b.currentData()]
        channels = tuple(by_key[k] for k in dict.fromkeys(keys))
        kind = self.trigger_kind.currentData()
        trigger_channel = by_key.get(self.trigger_channel.currentData())
        samples = self.trace_samples.value()
        return TraceSettings(channels, self.trace_rate.value(), samples,
                             min(samples - 1, samples * self.trace_pre.value() // 100),
                             Trigger(kind, trigger_channel, self.trigger_level.value()))

    def set_state(self, text: str) -> None:
        self.trace_state.setText(text)
        self.trace_state.setToolTip(text)
