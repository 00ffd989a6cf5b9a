"""ScopeView: the oscilloscope a technician tunes and verifies an axis with.

The page is composed of panels, each with one job: the toolbar (indicator and view-wide
actions, ``toolbar``), the channel table (``channel_table``), the time plot (``time_plot``), the
spectrum (``spectrum_panel``), the trigger (``trigger_panel``) and the tests
(``move_test_panel``). ScopeView holds what they share: the live acquisition, the data on show,
the recorder and the files.

Live, a GUI-thread QTimer drains the acquisition's ring buffer (the acquisition itself runs in
the link thread, see ``driver``; the ring's lock is held only to copy rows, never while drawing)
into pre-decimated min/max levels and draws the time window from them. A captured trace, a move
test or an opened recording is shown in the same plot, marked NOT LIVE. The indicator never
calls old data live: it checks the age of the newest sample itself on every frame.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtGui import QFontMetrics
from PySide6.QtWidgets import (
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QProgressBar,
    QSplitter,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from fha_studio import fileio
from fha_studio.gui.widgets import scrolling
from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.scope.acquisition import LiveMode, MoveTestResult, TraceResult, TraceSettings
from fha_studio.logic.scope.analysis import CursorDelta, cursor_delta, spectrum
from fha_studio.logic.scope.channels import ScopeChannel, scope_channels
from fha_studio.logic.scope.files import csv_text, recording_rows
from fha_studio.logic.scope.indicator import IndicatorKind, live_indicator
from fha_studio.logic.scope.levels import MinMaxLevels
from fha_studio.logic.scope.recorder import BesideColumns, ScopeRecorder
from fha_studio.recording import RecordingMetadata, read_recording

from .channel_table import ChannelTable
from .context import ScopeContext, actuator_text
from .cursor_table import CursorRow
from .driver import LiveStarted, ScopeCmd, ScopeController
from .move_test_panel import MoveTestPanel
from .spectrum_panel import SpectrumPanel
from .time_plot import TimePlot
from .toolbar import FileAction, ScopeToolbar
from .trigger_panel import TriggerPanel

log = logging.getLogger(__name__)

#: Redraw period of the live view [ms]: 40 frames/s at most, smooth to the eye.
REFRESH_MS = 25
#: How often the text under the plot and the cursor read-out follow the live data [s].
TEXT_INTERVAL_S = 0.25
DEFAULT_VISIBLE = ("feedback_position", "command_position", "output_speed", "motor_current")
#: Channel colours, strong enough on the white plot and on the window's background (the legend and
#: the channel table): no pale yellow or light pastel.
COLORS = ("#1f77b4", "#d62728", "#2ca02c", "#e07000", "#9467bd", "#8c564b", "#e377c2", "#008b8b",
          "#555555", "#1a237e", "#b8860b", "#006400", "#c2185b", "#4e342e", "#0097a7", "#6a1b9a")


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

    # panels made in _build (signal connections made before them refer to them)
    tests: MoveTestPanel
    time_plot: TimePlot
    sigLiveChanged = Signal(bool)  # live acquisition requested on / off
    sigRecordingSaved = Signal(object, str)  # Path of a finished fha-recording/1 file, what it holds
    sigLoadInertiaEdited = Signal(float)  # the user typed the declared load inertia [kg m^2]

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
        self._levels: MinMaxLevels | None = None
        self._status = None  # last LiveStatus from the driver
        self._static: _Static | None = None
        self._paused = False
        self._recorder: ScopeRecorder | None = None
        self.beside_recording: Callable[[float], BesideColumns | None] | None = None  # by live t0
        self.frames = 0
        self._last_text_update = 0.0
        self.last_test: MoveTestResult | None = None
        self.last_trace: TraceResult | None = None
        self.last_message = ""
        self._build()
        d = controller
        d.sigLiveStarted.connect(self._on_live_started)
        d.sigStatus.connect(self._on_status)
        d.sigTraceState.connect(self._on_trace_state)
        d.sigTraceDone.connect(self._on_trace_done)
        d.sigTestDone.connect(self._on_test_done)
        d.sigError.connect(self._on_error)
        d.sigTestState.connect(lambda text: self.tests.set_message(f"Test: {text} …"))
        d.sigReadoutProgress.connect(self._on_readout_progress)
        self._timer = QTimer(self)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._timer.setInterval(REFRESH_MS)
        self._timer.timeout.connect(self._refresh)
        self._timer.start()
        self._fill_channel_table()
        self._update_indicator()

    # ------------------------------------------------------------------------------------ layout
    def _build(self) -> None:
        outer = QVBoxLayout(self)
        outer.setContentsMargins(4, 4, 4, 4)
        self.toolbar = bar = ScopeToolbar()
        bar.sigLiveToggled.connect(self._live_toggled)
        bar.sigBackToLive.connect(self.back_to_live)
        bar.sigPaused.connect(self.set_paused)
        bar.sigAutoscale.connect(lambda on: self.time_plot.set_autoscale(on))
        bar.sigFit.connect(self.fit)
        bar.sigCursors.connect(self._cursors_toggled)
        bar.sigRecord.connect(self._record_clicked)
        bar.sigFile.connect(self._ask_path)
        outer.addWidget(bar)

        split = QSplitter(Qt.Orientation.Horizontal)
        left = QWidget()
        self._left_column = QVBoxLayout(left)
        self._left_column.setContentsMargins(0, 0, 0, 0)
        self.channel_table = ChannelTable()
        self.channel_table.sigVisibleChanged.connect(self.set_channel_visible)
        self.channel_table.sigScaleChanged.connect(self.set_channel_scale)
        self._left_column.addWidget(self.channel_table, 1)
        split.addWidget(left)

        self.plots = QTabWidget()
        self.time_plot = TimePlot()
        self.time_plot.sigCursorsMoved.connect(self._update_cursor_readout)
        self.plots.addTab(self.time_plot, "Time")
        self.spectrum_panel = SpectrumPanel()
        self.spectrum_panel.sigCompute.connect(self.compute_spectrum)
        self.plots.addTab(self.spectrum_panel, "Spectrum")
        split.addWidget(self.plots)

        side = QTabWidget()
        self.trigger = TriggerPanel(self.all_channels)
        self.trigger.sigArm.connect(self.arm_trace)
        self.trigger.sigCancel.connect(lambda: self.controller.send(ScopeCmd.CANCEL_TRACE))
        side.addTab(scrolling(self.trigger), "Trigger")
        self.tests = MoveTestPanel(actuator_text(self.context), float(self._actuator.max_speed_rpm),
                                   self.context.load_inertia_kgm2)
        self.tests.load_inertia.valueChanged.connect(self._load_inertia_edited)
        self.tests.sigRun.connect(self.run_test)
        self.tests.sigAbort.connect(lambda: self.controller.send(ScopeCmd.ABORT_TEST))
        side.addTab(scrolling(self.tests), "Tests")
        split.addWidget(side)
        split.setSizes([270, 730, 340])  # the trigger panel whole at 1366 px wide
        split.setStretchFactor(1, 1)
        outer.addWidget(split, 1)
        bottom = QHBoxLayout()
        self.info_label = QLabel("")
        self.info_label.setObjectName("scopeInfo")
        bottom.addWidget(self.info_label, 1)
        self.readout_progress = QProgressBar()
        self.readout_progress.setObjectName("scopeReadoutProgress")
        self.readout_progress.setVisible(False)
        bottom.addWidget(self.readout_progress)
        outer.addLayout(bottom)

        # The widgets other code drives directly (tests, screenshots, benchmarks).
        t = self.trigger
        self.trace_channels, self.trace_rate = t.trace_channels, t.trace_rate
        self.trace_samples, self.trace_pre = t.trace_samples, t.trace_pre
        self.trigger_kind, self.trigger_channel = t.trigger_kind, t.trigger_channel
        self.trigger_level, self.trace_state = t.trigger_level, t.trace_state
        self.test_angle, self.test_speed = self.tests.test_angle, self.tests.test_speed
        self.step_angle, self.result_labels = self.tests.step_angle, self.tests.result_labels
        self.load_inertia = self.tests.load_inertia
        self.live_button, self.time_base = bar.live_button, bar.time_base
        self.time_base.currentIndexChanged.connect(
            lambda _i: self.time_plot.show_time_base(self.toolbar.time_base_s()))
        self.cursors_box, self.record_button = bar.cursors_box, bar.record_button
        self.plot = self.time_plot.plot
        self.spectrum_channel = self.spectrum_panel.spectrum_channel
        self.spectrum_label = self.spectrum_panel.spectrum_label

    def dock_under_channels(self, widget: QWidget) -> None:
        """Put ``widget`` (the jog panel) under the channel table, beside the plot."""
        self._left_column.addWidget(widget)

    # --------------------------------------------------------------------------------- channels
    def _shown_channels(self) -> tuple[ScopeChannel, ...]:
        if self._static is not None:
            return self._static.channels
        if self._live is not None:
            return self._live.channels
        return tuple(self.all_channels)

    def _fill_channel_table(self) -> None:
        channels = self._shown_channels()
        # live (or not started) the table lists every channel, ticked or not: an unticked one is not
        # polled, but stays there to be ticked again
        listed = channels if self._static is not None else tuple(self.all_channels)
        self.channel_table.fill(listed, self._visible, self._scale, self._color)
        self._rebuild_curves()
        self.spectrum_panel.set_channels(channels)

    def _color(self, key: str) -> str:
        keys = [c.key for c in self.all_channels]
        return COLORS[keys.index(key) % len(COLORS)] if key in keys else COLORS[hash(key) % len(COLORS)]

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
        self.time_plot.set_curves(self._shown_channels(), self._visible, self._scale, self._color,
                                  live=self._static is None, note=self._shown_note())
        self.time_plot.show_time_base(self.toolbar.time_base_s())

    def _shown_note(self) -> str:
        """What the plots show, in a line under the legend."""
        ticked = sum(1 for c in self.all_channels if self._visible.get(c.key))
        if self._static is not None:
            return (f"Showing {self._static.label} (not live): untick a channel in the table to hide it; "
                    "each unit has its own plot, on one time axis.")
        if self._live is not None:
            return (f"Live: the {ticked} ticked channels of {len(self.all_channels)} are polled; tick "
                    "another in the table to add it (the live view restarts with it).")
        return "Not live: Start live polls the ticked channels; each unit has its own plot."

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
        self.toolbar.set_live(True)
        self.controller.send(ScopeCmd.START, tuple(wanted))
        self.sigLiveChanged.emit(True)

    def stop_live(self) -> None:
        self.controller.send(ScopeCmd.STOP)
        self.stop_recording()
        self._live = None
        self._levels = None
        self._status = None
        self.toolbar.set_live(False)
        self._update_indicator()
        self.time_plot.set_note(self._shown_note())
        self.sigLiveChanged.emit(False)

    def set_paused(self, paused: bool) -> None:
        """Freeze the drawing; acquisition and recording go on."""
        self._paused = bool(paused)
        self.toolbar.set_paused(self._paused)
        self._update_indicator()

    def _on_live_started(self, started: LiveStarted) -> None:
        self._live = started
        # no channel to poll (a drive that answers neither status nor DGR): nothing to draw
        self._levels = None
        if started.channels:
            self._levels = MinMaxLevels(len(started.channels), started.ring.capacity)
            self._levels.append(started.ring.drain())  # what came before this view learnt of it
        self._static = None
        self._status = None
        self.time_plot.show_grid_for_still_data(False)
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
        return self.toolbar.indicator_text()

    def _update_indicator(self) -> None:
        kind, text = IndicatorKind.NOT, "NOT LIVE: not started"
        if self._static is not None:
            text = f"NOT LIVE: showing {self._static.label}"
        elif self._live is not None:
            kind, text = live_indicator(self._status, self._newest_age_s(), self._paused)
        elif self.controller is not None and not self.controller.connected:
            text = "NOT LIVE: no drive connected"
        if self.toolbar.set_indicator(kind, text):
            self.sigIndicatorChanged.emit(text)

    def _refresh(self) -> None:
        """The GUI timer: drain the ring into the levels (and the recorder), draw the live window."""
        live, levels = self._live, self._levels
        self._update_indicator()
        if live is None or levels is None or self._static is not None:
            return
        rows = live.ring.drain()
        if len(rows):
            levels.append(rows)
            if self._recorder is not None:
                try:
                    self._recorder.write(rows)
                except OSError as exc:
                    self._message(f"Recording stopped: {exc}")
                    self.stop_recording()
        if self._paused:
            return
        now = time.monotonic() - live.t0
        self.time_plot.draw_levels(levels, live.channels, now - self.toolbar.time_base_s(), now, self._scale)
        self.frames += 1
        self.sigFrame.emit()
        clock = time.monotonic()
        if clock - self._last_text_update >= TEXT_INTERVAL_S:
            self._last_text_update = clock
            if self.time_plot.cursors_on:
                self._update_cursor_readout()
            self._update_info()

    def _update_info(self) -> None:
        s = self._status
        parts = []
        if s is not None and s.mode is not LiveMode.NONE:
            rate = f"{s.rate_hz:.1f}" if s.live else "—"  # nothing polled: no figure, not the last one
            parts.append(f"{rate} samples/s (line limit {s.limit_hz:.1f}/s)")
            parts.append(f"{s.samples} samples, {s.dropped} dropped")
        if self._recorder is not None:
            parts.append(f"● REC {self._recorder.rows_written} rows → {Path(self._recorder.path).name}")
        self.info_label.setText(" · ".join(parts))

    # -------------------------------------------------------------------------------- static data
    def show_static(self, channels, rows: np.ndarray, label: str, sample_rate_hz: float | None = None,
                    uniform: bool = True) -> None:
        """Show data that is not live (a capture, a file); live acquisition goes on unseen."""
        self._static = _Static(tuple(channels), np.asarray(rows, dtype=float), label, sample_rate_hz, uniform)
        self.time_plot.show_grid_for_still_data(True)
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
        self.time_plot.draw_rows(s.channels, s.rows, self._scale)
        self._update_cursor_readout()

    def back_to_live(self) -> None:
        self._static = None
        self.time_plot.show_grid_for_still_data(False)
        self._fill_channel_table()
        self._update_indicator()

    def fit(self) -> None:
        """Show the whole capture (or the live time base) and scale Y to the visible channels."""
        s = self._static
        if s is not None and len(s.rows):
            columns: dict[str, list[int]] = {}
            factors: dict[str, list[float]] = {}
            for j, c in enumerate(s.channels):
                if self._visible.get(c.key, True):
                    columns.setdefault(c.unit, []).append(j + 1)
                    factors.setdefault(c.unit, []).append(self._scale.get(c.key, 1.0))
            self.time_plot.fit(s.rows, columns, factors, self.toolbar.autoscale.isChecked())
        else:
            self.time_plot.fit(None, (), (), self.toolbar.autoscale.isChecked())

    # ------------------------------------------------------------------------------------ cursors
    def _cursors_toggled(self, on: bool) -> None:
        self.time_plot.set_cursors_on(on)
        self._update_cursor_readout()

    def set_cursors(self, t1_s: float, t2_s: float) -> None:
        if not self.cursors_box.isChecked():
            self.cursors_box.setChecked(True)
        self.time_plot.set_cursors(t1_s, t2_s)
        self._update_cursor_readout()

    def cursor_readout(self) -> dict[str, tuple[float, float, float | None]]:
        """{channel key: (dt s, dvalue, slope per s)} for the visible channels between the cursors."""
        return {key: (d.dt_s, d.dvalue, d.slope_per_s) for key, d in self._cursor_deltas().items()}

    def _cursor_deltas(self) -> dict[str, CursorDelta]:
        out: dict[str, CursorDelta] = {}
        data = self.shown_rows()
        if data is None or len(data[1]) < 2:
            return out
        channels, rows = data
        t1, t2 = self.time_plot.cursor_times()
        for j, c in enumerate(channels):
            if self._visible.get(c.key, True):
                out[c.key] = cursor_delta(rows[:, 0], rows[:, j + 1], t1, t2)
        return out

    def _update_cursor_readout(self, *_args) -> None:
        table = self.time_plot.cursor_table
        if not self.time_plot.cursors_on:
            return
        deltas = self._cursor_deltas()
        if not deltas:
            table.show_message("No data between the cursors yet.")
            return
        channels = {c.key: c for c in self._shown_channels()}
        rows = [CursorRow(channels[key].name, channels[key].unit, self._color(key), d.value_a, d.value_b,
                          d.slope_per_s) for key, d in deltas.items()]
        t_a, t_b = self.time_plot.cursor_axis_times()
        table.show_rows(t_a, t_b, rows, "Time before now" if self.time_plot.live else "Time")

    # ------------------------------------------------------------------------------ data on show
    def shown_rows(self) -> tuple[tuple[ScopeChannel, ...], np.ndarray] | None:
        """(channels, rows [t_s, values...]) of what the plot shows (the live time window)."""
        if self._static is not None:
            return self._static.channels, self._static.rows
        live = self._live
        if live is None or len(live.ring) == 0:
            return None
        data = live.ring.window(copy=True)
        x0, x1 = self.time_plot.x_range()
        i0, i1 = np.searchsorted(data[:, 0], [x0, x1])
        return live.channels, data[max(0, i0 - 1): i1 + 1]

    # ------------------------------------------------------------------------------------- files
    def file_actions(self) -> dict[FileAction, Callable[[str], object]]:
        """What each file action does with the path given."""
        return {FileAction.PNG: self.export_png, FileAction.CSV: self.export_csv,
                FileAction.SAVE: self.save_capture, FileAction.OPEN: self.open_recording,
                FileAction.RECORD: self.start_recording}

    def _ask_path(self, what: FileAction) -> None:
        if what.opens:
            path, _ = QFileDialog.getOpenFileName(self, "Open a recording", "", what.file_filter)
        else:
            path, _ = QFileDialog.getSaveFileName(self, "Save", "", what.file_filter)
        if not path:
            if what is FileAction.RECORD:
                self.toolbar.set_recording(False)
            return
        try:
            self.file_actions()[what](path)
        except (OSError, ValueError) as exc:
            if what is FileAction.RECORD:
                self.toolbar.set_recording(False)
            self._message(str(exc))

    def _metadata(self, sample_rate_hz: float | None, extra: dict | None = None) -> RecordingMetadata:
        c = self.context
        return RecordingMetadata(c.actuator, c.load_inertia_kgm2, c.supply_voltage, sample_rate_hz,
                                 extra=dict(extra or {}))

    def _load_inertia_edited(self, value: float) -> None:
        if value != self.context.load_inertia_kgm2:
            self.context = dataclasses.replace(self.context, load_inertia_kgm2=value)
            self.sigLoadInertiaEdited.emit(value)

    def set_context(self, context: ScopeContext) -> None:
        """Another actuator or driver (resolution, ratio, speed range): channels are rebuilt and
        live stops. Another load inertia or supply voltage only goes into what is recorded next."""
        if context == self.context:
            return
        same_axis = dataclasses.replace(context, load_inertia_kgm2=self.context.load_inertia_kgm2,
                                        supply_voltage=self.context.supply_voltage) == self.context
        self.context = context
        self.load_inertia.blockSignals(True)
        self.load_inertia.setValue(context.load_inertia_kgm2)
        self.load_inertia.blockSignals(False)
        if same_axis:
            return
        self.stop_live()
        self._actuator = context.actuator_data()
        self.all_channels = scope_channels(load_parameter_model(context.driver),
                                           self._actuator.output_resolution_ppr)
        self.tests.set_actuator(actuator_text(context), float(self._actuator.max_speed_rpm))
        self.trigger.set_channels(self.all_channels)
        self._static = None
        self._fill_channel_table()

    @property
    def ratio(self) -> int:
        return int(self._actuator.ratio)

    def _record_clicked(self, checked: bool) -> None:
        if checked:
            self._ask_path(FileAction.RECORD)
        else:
            self.stop_recording()

    def start_recording(self, path) -> None:
        """Record the live samples to ``path`` (fha-recording/1 + extra channels) while plotting."""
        if self._live is None or self._live.mode is LiveMode.NONE:
            raise ValueError("start the live view first: the recording takes the live samples")
        self.stop_recording()
        # start with the samples that come from now on (those before still reach the plot)
        if self._levels is not None:
            self._levels.append(self._live.ring.drain())
        self._recorder = ScopeRecorder(path, self._metadata(None, {
            "source": "fha-studio scope, polled monitor items (host time stamps)"}), self._live.channels,
            self.beside_recording(self._live.t0) if self.beside_recording is not None else None)
        self.toolbar.set_recording(True)

    def stop_recording(self) -> Path | None:
        rec, self._recorder = self._recorder, None
        self.toolbar.set_recording(False)
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
        self.time_plot.export_png(path)
        return Path(path)

    def export_csv(self, path) -> Path:
        """The data on show as CSV: ``t_s`` and one column per channel, ``key [unit]``."""
        data = self.shown_rows()
        if data is None:
            raise ValueError("nothing on show to export")
        fileio.write_text(path, csv_text(*data))  # whole or not at all
        return Path(path)

    def open_recording(self, path) -> None:
        """Show an fha-recording/1 file (contract columns as the scope's channels, extras by name)."""
        shown = recording_rows(read_recording(path), self.all_channels)
        self.show_static(shown.channels, shown.rows, f"file {Path(path).name}", shown.sample_rate_hz,
                         shown.uniform)

    # -------------------------------------------------------------------------------------- trace
    def trace_settings(self) -> TraceSettings:
        return self.trigger.trace_settings()

    def arm_trace(self) -> None:
        try:
            settings = self.trace_settings()
            settings.check()
        except ValueError as exc:
            self._message(str(exc))
            return
        self.trigger.set_state("arming…")
        self.controller.send(ScopeCmd.ARM_TRACE, settings)

    def _on_trace_state(self, text: str) -> None:
        self.trigger.set_state(text)
        if not text.startswith("reading out"):
            self.readout_progress.setVisible(False)

    def _on_readout_progress(self, done: int, total: int, seconds_left: float) -> None:
        """A trace read-out (an armed trace or a test's) block by block, with the time left."""
        bar = self.readout_progress
        bar.setRange(0, max(1, total))
        bar.setValue(done)
        left = "" if seconds_left < 0 else f", about {seconds_left:.0f} s left"
        bar.setFormat(f"Reading out the capture: {done} of {total} samples{left}")
        # as wide as its longest text for this capture (its own size hint is about 90 px): the
        # text is never cut, and the bar does not change its width while it counts
        widest = f"Reading out the capture: {total} of {total} samples, about 999 s left"
        bar.setMinimumWidth(QFontMetrics(bar.font()).horizontalAdvance(widest) + 24)
        bar.setVisible(done < total)

    def _on_trace_done(self, result: TraceResult) -> None:
        self.last_trace = result
        self.readout_progress.setVisible(False)
        stamp = time.strftime("%H:%M:%S", time.localtime(result.captured_at))
        self.show_static(result.channels, result.rows(), f"trace {stamp}",
                         result.sample_rate_hz, True)
        self.sigTraceDone.emit(result)

    # -------------------------------------------------------------------------------------- tests
    def run_test(self, kind: str) -> None:
        angle = self.tests.angle_deg(kind)
        speed = float(self._actuator.max_speed_rpm) if kind == "step" else self.test_speed.value()
        self.tests.started(kind, angle, speed)
        self.controller.send(ScopeCmd.RUN_TEST, {
            "channels": self.all_channels, "angle_deg": angle, "speed_rpm": speed, "kind": kind,
            "output_resolution_ppr": self._actuator.output_resolution_ppr})

    def _on_test_done(self, result: MoveTestResult) -> None:
        self.last_test = result
        self.readout_progress.setVisible(False)
        self.tests.show_result(result)
        c = result.capture
        if c is not None:
            self.show_static(c.channels, c.rows(), f"{result.kind} test capture", c.sample_rate_hz,
                             c.method == "trace")
        self.sigTestDone.emit(result)

    # ----------------------------------------------------------------------------------- spectrum
    def compute_spectrum(self) -> None:
        s = self._static
        key = self.spectrum_panel.channel_key()
        panel = self.spectrum_panel
        if s is None or key is None:
            panel.message("No capture on show: arm a trace (or open a recording) first.")
            return
        if not s.uniform:
            panel.message("This capture is not uniformly sampled (polled): use a drive trace.")
            return
        j = [c.key for c in s.channels].index(key)
        try:
            spec = spectrum(s.rows[:, 0], s.rows[:, j + 1], detrend=panel.detrend())
        except ValueError as exc:
            panel.message(str(exc))
            return
        panel.show_spectrum(spec, s.channels[j].unit)
        self.last_spectrum = spec
        self.plots.setCurrentIndex(1)

    # --------------------------------------------------------------------------------------- misc
    def _on_error(self, text: str) -> None:
        self.trigger.set_state(f"error: {text}")
        self.readout_progress.setVisible(False)
        self._message(text)

    def _message(self, text: str) -> None:
        log.info("scope: %s", text)
        self.info_label.setText(text)
        self.last_message = text

    def shutdown(self) -> None:
        self._timer.stop()
        self.stop_recording()
        self.controller.send(ScopeCmd.STOP)
