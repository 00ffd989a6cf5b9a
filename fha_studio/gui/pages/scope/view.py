"""ScopeView: the oscilloscope a technician tunes and verifies an axis with.

A rolling live view drained by a GUI-thread QTimer from the acquisition's ring buffer (the
acquisition itself runs in the link thread, see ``driver``); a captured trace, a move test
or an opened recording is shown in the same plot, marked NOT LIVE. The indicator never calls
old data live: it checks the age of the newest sample itself on every frame.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyqtgraph as pg
from pyqtgraph import exporters
from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtWidgets import (
    QAbstractItemView,
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSpinBox,
    QSplitter,
    QTableWidget,
    QTableWidgetItem,
    QTabWidget,
    QToolBar,
    QVBoxLayout,
    QWidget,
)

from fha_studio.catalog import DEFAULT_ACTUATOR
from fha_studio.hardware import protocol as p
from fha_studio.hardware.parameters import MonitorItem, load_parameter_model
from fha_studio.logic.scope.acquisition import LiveMode, MoveTestResult, TraceResult, TraceSettings, Trigger
from fha_studio.logic.scope.analysis import cursor_delta, spectrum
from fha_studio.logic.scope.channels import ScopeChannel, scope_channels
from fha_studio.logic.scope.recorder import CONTRACT_SOURCES, ScopeRecorder
from fha_studio.recording import RecordingMetadata, read_recording

from .driver import LiveStarted, ScopeCmd, ScopeController

log = logging.getLogger(__name__)

#: Redraw period of the live view [ms] (friture: 10-50 ms).
REFRESH_MS = 25
TIME_BASES_S = (0.5, 1.0, 2.0, 5.0, 10.0, 30.0, 60.0)
DEFAULT_VISIBLE = ("feedback_position", "command_position", "output_speed", "motor_current")
COLORS = ("#f0c419", "#4fc3f7", "#81c784", "#ff8a65", "#ba68c8", "#e57373", "#90a4ae", "#aed581",
          "#ffd54f", "#4dd0e1", "#f06292", "#a1887f", "#7986cb", "#dce775", "#ffb74d", "#9575cd")
#: Indicator colours: live, not live, paused.
INDICATOR_STYLE = {
    "live": "background:#1b5e20; color:white; font-weight:bold; padding:3px 8px; border-radius:3px;",
    "not": "background:#b71c1c; color:white; font-weight:bold; padding:3px 8px; border-radius:3px;",
    "paused": "background:#e65100; color:white; font-weight:bold; padding:3px 8px; border-radius:3px;",
}
_TRIGGERS = (
    ("Immediate", p.TriggerKind.IMMEDIATE),
    ("Level rises through", p.TriggerKind.RISING_LEVEL),
    ("Level falls through", p.TriggerKind.FALLING_LEVEL),
    ("I/O bit rises", p.TriggerKind.IO_BIT_RISES),
    ("I/O bit falls", p.TriggerKind.IO_BIT_FALLS),
    ("Alarm", p.TriggerKind.ALARM),
)
# Recording columns back to scope channels (opening a file).
_COLUMN_KEYS = {column: key for column, key in CONTRACT_SOURCES.items()}


def peak_decimate(rows: np.ndarray, bins: int) -> tuple[np.ndarray, np.ndarray]:
    """At most ``2 * bins`` rows keeping each bin's minimum and maximum per channel (peak
    detection, as pyqtgraph's 'peak' mode, done once for all channels before ``setData``).

    Returns (time of each output row, rows); short inputs come back unchanged.
    """
    n = len(rows)
    if n <= 4 * bins:
        return rows[:, 0], rows
    k = n // bins
    start = n - k * bins  # keep the newest samples whole; the few oldest go
    blocks = rows[start:].reshape(bins, k, rows.shape[1])
    out = np.empty((2 * bins, rows.shape[1]))
    out[0::2] = blocks.min(axis=1)
    out[1::2] = blocks.max(axis=1)
    t = np.empty(2 * bins)
    t[0::2] = blocks[:, 0, 0]
    t[1::2] = blocks[:, -1, 0]
    return t, out


@dataclass(frozen=True)
class ScopeContext:
    """What the scope must know of the axis: the actuator (resolution, ratio) and the load."""

    actuator: str = DEFAULT_ACTUATOR
    load_inertia_kgm2: float = 0.0
    supply_voltage: int = 200
    driver: str = "HA-655"

    def actuator_data(self):
        from fha_studio.catalog import get_actuator

        return get_actuator(self.actuator)


@dataclass
class _Static:
    """Data on show that is not live: a trace, a test capture, an opened recording."""

    channels: tuple[ScopeChannel, ...]
    rows: np.ndarray  # [t_s, values...]
    label: str
    sample_rate_hz: float | None
    uniform: bool


class ScopeView(QWidget):
    """The scope page. ``controller`` carries requests to the driver in the link thread."""

    sigIndicatorChanged = Signal(str)  # the indicator text: LIVE / NOT LIVE: ... / PAUSED ...
    sigFrame = Signal()  # one live redraw done (benchmarks count these)
    sigTestDone = Signal(object)  # MoveTestResult
    sigTraceDone = Signal(object)  # TraceResult
    sigLiveChanged = Signal(bool)  # live acquisition requested on / off
    sigRecordingSaved = Signal(object, str)  # Path of a finished fha-recording/1 file, what it holds

    def __init__(self, controller: ScopeController, context: ScopeContext | None = None,
                 parent: QWidget | None = None):
        super().__init__(parent)
        self.setObjectName("scope")
        self.controller = controller
        self.context = context or ScopeContext()
        self._actuator = self.context.actuator_data()
        self.all_channels = scope_channels(load_parameter_model(self.context.driver),
                                           self._actuator.output_resolution_ppr)
        self._visible = {c.key: c.key in DEFAULT_VISIBLE for c in self.all_channels}
        self._scale = {c.key: 1.0 for c in self.all_channels}
        self._live: LiveStarted | None = None
        self._status = None  # last LiveStatus from the driver
        self._static: _Static | None = None
        self._paused = False
        self._recorder: ScopeRecorder | None = None
        self._curves: dict[str, pg.PlotDataItem] = {}
        self._indicator_text = ""
        self.frames = 0
        self._last_cursor_update = 0.0
        self._last_draw = 0.0
        self.last_test: MoveTestResult | None = None
        self.last_trace: TraceResult | None = None
        self._build()
        d = controller
        d.sigLiveStarted.connect(self._on_live_started)
        d.sigStatus.connect(self._on_status)
        d.sigTraceState.connect(self._on_trace_state)
        d.sigTraceDone.connect(self._on_trace_done)
        d.sigTestDone.connect(self._on_test_done)
        d.sigError.connect(self._on_error)
        d.sigTestState.connect(lambda text: self.test_message.setText(f"Test: {text} …"))
        self._timer = QTimer(self)
        self._timer.setInterval(REFRESH_MS)
        self._timer.timeout.connect(self._refresh)
        self._timer.start()
        self._fill_channel_table()
        self._update_indicator()

    # ------------------------------------------------------------------------------------ layout
    def _build(self) -> None:
        pg.setConfigOptions(antialias=False)
        outer = QVBoxLayout(self)
        outer.setContentsMargins(4, 4, 4, 4)
        bar = QToolBar("Scope")
        self.indicator = QLabel()
        self.indicator.setObjectName("scopeIndicator")
        self.indicator.setMinimumWidth(90)
        bar.addWidget(self.indicator)
        bar.addSeparator()
        self.live_button = QPushButton("Start live")
        self.live_button.setCheckable(True)
        self.live_button.toggled.connect(self._live_toggled)
        bar.addWidget(self.live_button)
        self.back_button = QPushButton("Back to live")
        self.back_button.setToolTip("Leave the capture or file on show and return to the live view")
        self.back_button.clicked.connect(self.back_to_live)
        bar.addWidget(self.back_button)
        self.pause_button = QPushButton("Pause")
        self.pause_button.setCheckable(True)
        self.pause_button.toggled.connect(self.set_paused)
        bar.addWidget(self.pause_button)
        bar.addWidget(QLabel(" Time base "))
        self.time_base = QComboBox()
        for tb in TIME_BASES_S:
            self.time_base.addItem(f"{tb:g} s", tb)
        self.time_base.setCurrentIndex(TIME_BASES_S.index(10.0))
        bar.addWidget(self.time_base)
        self.autoscale = QCheckBox("Autoscale Y")
        self.autoscale.setChecked(True)
        self.autoscale.toggled.connect(self._autoscale_toggled)
        bar.addWidget(self.autoscale)
        fit = QPushButton("Fit")
        fit.clicked.connect(self.fit)
        bar.addWidget(fit)
        self.cursors_box = QCheckBox("Cursors")
        self.cursors_box.toggled.connect(self._cursors_toggled)
        bar.addWidget(self.cursors_box)
        bar.addSeparator()
        self.record_button = QPushButton("Record…")
        self.record_button.setCheckable(True)
        self.record_button.clicked.connect(self._record_clicked)
        bar.addWidget(self.record_button)
        self.save_button = QPushButton("Save capture…")
        self.save_button.clicked.connect(lambda: self._ask_path("save"))
        bar.addWidget(self.save_button)
        for text, what in (("PNG…", "png"), ("CSV…", "csv"), ("Open…", "open")):
            button = QPushButton(text)
            button.clicked.connect(lambda _=False, w=what: self._ask_path(w))
            bar.addWidget(button)
        outer.addWidget(bar)

        split = QSplitter(Qt.Orientation.Horizontal)
        self.channel_table = QTableWidget(0, 3)
        self.channel_table.setObjectName("scopeChannels")
        self.channel_table.setHorizontalHeaderLabels(["Channel", "Unit", "Scale ×"])
        self.channel_table.verticalHeader().setVisible(False)
        self.channel_table.setSelectionMode(QAbstractItemView.SelectionMode.NoSelection)
        header = self.channel_table.horizontalHeader()
        header.setSectionResizeMode(0, header.ResizeMode.Stretch)
        header.setSectionResizeMode(1, header.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(2, header.ResizeMode.Fixed)
        self.channel_table.setColumnWidth(2, 78)
        self.channel_table.setMinimumWidth(300)
        self.channel_table.itemChanged.connect(self._channel_item_changed)
        split.addWidget(self.channel_table)

        self.plots = QTabWidget()
        self.plot = pg.PlotWidget()
        self.plot.setObjectName("scopePlot")
        self.plot.setBackground("#111")
        self.plot.showGrid(x=False, y=True, alpha=0.25)  # x grid only when still: scrolling it is costly
        self.plot.setLabel("bottom", "time", units="s")
        self.plot.addLegend(offset=(-8, 8), brush=pg.mkBrush(17, 17, 17, 200), labelTextColor="#ddd")
        self.plot.setClipToView(True)
        self.plot.setDownsampling(auto=True, mode="peak")
        self.plot.plotItem.vb.enableAutoRange(axis="y", enable=True)
        self.cursor1 = pg.InfiniteLine(angle=90, movable=True, pen=pg.mkPen("#ffffff", width=1))
        self.cursor2 = pg.InfiniteLine(angle=90, movable=True, pen=pg.mkPen("#ffffff", width=1,
                                                                             style=Qt.PenStyle.DashLine))
        for c in (self.cursor1, self.cursor2):
            c.sigPositionChanged.connect(self._update_cursor_readout)
        time_page = QWidget()
        tl = QVBoxLayout(time_page)
        tl.setContentsMargins(0, 0, 0, 0)
        tl.addWidget(self.plot, 1)
        self.cursor_label = QLabel("")
        self.cursor_label.setObjectName("scopeCursorReadout")
        self.cursor_label.setWordWrap(True)
        tl.addWidget(self.cursor_label)
        self.plots.addTab(time_page, "Time")
        self.plots.addTab(self._build_spectrum(), "Spectrum")
        split.addWidget(self.plots)

        side = QTabWidget()
        side.addTab(self._build_trigger_panel(), "Trigger")
        side.addTab(self._build_test_panel(), "Tests")
        split.addWidget(side)
        split.setSizes([300, 760, 300])
        split.setStretchFactor(1, 1)
        outer.addWidget(split, 1)
        self.info_label = QLabel("")
        self.info_label.setObjectName("scopeInfo")
        outer.addWidget(self.info_label)

    def _build_spectrum(self) -> QWidget:
        page = QWidget()
        lay = QVBoxLayout(page)
        lay.setContentsMargins(0, 0, 0, 0)
        row = QHBoxLayout()
        row.addWidget(QLabel("Channel"))
        self.spectrum_channel = QComboBox()
        row.addWidget(self.spectrum_channel, 1)
        row.addWidget(QLabel("Remove"))
        self.spectrum_detrend = QComboBox()
        self.spectrum_detrend.addItem("ramp (moves)", "linear")
        self.spectrum_detrend.addItem("mean", "constant")
        row.addWidget(self.spectrum_detrend)
        go = QPushButton("Compute")
        go.clicked.connect(self.compute_spectrum)
        row.addWidget(go)
        lay.addLayout(row)
        self.spectrum_plot = pg.PlotWidget()
        self.spectrum_plot.setBackground("#111")
        self.spectrum_plot.showGrid(x=True, y=True, alpha=0.25)
        self.spectrum_plot.setLabel("bottom", "frequency", units="Hz")
        self.spectrum_plot.setLogMode(y=True)
        self.spectrum_curve = self.spectrum_plot.plot(pen=pg.mkPen("#4fc3f7"))
        lay.addWidget(self.spectrum_plot, 1)
        self.spectrum_label = QLabel("Capture a trace (uniform sampling), then compute its spectrum.")
        self.spectrum_label.setWordWrap(True)
        lay.addWidget(self.spectrum_label)
        return page

    def _build_trigger_panel(self) -> QWidget:
        page = QWidget()
        form = QFormLayout(page)
        analog = [c for c in self.all_channels if not c.is_bit]
        bits = [c for c in self.all_channels if c.is_bit]
        bits.append(ScopeChannel("moving", "Moving", "bit", MonitorItem.IO_STATE, 1.0, p.IoBit.MOVING))
        self._trigger_bits = bits
        self.trace_channels: list[QComboBox] = []
        defaults = ("feedback_position", "command_position", "output_speed", "motor_current")
        for k in range(p.TRACE_MAX_CHANNELS):
            box = QComboBox()
            box.addItem("—", None)
            for c in analog + [c for c in bits if c.key != "moving"]:
                box.addItem(c.name, c.key)
            box.setCurrentIndex(max(0, box.findData(defaults[k])))
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
        for text, kind in _TRIGGERS:
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
        self.arm_button.clicked.connect(self.arm_trace)
        cancel = QPushButton("Cancel")
        cancel.clicked.connect(lambda: self.controller.send(ScopeCmd.CANCEL_TRACE))
        row.addWidget(self.arm_button)
        row.addWidget(cancel)
        form.addRow(row)
        self.trace_state = QLabel("idle")
        self.trace_state.setObjectName("scopeTraceState")
        self.trace_state.setWordWrap(True)
        form.addRow("State", self.trace_state)
        self._trigger_kind_changed()
        return page

    def _build_test_panel(self) -> QWidget:
        page = QWidget()
        lay = QVBoxLayout(page)
        form = QFormLayout()
        self.test_angle = QDoubleSpinBox()
        self.test_angle.setRange(-3600.0, 3600.0)
        self.test_angle.setDecimals(2)
        self.test_angle.setValue(90.0)
        self.test_angle.setSuffix(" deg")
        form.addRow("Move by", self.test_angle)
        self.test_speed = QDoubleSpinBox()
        self.test_speed.setRange(0.1, float(self._actuator.max_speed_rpm))
        self.test_speed.setValue(min(30.0, float(self._actuator.max_speed_rpm)))
        self.test_speed.setSuffix(" r/min")
        form.addRow("Speed", self.test_speed)
        self.step_angle = QDoubleSpinBox()
        self.step_angle.setRange(-10.0, 10.0)
        self.step_angle.setDecimals(3)
        self.step_angle.setValue(0.5)
        self.step_angle.setSuffix(" deg")
        form.addRow("Step", self.step_angle)
        lay.addLayout(form)
        row = QHBoxLayout()
        self.move_test_button = QPushButton("Move test")
        self.move_test_button.clicked.connect(lambda: self.run_test("move"))
        self.step_test_button = QPushButton("Step test")
        self.step_test_button.clicked.connect(lambda: self.run_test("step"))
        abort = QPushButton("Abort")
        abort.clicked.connect(lambda: self.controller.send(ScopeCmd.ABORT_TEST))
        for b in (self.move_test_button, self.step_test_button, abort):
            row.addWidget(b)
        lay.addLayout(row)
        box = QGroupBox("Result")
        res = QFormLayout(box)
        self.result_labels: dict[str, QLabel] = {}
        for key, text in (("overshoot", "Overshoot"), ("rise", "Rise time 10-90 %"),
                          ("settling", "Settling time"), ("in_position", "In-position after command end"),
                          ("final_error", "Final error"), ("method", "Captured by")):
            label = QLabel("—")
            label.setObjectName(f"scopeResult_{key}")
            label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
            self.result_labels[key] = label
            res.addRow(text, label)
        lay.addWidget(box)
        files = QGroupBox("Recordings")
        ff = QFormLayout(files)
        self.actuator_label = QLabel(self.context.actuator)
        ff.addRow("Actuator", self.actuator_label)
        self.load_inertia = QDoubleSpinBox()
        self.load_inertia.setObjectName("scopeLoadInertia")
        self.load_inertia.setRange(0.0, 1e4)
        self.load_inertia.setDecimals(4)
        self.load_inertia.setValue(self.context.load_inertia_kgm2)
        self.load_inertia.setSuffix(" kg m²")
        self.load_inertia.setToolTip("The load inertia written into recordings (the model check needs it)")
        ff.addRow("Load inertia", self.load_inertia)
        lay.addWidget(files)
        self.test_message = QLabel("The servo must be on. The axis moves.")
        self.test_message.setWordWrap(True)
        lay.addWidget(self.test_message)
        lay.addStretch(1)
        return page

    # --------------------------------------------------------------------------------- channels
    def _shown_channels(self) -> tuple[ScopeChannel, ...]:
        if self._static is not None:
            return self._static.channels
        if self._live is not None:
            return self._live.channels
        return tuple(self.all_channels)

    def _fill_channel_table(self) -> None:
        channels = self._shown_channels()
        t = self.channel_table
        t.blockSignals(True)
        t.setRowCount(len(channels))
        for row, c in enumerate(channels):
            name = QTableWidgetItem(c.name)
            name.setData(Qt.ItemDataRole.UserRole, c.key)
            name.setFlags(Qt.ItemFlag.ItemIsEnabled | Qt.ItemFlag.ItemIsUserCheckable)
            shown = self._visible.get(c.key, True)
            name.setCheckState(Qt.CheckState.Checked if shown else Qt.CheckState.Unchecked)
            name.setForeground(pg.mkColor(self._color(c.key)))
            t.setItem(row, 0, name)
            unit = QTableWidgetItem(c.unit)
            unit.setFlags(Qt.ItemFlag.ItemIsEnabled)
            t.setItem(row, 1, unit)
            spin = QDoubleSpinBox()
            spin.setRange(1e-4, 1e4)
            spin.setDecimals(3)
            spin.setToolTip(f"Multiply {c.name} by this factor on the plot (cursors read {c.unit})")
            spin.setValue(self._scale.get(c.key, 1.0))
            spin.valueChanged.connect(lambda v, k=c.key: self.set_channel_scale(k, v))
            t.setCellWidget(row, 2, spin)
        t.blockSignals(False)
        self._rebuild_curves()
        self.spectrum_channel.clear()
        for c in channels:
            if not c.is_bit:
                self.spectrum_channel.addItem(f"{c.name} [{c.unit}]", c.key)

    def _color(self, key: str) -> str:
        keys = [c.key for c in self.all_channels]
        return COLORS[keys.index(key) % len(COLORS)] if key in keys else COLORS[hash(key) % len(COLORS)]

    def _channel_item_changed(self, item: QTableWidgetItem) -> None:
        if item.column() != 0:
            return
        checked = item.checkState() == Qt.CheckState.Checked
        self.set_channel_visible(item.data(Qt.ItemDataRole.UserRole), checked)

    def set_channel_visible(self, key: str, visible: bool) -> None:
        """Show or hide a channel. Live, the polled items follow the visible channels (restart)."""
        if self._visible.get(key) == visible:
            return
        if self._recorder is not None and self._live is not None and self._static is None:
            self._message("Stop recording before changing the live channels.")
            self._fill_channel_table()
            return
        self._visible[key] = visible
        if self._static is None and self.live_button.isChecked():
            self.start_live()  # poll what is shown: fewer items, more samples per second
        else:
            self._rebuild_curves()
            self._redraw_static()

    def set_channel_scale(self, key: str, scale: float) -> None:
        self._scale[key] = float(scale)
        self._rebuild_curves()
        self._redraw_static()

    def _rebuild_curves(self) -> None:
        for curve in self._curves.values():
            self.plot.removeItem(curve)
        self._curves.clear()
        for c in self._shown_channels():
            if not self._visible.get(c.key, True):
                continue
            scale = self._scale.get(c.key, 1.0)
            label = f"{c.name} [{c.unit}]" + (f" ×{scale:g}" if scale != 1 else "")
            curve = self.plot.plot(pen=pg.mkPen(self._color(c.key), width=1), name=label)
            curve.setDownsampling(auto=True, method="peak")
            curve.setClipToView(True)
            self._curves[c.key] = curve

    # ------------------------------------------------------------------------------------- live
    def _live_toggled(self, on: bool) -> None:
        if on:
            self.start_live()
        else:
            self.stop_live()

    def start_live(self) -> None:
        """Start (or restart with the visible channels) the live acquisition in the link thread."""
        self._static = None
        wanted = [c for c in self.all_channels if self._visible.get(c.key)]
        if not wanted:
            wanted = [c for c in self.all_channels if c.key in DEFAULT_VISIBLE]
        if not self.live_button.isChecked():
            self.live_button.blockSignals(True)
            self.live_button.setChecked(True)
            self.live_button.blockSignals(False)
        self.live_button.setText("Stop live")
        self.controller.send(ScopeCmd.START, tuple(wanted))
        self.sigLiveChanged.emit(True)

    def stop_live(self) -> None:
        self.controller.send(ScopeCmd.STOP)
        self.stop_recording()
        self._live = None
        self._status = None
        self.live_button.blockSignals(True)
        self.live_button.setChecked(False)
        self.live_button.blockSignals(False)
        self.live_button.setText("Start live")
        self._update_indicator()
        self.sigLiveChanged.emit(False)

    def set_paused(self, paused: bool) -> None:
        """Freeze the drawing; acquisition and recording go on."""
        self._paused = bool(paused)
        if self.pause_button.isChecked() != self._paused:
            self.pause_button.setChecked(self._paused)
        self._update_indicator()

    def _on_live_started(self, started: LiveStarted) -> None:
        self._live = started
        self._static = None
        self._status = None
        self.plot.showGrid(x=False, y=True, alpha=0.25)
        self._fill_channel_table()
        self._update_indicator()

    def _on_status(self, status) -> None:
        self._status = status
        self._update_indicator()

    def _newest_age_s(self) -> float | None:
        live = self._live
        if live is None or len(live.ring) == 0:
            return None
        return time.monotonic() - live.t0 - float(live.ring.window(1)[0, 0])

    def indicator_text(self) -> str:
        return self._indicator_text

    def _update_indicator(self) -> None:
        kind, text = "not", "NOT LIVE: not started"
        if self._static is not None:
            text = f"NOT LIVE: showing {self._static.label}"
        elif self._live is not None:
            status = self._status
            age = self._newest_age_s()
            stale_after = max(0.5, 5.0 / status.rate_hz) if status and status.rate_hz else 0.5
            if status is None:
                text = "NOT LIVE: waiting for the first sample"
            elif not status.live:
                text = status.label
            elif age is None or age > stale_after:
                text = "NOT LIVE: no new sample for " + ("a while" if age is None else f"{age:.1f} s")
            else:
                kind, text = "live", "LIVE"
            if self._paused:
                text = "PAUSED (acquisition goes on)" if kind == "live" else f"PAUSED · {text}"
                kind = "paused"
        elif self.controller is not None and not self.controller.connected:
            text = "NOT LIVE: no drive connected"
        if text != self._indicator_text:
            self._indicator_text = text
            short = text if len(text) < 48 else text[:46] + "…"
            self.indicator.setText(short)
            self.indicator.setToolTip(text)
            self.indicator.setStyleSheet(INDICATOR_STYLE[kind])
            self.sigIndicatorChanged.emit(text)

    def _refresh(self) -> None:
        """The GUI timer: drain the ring (to the recorder), redraw the live window, update state."""
        live = self._live
        self._update_indicator()
        if live is None or self._static is not None:
            return
        rows = live.ring.drain()
        if self._recorder is not None and len(rows):
            try:
                self._recorder.write(rows)
            except OSError as exc:
                self._message(f"Recording stopped: {exc}")
                self.stop_recording()
        if self._paused:
            return
        tb = float(self.time_base.currentData())
        # redraw when the trace has moved by about a pixel (a 60 s time base needs ~16 frames/s)
        interval_s = min(0.1, max(REFRESH_MS / 1000, tb / max(100, self.plot.width())))
        clock = time.monotonic()
        if clock - self._last_draw < interval_s * 0.9:
            return
        self._last_draw = clock
        data = live.ring.window()
        now = clock - live.t0
        if len(data):
            i0 = int(np.searchsorted(data[:, 0], now - tb))
            t, columns = peak_decimate(data[i0:], max(200, self.plot.width()))
            for j, c in enumerate(live.channels):
                curve = self._curves.get(c.key)
                if curve is not None:
                    curve.setData(t, columns[:, j + 1] * self._scale.get(c.key, 1.0))
        self.plot.setXRange(now - tb, now, padding=0)
        self.frames += 1
        self.sigFrame.emit()
        if self.cursors_box.isChecked() and time.monotonic() - self._last_cursor_update > 0.2:
            self._update_cursor_readout()
        self._update_info()

    def _update_info(self) -> None:
        s = self._status
        parts = []
        if s is not None and s.mode is not LiveMode.NONE:
            parts.append(f"{s.rate_hz:.1f} samples/s (line limit {s.limit_hz:.1f}/s)")
            parts.append(f"{s.samples} samples, {s.dropped} dropped")
        if self._recorder is not None:
            parts.append(f"● REC {self._recorder.rows_written} rows → {Path(self._recorder.path).name}")
        self.info_label.setText(" · ".join(parts))

    # -------------------------------------------------------------------------------- static data
    def show_static(self, channels, rows: np.ndarray, label: str, sample_rate_hz: float | None = None,
                    uniform: bool = True) -> None:
        """Show data that is not live (a capture, a file); live acquisition goes on unseen."""
        self._static = _Static(tuple(channels), np.asarray(rows, dtype=float), label, sample_rate_hz, uniform)
        self.plot.showGrid(x=True, y=True, alpha=0.25)
        for c in self._static.channels:
            self._visible[c.key] = True  # a capture shows all it has; hide by hand
        self._fill_channel_table()
        self._redraw_static()
        self.fit()
        self._update_indicator()

    def _redraw_static(self) -> None:
        s = self._static
        if s is None:
            return
        for j, c in enumerate(s.channels):
            curve = self._curves.get(c.key)
            if curve is not None:
                curve.setData(s.rows[:, 0], s.rows[:, j + 1] * self._scale.get(c.key, 1.0))
        self._update_cursor_readout()

    def back_to_live(self) -> None:
        self._static = None
        self.plot.showGrid(x=False, y=True, alpha=0.25)
        self._fill_channel_table()
        self._update_indicator()

    def fit(self) -> None:
        """Show the whole capture (or the live time base) and scale Y to the visible channels."""
        vb = self.plot.plotItem.vb
        if self._static is not None and len(self._static.rows):
            t = self._static.rows[:, 0]
            vb.setXRange(float(t[0]), float(t[-1]), padding=0.02)  # from the data, not from clipped curves
            shown = [j + 1 for j, c in enumerate(self._static.channels) if self._visible.get(c.key, True)]
            if shown:
                y = self._static.rows[:, shown] * [self._scale.get(self._static.channels[j - 1].key, 1.0)
                                                   for j in shown]
                lo, hi = float(np.nanmin(y)), float(np.nanmax(y))
                vb.setYRange(lo, hi if hi > lo else lo + 1.0, padding=0.05)
        else:
            vb.autoRange(padding=0.02)
        if self.autoscale.isChecked():
            vb.enableAutoRange(axis="y", enable=True)

    def _autoscale_toggled(self, on: bool) -> None:
        self.plot.plotItem.vb.enableAutoRange(axis="y", enable=bool(on))

    # ------------------------------------------------------------------------------------ cursors
    def _cursors_toggled(self, on: bool) -> None:
        for c in (self.cursor1, self.cursor2):
            if on:
                self.plot.addItem(c, ignoreBounds=True)
            else:
                self.plot.removeItem(c)
        if on:
            (x0, x1), _ = self.plot.plotItem.vb.viewRange()
            self.set_cursors(x0 + 0.3 * (x1 - x0), x0 + 0.7 * (x1 - x0))
        self._update_cursor_readout()

    def set_cursors(self, t1_s: float, t2_s: float) -> None:
        if not self.cursors_box.isChecked():
            self.cursors_box.setChecked(True)
        self.cursor1.setValue(t1_s)
        self.cursor2.setValue(t2_s)
        self._update_cursor_readout()

    def cursor_readout(self) -> dict[str, tuple[float, float, float | None]]:
        """{channel key: (dt s, dvalue, slope per s)} for the visible channels between the cursors."""
        out: dict[str, tuple[float, float, float | None]] = {}
        data = self.shown_rows()
        if data is None or len(data) < 2:
            return out
        channels, rows = data
        t1, t2 = float(self.cursor1.value()), float(self.cursor2.value())
        for j, c in enumerate(channels):
            if self._visible.get(c.key, True):
                d = cursor_delta(rows[:, 0], rows[:, j + 1], t1, t2)
                out[c.key] = (d.dt_s, d.dvalue, d.slope_per_s)
        return out

    def _update_cursor_readout(self, *_args) -> None:
        self._last_cursor_update = time.monotonic()
        if not self.cursors_box.isChecked():
            self.cursor_label.setText("")
            return
        readout = self.cursor_readout()
        if not readout:
            self.cursor_label.setText("Cursors: no data")
            return
        units = {c.key: c for c in self._shown_channels()}
        dt = next(iter(readout.values()))[0]
        parts = [f"Δt = {dt * 1000:.2f} ms" + (f" ({1 / abs(dt):.2f} Hz)" if dt else "")]
        for key, (_dt, dv, slope) in readout.items():
            c = units[key]
            slope_text = "—" if slope is None else f"{slope:.4g} {c.unit}/s"
            parts.append(f"{c.name}: Δ {dv:.4g} {c.unit}, {slope_text}")
        self.cursor_label.setText(" | ".join(parts))

    # ------------------------------------------------------------------------------ data on show
    def shown_rows(self) -> tuple[tuple[ScopeChannel, ...], np.ndarray] | None:
        """(channels, rows [t_s, values...]) of what the plot shows (the live time window)."""
        if self._static is not None:
            return self._static.channels, self._static.rows
        live = self._live
        if live is None or len(live.ring) == 0:
            return None
        data = live.ring.window()
        (x0, x1), _ = self.plot.plotItem.vb.viewRange()
        i0, i1 = np.searchsorted(data[:, 0], [x0, x1])
        return live.channels, np.array(data[max(0, i0 - 1): i1 + 1])

    # ------------------------------------------------------------------------------------- files
    def _ask_path(self, what: str) -> None:
        filters = {"png": "PNG image (*.png)", "csv": "CSV (*.csv)", "save": "FHA recording (*.csv)",
                   "open": "FHA recording (*.csv);;All files (*)", "record": "FHA recording (*.csv)"}
        if what == "open":
            path, _ = QFileDialog.getOpenFileName(self, "Open a recording", "", filters[what])
        else:
            path, _ = QFileDialog.getSaveFileName(self, "Save", "", filters[what])
        if not path:
            if what == "record":
                self.record_button.setChecked(False)
            return
        try:
            {"png": self.export_png, "csv": self.export_csv, "save": self.save_capture,
             "open": self.open_recording, "record": self.start_recording}[what](path)
        except (OSError, ValueError) as exc:
            if what == "record":
                self.record_button.setChecked(False)
            self._message(str(exc))

    def _metadata(self, sample_rate_hz: float | None, extra: dict | None = None) -> RecordingMetadata:
        c = self.context
        return RecordingMetadata(c.actuator, self.load_inertia.value(), c.supply_voltage, sample_rate_hz,
                                 extra=dict(extra or {}))

    def set_context(self, context: ScopeContext) -> None:
        """Another actuator (resolution, ratio, speed range): channels are rebuilt, live stops."""
        if context == self.context:
            return
        self.stop_live()
        self.context = context
        self._actuator = context.actuator_data()
        self.all_channels = scope_channels(load_parameter_model(context.driver),
                                           self._actuator.output_resolution_ppr)
        self.actuator_label.setText(context.actuator)
        self.test_speed.setMaximum(float(self._actuator.max_speed_rpm))
        self._static = None
        self._fill_channel_table()

    @property
    def ratio(self) -> int:
        return int(self._actuator.ratio)

    def _record_clicked(self, checked: bool) -> None:
        if checked:
            self._ask_path("record")
        else:
            self.stop_recording()

    def start_recording(self, path) -> None:
        """Record the live samples to ``path`` (fha-recording/1 + extra channels) while plotting."""
        if self._live is None or self._live.mode is LiveMode.NONE:
            raise ValueError("start the live view first: the recording takes the live samples")
        self.stop_recording()
        self._live.ring.drain()  # start with the samples that come from now on
        self._recorder = ScopeRecorder(path, self._metadata(None, {
            "source": "fha-studio scope, polled monitor items (host time stamps)"}), self._live.channels)
        self.record_button.setChecked(True)
        self.record_button.setText("■ Stop recording")

    def stop_recording(self) -> Path | None:
        rec, self._recorder = self._recorder, None
        self.record_button.setChecked(False)
        self.record_button.setText("Record…")
        if rec is None:
            return None
        rec.close()
        self.sigRecordingSaved.emit(Path(rec.path), f"live recording, {rec.rows_written} rows")
        return Path(rec.path)

    @property
    def recording(self) -> bool:
        return self._recorder is not None

    def save_capture(self, path) -> Path:
        """Write the capture on show (trace, test, file) as fha-recording/1."""
        s = self._static
        if s is None:
            raise ValueError("no capture on show: arm a trace, run a test or open a recording first")
        extra = {"source": f"fha-studio scope: {s.label}"}
        rec = ScopeRecorder(path, self._metadata(s.sample_rate_hz if s.uniform else None, extra), s.channels)
        try:
            rec.write(s.rows)
        finally:
            rec.close()
        self.sigRecordingSaved.emit(Path(rec.path), s.label)
        return Path(rec.path)

    def export_png(self, path) -> Path:
        exporter = exporters.ImageExporter(self.plot.plotItem)
        exporter.parameters()["width"] = max(800, self.plot.width())
        exporter.export(str(path))
        return Path(path)

    def export_csv(self, path) -> Path:
        """The data on show as CSV: ``t_s`` and one column per channel, ``key [unit]``."""
        data = self.shown_rows()
        if data is None:
            raise ValueError("nothing on show to export")
        channels, rows = data
        header = ",".join(["t_s"] + [f"{c.key} [{c.unit}]" for c in channels])
        np.savetxt(path, rows, delimiter=",", header=header, comments="", fmt="%.9g")
        return Path(path)

    def open_recording(self, path) -> None:
        """Show an fha-recording/1 file (contract columns as the scope's channels, extras by name)."""
        recording = read_recording(path)
        by_key = {c.key: c for c in self.all_channels}
        channels, columns = [], []
        for name, values in recording.channels.items():
            if name == "t":
                continue
            key = _COLUMN_KEYS.get(name, name)
            channel = by_key.get(key) or ScopeChannel(key, name, "", 0)
            channels.append(channel)
            columns.append(values)
        rows = np.column_stack([recording.t_s, *columns])
        dt = np.diff(recording.t_s)
        uniform = len(dt) > 0 and float(np.ptp(dt)) <= 0.01 * float(np.median(dt))
        self.show_static(channels, rows, f"file {Path(path).name}",
                         recording.metadata.sample_rate_hz, uniform)

    # -------------------------------------------------------------------------------------- trace
    def _trigger_kind_changed(self, *_args) -> None:
        kind = self.trigger_kind.currentData()
        self.trigger_channel.clear()
        if kind in (p.TriggerKind.RISING_LEVEL, p.TriggerKind.FALLING_LEVEL):
            for c in self.all_channels:
                if not c.is_bit:
                    self.trigger_channel.addItem(f"{c.name} [{c.unit}]", c.key)
        elif kind in (p.TriggerKind.IO_BIT_RISES, p.TriggerKind.IO_BIT_FALLS):
            for c in self._trigger_bits:
                self.trigger_channel.addItem(c.name, c.key)
        self.trigger_channel.setEnabled(self.trigger_channel.count() > 0)
        self.trigger_level.setEnabled(kind in (p.TriggerKind.RISING_LEVEL, p.TriggerKind.FALLING_LEVEL))

    def trace_settings(self) -> TraceSettings:
        by_key = {c.key: c for c in self.all_channels + self._trigger_bits}
        keys = [b.currentData() for b in self.trace_channels if b.currentData()]
        channels = tuple(by_key[k] for k in dict.fromkeys(keys))
        kind = self.trigger_kind.currentData()
        trigger_channel = by_key.get(self.trigger_channel.currentData())
        samples = self.trace_samples.value()
        return TraceSettings(channels, self.trace_rate.value(), samples,
                             min(samples - 1, samples * self.trace_pre.value() // 100),
                             Trigger(kind, trigger_channel, self.trigger_level.value()))

    def arm_trace(self) -> None:
        try:
            settings = self.trace_settings()
            settings.check()
        except ValueError as exc:
            self._message(str(exc))
            return
        self.trace_state.setText("arming…")
        self.controller.send(ScopeCmd.ARM_TRACE, settings)

    def _on_trace_state(self, text: str) -> None:
        self.trace_state.setText(text)
        self.trace_state.setToolTip(text)

    def _on_trace_done(self, result: TraceResult) -> None:
        self.last_trace = result
        stamp = time.strftime("%H:%M:%S", time.localtime(result.captured_at))
        self.show_static(result.channels, result.rows(), f"trace {stamp}",
                         result.sample_rate_hz, True)
        self.sigTraceDone.emit(result)

    # -------------------------------------------------------------------------------------- tests
    def run_test(self, kind: str) -> None:
        angle = self.step_angle.value() if kind == "step" else self.test_angle.value()
        speed = float(self._actuator.max_speed_rpm) if kind == "step" else self.test_speed.value()
        self.test_message.setText(f"{kind} test running: {angle:g} deg at {speed:g} r/min …")
        for label in self.result_labels.values():
            label.setText("…")
        self.controller.send(ScopeCmd.RUN_TEST, {
            "channels": self.all_channels, "angle_deg": angle, "speed_rpm": speed, "kind": kind,
            "output_resolution_ppr": self._actuator.output_resolution_ppr})

    def _on_test_done(self, result: MoveTestResult) -> None:
        self.last_test = result
        m = result.metrics

        def ms(v):
            return "not reached" if v is None else f"{v * 1000:.1f} ms"

        if m is None:
            for label in self.result_labels.values():
                label.setText("—")
            self.test_message.setText(result.describe())
        else:
            self.result_labels["overshoot"].setText(f"{m.overshoot_percent:.2f} % ({m.overshoot:.4g} deg)")
            self.result_labels["rise"].setText(ms(m.rise_time_s))
            band = f" (band ±{m.settling_band:.3g} deg)"
            self.result_labels["settling"].setText(ms(m.settling_time_s) + band)
            window = result.in_position_range_deg
            inpos = "" if window is None else f" (±{window:.3g} deg)"
            self.result_labels["in_position"].setText(ms(m.in_position_time_s) + inpos)
            self.result_labels["final_error"].setText(f"{m.final_error:.4g} deg")
            self.test_message.setText(f"{result.kind} test of {result.angle_deg:g} deg at "
                                      f"{result.speed_rpm:g} r/min done.")
        if result.capture is not None:
            c = result.capture
            self.result_labels["method"].setText(
                f"{'drive trace' if c.method == 'trace' else 'polling'}, {len(c.t_s)} samples"
                + (f" at {c.sample_rate_hz:.0f} Hz" if c.method == "trace" else ""))
            self.show_static(c.channels, c.rows(), f"{result.kind} test capture", c.sample_rate_hz,
                             c.method == "trace")
        self.sigTestDone.emit(result)

    # ----------------------------------------------------------------------------------- spectrum
    def compute_spectrum(self) -> None:
        s = self._static
        key = self.spectrum_channel.currentData()
        if s is None or key is None:
            self.spectrum_label.setText("No capture on show: arm a trace (or open a recording) first.")
            return
        if not s.uniform:
            self.spectrum_label.setText("This capture is not uniformly sampled (polled): use a drive trace.")
            return
        j = [c.key for c in s.channels].index(key)
        try:
            spec = spectrum(s.rows[:, 0], s.rows[:, j + 1], detrend=self.spectrum_detrend.currentData())
        except ValueError as exc:
            self.spectrum_label.setText(str(exc))
            return
        f, a = spec.frequency_hz[1:], np.maximum(spec.amplitude[1:], 1e-12)
        self.spectrum_curve.setData(f, a)
        unit = s.channels[j].unit
        peaks = spec.prominent_peaks(4, min_hz=f[0] if len(f) else 0.0)
        text = ", ".join(f"{hz:.2f} Hz ({amp:.3g} {unit})" for hz, amp in peaks) or "none stand out"
        self.spectrum_label.setText(f"Peaks: {text}. Resolution {f[0]:.3g} Hz." if len(f) else "Peaks: none")
        self.last_spectrum = spec
        self.plots.setCurrentIndex(1)

    # --------------------------------------------------------------------------------------- misc
    def _on_error(self, text: str) -> None:
        self.trace_state.setText(f"error: {text}")
        self._message(text)

    def _message(self, text: str) -> None:
        log.info("scope: %s", text)
        self.info_label.setText(text)
        self.last_message = text

    def shutdown(self) -> None:
        self._timer.stop()
        self.stop_recording()
        self.controller.send(ScopeCmd.STOP)
