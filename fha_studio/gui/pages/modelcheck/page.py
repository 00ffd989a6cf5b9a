"""Page "Model check": load a recording (or take the scope's capture), run the discrepancy
workflow off the GUI thread, and show each step: residuals, where they sit, the effects named
with their parameters, the gap on held-out data, and the re-simulation with the updated model.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QObject, QStandardPaths, QThread, Signal, Slot
from PySide6.QtGui import QFont, QPalette
from PySide6.QtWidgets import (
    QComboBox,
    QDoubleSpinBox,
    QFileDialog,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QMessageBox,
    QPlainTextEdit,
    QPushButton,
    QSplitter,
    QTableWidget,
    QTableWidgetItem,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from fha_studio import clock, fileio
from fha_studio.gui.pages.base import BasePage, PageId
from fha_studio.gui.state import AxisState
from fha_studio.logic.modelcheck import ModelCheckError, ModelCheckResult, run_modelcheck
from fha_studio.logic.modelcheck.candidates import LABELS, label_of, param_words
from fha_studio.logic.modelcheck.signals import bandwidth_bounds_hz, window_for_bandwidth
from fha_studio.logic.wording import manual_units_in_text, unit_words
from fha_studio.recording import Recording, RecordingError, read_recording

COLORS = {"measured": "#1f77b4", "nominal": "#d62728", "updated": "#2ca02c", "residual": "#555555"}
VARIABLE_LABELS = {
    "time": "time",
    "speed": "output speed",
    "position": "output position",
    "acceleration": "acceleration",
    "motor_angle": "motor angle",
    "torque": "torque",
}


class _Worker(QObject):
    """Runs the workflow in its own thread; the GUI thread never waits for it."""

    sigDone = Signal(object, float)  # ModelCheckResult, seconds
    sigFailed = Signal(str)

    @Slot(object)
    def run(self, request: tuple[Recording, int | None]) -> None:
        recording, window = request
        started = time.perf_counter()
        try:
            result = run_modelcheck(recording, window=window)
        except (ModelCheckError, RecordingError, ValueError) as exc:
            self.sigFailed.emit(str(exc))
            return
        except Exception as exc:  # an analysis bug must not kill the thread silently
            self.sigFailed.emit(f"the model check failed: {type(exc).__name__}: {exc}")
            return
        self.sigDone.emit(result, time.perf_counter() - started)


#: The residual tab's torque plot: measured (a recording with the motor current) ...
TORQUE_TITLE = "Motor torque (Kt x current) and what the nominal model needs"
#: ... or read through the speed loop (a bench recording without current).
TORQUE_TITLE_NO_CURRENT = ("Motor torque read through the speed loop (no current recorded) and what "
                           "the nominal model needs")
NO_CURRENT_TORQUE = "read through the speed loop (following error and speed)"
#: The effects table when no effect was named.
NO_EFFECT = ("No missing effect named: the nominal model explains this recording as far as it shows; "
             "the lines below say what was tried, why nothing was named and what this recording "
             "cannot show.")


#: What an empty plot says instead of a made-up 0 to 1 range.
EMPTY_PLOT = "Nothing yet: open a recording and run the model check"


class _WholeLinesText(QPlainTextEdit):
    """A read-only text box that shows whole lines only: whatever height the splitter gives it,
    the part of a line that would not fit is left blank below the text instead of cut. The pad
    round the text is a viewport margin, not the document's (that one scrolls away, and a line
    scrolled to the top would then be cut at the bottom)."""

    PAD_PX = 4

    def __init__(self) -> None:
        super().__init__()
        self.setReadOnly(True)
        self.document().setDocumentMargin(0)
        self.setBackgroundRole(QPalette.ColorRole.Base)  # the pad is the text's white, not the window's
        self.setAutoFillBackground(True)

    def line_height(self) -> int:
        layout = self.document().firstBlock().layout()
        if layout is not None and layout.lineCount() > 0:
            return max(1, round(layout.lineAt(0).height()))
        return max(1, self.fontMetrics().lineSpacing())

    def resizeEvent(self, event) -> None:
        self._fit_whole_lines()
        super().resizeEvent(event)

    def _fit_whole_lines(self) -> None:
        pad = self.PAD_PX
        inner = max(0, self.contentsRect().height() - 2 * pad)
        self.setViewportMargins(pad, pad, pad, pad + inner % self.line_height())

    def setPlainText(self, text: str) -> None:
        super().setPlainText(text)
        self._fit_whole_lines()


def _show_empty(widget: pg.PlotWidget, words: str = EMPTY_PLOT) -> None:
    """``words`` in the middle of the plot and no numbers on its axes: an empty plot says there is
    nothing yet rather than show a range nothing measured."""
    item = widget.getPlotItem()
    item.clear()
    for side in ("left", "bottom"):
        item.getAxis(side).setStyle(showValues=False)
    note = pg.TextItem(words, color="#555", anchor=(0.5, 0.5))
    item.addItem(note, ignoreBounds=True)
    note.setPos(0.5, 0.5)
    item.getViewBox().setRange(xRange=(0.0, 1.0), yRange=(0.0, 1.0), padding=0.0)
    widget.empty_note = note  # what the tests read


def _clear(widget: pg.PlotWidget) -> None:
    """An empty plot about to be drawn: its axes get their numbers back."""
    item = widget.getPlotItem()
    item.clear()
    for side in ("left", "bottom"):
        item.getAxis(side).setStyle(showValues=True)
    item.enableAutoRange()  # the empty plot's fixed range turned it off
    widget.empty_note = None


def _plot(title: str, left: str, bottom: str = "time (s)", *, empty: bool = True) -> pg.PlotWidget:
    widget = pg.PlotWidget(background="w")
    item = widget.getPlotItem()
    item.setTitle(title, color="#222", size="10pt")
    item.setLabel("left", left)
    item.setLabel("bottom", bottom)
    for side in ("left", "bottom"):  # a residual of 0.3 N·m reads "0.3", not "300" and "(x0.001)"
        item.getAxis(side).enableAutoSIPrefix(False)
    item.showGrid(x=True, y=True, alpha=0.25)
    item.addLegend(offset=(10, 5), labelTextColor="#222")
    item.setClipToView(True)
    item.setDownsampling(auto=True, mode="peak")
    widget.default_words = (title, left, bottom)  # what an emptied plot goes back to
    if empty:
        _show_empty(widget)
    else:
        widget.empty_note = None
    return widget


class ModelCheckPage(BasePage):
    """Loads a recording, runs the model check, shows the story step by step."""

    sigRequestRun = Signal(object)  # (Recording, analysis window in samples or None), to the worker
    sigFinished = Signal(object)  # ModelCheckResult, after the views were filled
    sigFailed = Signal(str)

    def __init__(self, session=None, main_window=None):
        super().__init__(main_window)
        self.session = session
        # the declared load inertia is the axis's (a page without a main window keeps its own state)
        self.state = session.state if session is not None else AxisState(parent=self)
        self.main_window = main_window
        self.recording: Recording | None = None
        self.recording_path: Path | None = None  # the file the loaded recording came from
        self._recording_label = ""
        self.result: ModelCheckResult | None = None
        self._running = False
        self._ran_with_current = True  # what the last run had: a current column
        self._build()
        self._thread = QThread(self)
        self._thread.setObjectName("model check")
        self._worker = _Worker()
        self._worker.moveToThread(self._thread)
        self.sigRequestRun.connect(self._worker.run)
        self._worker.sigDone.connect(self._on_done)
        self._worker.sigFailed.connect(self._on_failed)
        self._thread.finished.connect(self._worker.deleteLater)
        self._thread.start()
        self._update_buttons()

    # ---------------------------------------------------------------- layout
    def _build(self) -> None:
        self.open_button = QPushButton("Open recording…")
        self.open_button.clicked.connect(self._open_clicked)
        self.scope_button = QPushButton("Use the scope's capture")
        self.scope_button.setToolTip("The trace, test or recording on show in the Scope page")
        self.scope_button.clicked.connect(self._scope_clicked)
        self.inertia_spin = QDoubleSpinBox()
        self.inertia_spin.setDecimals(4)
        self.inertia_spin.setRange(0.0, 10000.0)
        self.inertia_spin.setSuffix(" kg·m²")
        self.inertia_spin.setKeyboardTracking(False)
        self.inertia_spin.setValue(self.state.load_inertia_kgm2)
        self.inertia_spin.setToolTip("The axis's declared load inertia (the same on the Sizing and Scope "
                                     "pages); the model check uses it, whatever the recording declares")
        self.inertia_spin.valueChanged.connect(self.state.set_load_inertia)
        self.state.sigLoadInertiaChanged.connect(self._declared_inertia_changed)
        self.bandwidth_spin = QDoubleSpinBox()
        self.bandwidth_spin.setDecimals(2)
        self.bandwidth_spin.setSuffix(" Hz")
        self.bandwidth_spin.setRange(0.0, 0.0)
        self.bandwidth_spin.setSpecialValueText("from the data")
        self.bandwidth_spin.setKeyboardTracking(False)
        self.bandwidth_spin.setToolTip(
            "The analysis bandwidth: by default the highest at which the rigid model still explains "
            "the recording; set one yourself within what the recording supports")
        self.run_button = QPushButton("Run model check")
        self.run_button.setDefault(True)
        self.run_button.clicked.connect(self.run)
        self.save_model_button = QPushButton("Save updated model…")
        self.save_model_button.clicked.connect(self._save_model_clicked)
        self.save_report_button = QPushButton("Save report (JSON)…")
        self.save_report_button.clicked.connect(self._save_report_clicked)
        # two rows, so that the page fits a 1024-pixel-wide screen: what to check, then what to do
        bar = QVBoxLayout()
        inputs, actions = QHBoxLayout(), QHBoxLayout()
        for w in (self.open_button, self.scope_button, QLabel("Declared load inertia:"), self.inertia_spin,
                  QLabel("Bandwidth:"), self.bandwidth_spin):
            inputs.addWidget(w)
        for w in (self.run_button, self.save_model_button, self.save_report_button):
            actions.addWidget(w)
        for row in (inputs, actions):
            row.addStretch(1)
            bar.addLayout(row)
        self.source_label = QLabel("No recording loaded. Open an fha-recording/1 file, or capture a move "
                                   "in the Scope page and take it from there.")
        self.source_label.setWordWrap(True)
        self.summary = _WholeLinesText()
        self.summary.setFont(QFont("monospace", 9))
        self.summary.setPlaceholderText("The findings appear here: which effect is missing, its "
                                        "parameters, and the gap before and after on held-out data.")

        self.steps = QTabWidget()
        self.steps.setDocumentMode(True)
        self.steps.addTab(self._build_residual_tab(), "1 Residual")
        self.steps.addTab(self._build_where_tab(), "2 Where it sits")
        self.steps.addTab(self._build_effects_tab(), "3 Effects and what to do")
        self.steps.addTab(self._build_gap_tab(), "4 Gap on held-out data")
        self.steps.addTab(self._build_resim_tab(), "5 Re-simulation")

        split = QSplitter()
        split.setOrientation(pg.QtCore.Qt.Orientation.Vertical)
        split.addWidget(self.summary)
        split.addWidget(self.steps)
        split.setStretchFactor(0, 1)
        split.setStretchFactor(1, 4)
        split.setSizes([130, 520])  # the findings readable at once, the plots below
        layout = QVBoxLayout(self)
        layout.addLayout(bar)
        layout.addWidget(self.source_label)
        layout.addWidget(split, 1)

    def _build_residual_tab(self) -> QWidget:
        self.torque_plot = _plot(TORQUE_TITLE, unit_words("N m"))
        self.residual_plot = _plot("Residual: measured - nominal", "")
        self.residual_plot.setXLink(self.torque_plot)
        return _stack(self.torque_plot, self.residual_plot)

    def _build_where_tab(self) -> QWidget:
        self.where_channel = QComboBox()
        self.where_variable = QComboBox()
        self.where_channel.currentIndexChanged.connect(self._fill_where_variables)
        self.where_variable.currentIndexChanged.connect(self._draw_where)
        self.where_plot = _plot("Residual against", "")
        controls = QHBoxLayout()
        controls.addWidget(QLabel("Channel:"))
        controls.addWidget(self.where_channel)
        controls.addWidget(QLabel("against:"))
        controls.addWidget(self.where_variable)
        key = QLabel("dots: residual of the nominal model; lines: mean per bin before (red) and after "
                     "(green) adding the effects")
        key.setWordWrap(True)  # the page fits a 1024-pixel-wide screen
        controls.addWidget(key, 1)
        controls.addStretch(1)
        box = QWidget()
        layout = QVBoxLayout(box)
        layout.addLayout(controls)
        layout.addWidget(self.where_plot, 1)
        return box

    def _build_effects_tab(self) -> QWidget:
        self.effects_table = QTableWidget(0, 4)
        self.effects_table.setHorizontalHeaderLabels(["Effect", "Size (± one standard deviation)",
                                                      "Could also be", "What to do next"])
        self.effects_table.setWordWrap(True)
        self.effects_table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        self.effects_table.horizontalHeader().setStretchLastSection(True)
        self.effects_table.verticalHeader().setVisible(False)
        self.findings = QPlainTextEdit()
        self.findings.setReadOnly(True)
        self.findings.setPlaceholderText("How each effect was tried, what the data cannot tell apart, "
                                         "what no effect explains and how small an effect the recording "
                                         "could have shown appear here.")
        return _stack(self.effects_table, self.findings)

    def _build_gap_tab(self) -> QWidget:
        self.gap_plots: dict[str, pg.PlotWidget] = {}
        self.gap_box = QWidget()
        self.gap_empty = QLabel(EMPTY_PLOT)  # no plot before a run: no made-up axes either
        self.gap_empty.setAlignment(pg.QtCore.Qt.AlignmentFlag.AlignCenter)
        QVBoxLayout(self.gap_box).addWidget(self.gap_empty, 1)
        return self.gap_box

    def _build_resim_tab(self) -> QWidget:
        self.resim_torque_plot = _plot("Re-simulation of the recorded command: torque", unit_words("N m"))
        self.resim_pos_plot = _plot("Position: simulated - measured", unit_words("arcsec"))
        self.resim_pos_plot.setXLink(self.resim_torque_plot)
        return _stack(self.resim_torque_plot, self.resim_pos_plot)

    def _update_buttons(self) -> None:
        self.run_button.setEnabled(self.recording is not None and not self._running)
        self.inertia_spin.setEnabled(not self._running)
        self.bandwidth_spin.setEnabled(self.recording is not None and not self._running)
        self.save_model_button.setEnabled(self.result is not None and not self._running)
        self.save_report_button.setEnabled(self.result is not None and not self._running)
        self.open_button.setEnabled(not self._running)
        self.scope_button.setEnabled(not self._running and self._scope_view() is not None)

    # ---------------------------------------------------------------- input
    def load_recording(self, path: str | Path) -> Recording:
        """Read a recording (RecordingError names line and field on bad input); nothing changes
        on failure."""
        recording = read_recording(path)
        self._set_recording(recording, f"{Path(path).name}")
        self.recording_path = Path(path)
        return recording

    def _declared_inertia_changed(self, value_kgm2: float) -> None:
        if self.inertia_spin.value() != value_kgm2:
            self.inertia_spin.blockSignals(True)
            self.inertia_spin.setValue(value_kgm2)
            self.inertia_spin.blockSignals(False)
        if self.recording is not None:
            self._describe_recording()

    def _set_recording(self, recording: Recording, label: str) -> None:
        self.recording = recording
        self._recording_label = label
        self.result = None
        low, high = bandwidth_bounds_hz(len(recording), self._sample_interval_s(recording))
        self.bandwidth_spin.setRange(0.0, round(high, 2))
        self.bandwidth_spin.setValue(0.0)
        self.bandwidth_spin.setToolTip(
            f"The analysis bandwidth: by default the highest at which the rigid model still explains "
            f"the recording; this recording supports {low:.2g} to {high:.3g} Hz")
        self._describe_recording()
        self._show_nothing_yet()
        self.summary.setPlainText("Not run yet: press Run model check.")
        self._update_buttons()

    def _describe_recording(self) -> None:
        recording, label = self.recording, self._recording_label
        if recording is None:
            return
        m = recording.metadata
        declared = self.state.load_inertia_kgm2
        optional = {"cmd_pos": recording.cmd_pos_deg, "load_pos": recording.load_pos_deg,
                    "vel": recording.vel_rpm}
        columns = ", ".join(["t", "pos"] + (["current"] if recording.has_current else [])
                            + [c for c, v in optional.items() if v is not None])
        # a bench capture (fha-studio bench import / record) says where its position came from
        bench = m.extra.get("source_pos", "")
        self.source_label.setText(
            f"Recording: {label} — {m.actuator}, {len(recording)} samples over {recording.duration_s:.2f} s, "
            f"columns {columns}. " + (f"Position from {bench}. " if bench else "")
            + ("" if recording.has_current else "No current column (no current probe on the bench). ")
            + ("No load inertia declared in it." if m.load_inertia_kgm2 is None
               else f"Declared load inertia {m.load_inertia_kgm2:g} kg·m².")
            + ("" if m.load_inertia_kgm2 is not None and abs(declared - m.load_inertia_kgm2) <= 1e-12 else
               f" The model check uses the axis's declared load inertia, {declared:g} kg·m².")
        )

    def _open_clicked(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Open a recording", "",
                                              "fha-recording (*.csv);;All (*)")
        if path:
            try:
                self.load_recording(path)
            except (RecordingError, OSError) as exc:
                self._show_error(str(exc))

    def _scope_view(self):
        """The Scope page's view if that page has been opened, else None."""
        if self.main_window is None:
            return None
        scope = self.main_window.built_page(PageId.SCOPE)
        return None if scope is None else scope.view

    def take_scope_capture(self) -> Path:
        """Save the capture on show in the scope and load it here; returns the file written."""
        view = self._scope_view()
        if view is None:
            raise ValueError("the Scope page has not been opened: capture a move there first")
        folder = Path(QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation))
        folder = folder / "captures"
        folder.mkdir(parents=True, exist_ok=True)
        path = view.save_capture(folder / f"capture-{clock.file_stamp()}.csv")
        self._set_recording(read_recording(path), f"the scope's capture ({path})")
        self.recording_path = Path(path)
        return path

    def _scope_clicked(self) -> None:
        try:
            self.take_scope_capture()
        except (ValueError, RecordingError, OSError) as exc:
            self._show_error(str(exc))

    # ---------------------------------------------------------------- run
    @staticmethod
    def _sample_interval_s(recording: Recording) -> float:
        return float(np.median(np.diff(recording.t_s))) if len(recording) > 1 else 1e-3

    def analysis_window(self) -> int | None:
        """The analysis window (samples) the user set as a bandwidth, or None: chosen from the data.

        A bandwidth outside what the recording supports is brought to the nearest bound."""
        hz = self.bandwidth_spin.value()
        if self.recording is None or hz <= 0.0:
            return None
        return window_for_bandwidth(hz, len(self.recording), self._sample_interval_s(self.recording))

    def declared_recording(self) -> Recording | None:
        """The loaded recording with the axis's declared load inertia (what the check runs on)."""
        recording = self.recording
        if recording is None:
            return None
        declared = self.state.load_inertia_kgm2
        recorded = recording.metadata.load_inertia_kgm2
        if recorded is None or abs(declared - recorded) > 1e-12:
            recording = recording.with_declared_load(declared)
        return recording

    def run(self) -> None:
        """Start the workflow on the loaded recording (in the page's thread); sigFinished follows."""
        if self.recording is None or self._running:
            return
        recording = self.declared_recording()
        self._ran_with_current = recording.has_current
        self._running = True
        self._show_nothing_yet()
        self._update_buttons()
        self.summary.setPlainText("Running the model check…")
        self.sigRequestRun.emit((recording, self.analysis_window()))

    def _on_done(self, result: ModelCheckResult, seconds: float) -> None:
        self._running = False
        self.result = result
        lines = result.summary_lines(manual_units=True)
        lines.append(f"Analysis bandwidth {result.bandwidth_hz:.3g} Hz: {result.window_reason}.")
        self.summary.setPlainText("\n".join(lines) + f"\n\n(analysis took {seconds:.1f} s)")
        self._draw_residual(result)
        self._fill_where(result)
        self._fill_effects(result)
        self._draw_gap(result)
        self._draw_resimulation(result)
        self._update_buttons()
        self.sigFinished.emit(result)

    def _on_failed(self, message: str) -> None:
        self._running = False
        self._update_buttons()
        self._show_error(message)

    def _show_error(self, message: str) -> None:
        self._show_nothing_yet()
        self._update_buttons()
        self.summary.setPlainText(f"Cannot run the model check:\n{message}")
        self.sigFailed.emit(message)

    def _show_nothing_yet(self) -> None:
        """Every step back to its empty state: once the summary no longer describes the result on
        show (a new recording, a run started or refused), its curves would be read as the new one's."""
        self.result = None
        for plot in (self.torque_plot, self.residual_plot, self.where_plot, self.resim_torque_plot,
                     self.resim_pos_plot):
            title, left, bottom = plot.default_words
            item = plot.getPlotItem()
            item.setTitle(title, color="#222", size="10pt")
            item.setLabel("left", left)
            item.setLabel("bottom", bottom)
            _show_empty(plot)
        self.burst_regions: list[pg.LinearRegionItem] = []
        for combo in (self.where_channel, self.where_variable):
            combo.blockSignals(True)
            combo.clear()
            combo.blockSignals(False)
        self.effects_table.clearSpans()
        self.effects_table.setRowCount(0)
        self.findings.clear()
        self._remove_gap_plots()
        self.gap_empty.setVisible(True)

    # ---------------------------------------------------------------- drawing
    def _draw_residual(self, r: ModelCheckResult) -> None:
        res = r.residual
        t = res["t_s"]
        _clear(self.torque_plot)
        # without a current the motor's torque is read through the speed loop, not measured
        measured = "measured (Kt x current)" if self._ran_with_current else NO_CURRENT_TORQUE
        self.torque_plot.getPlotItem().setTitle(
            TORQUE_TITLE if self._ran_with_current else TORQUE_TITLE_NO_CURRENT, color="#222", size="10pt")
        self.torque_plot.plot(t, res["torque_measured_nm"], pen=pg.mkPen(COLORS["measured"], width=1),
                              name=measured)
        self.torque_plot.plot(t, res["torque_nominal_nm"], pen=pg.mkPen(COLORS["nominal"], width=1),
                              name="nominal model (J x acceleration)")
        _clear(self.residual_plot)
        self.residual_plot.plot(t, res["torque_residual_nm"], pen=pg.mkPen(COLORS["residual"], width=1),
                                name=f"torque residual ({unit_words('N m')})")
        if "load_diff_arcsec" in res:
            self.residual_plot.plot(t, res["load_diff_arcsec"], pen=pg.mkPen(COLORS["updated"], width=1),
                                    name=f"load encoder - motor encoder ({unit_words('arcsec')})")
        # where a residual no effect explains sits in time (an unmeasured disturbance)
        self.burst_regions = []
        for structure in r.structures:
            for start, stop, _peak in structure.spans:
                region = pg.LinearRegionItem((start, stop), movable=False, brush=pg.mkBrush(214, 39, 40, 50),
                                             pen=pg.mkPen(None))
                self.residual_plot.addItem(region)
                self.burst_regions.append(region)

    def _fill_where(self, r: ModelCheckResult) -> None:
        self.where_channel.blockSignals(True)
        self.where_channel.clear()
        for name in r.where:
            self.where_channel.addItem(_channel_name(name, r), name)
        self.where_channel.blockSignals(False)
        self._fill_where_variables()

    def _fill_where_variables(self, *_args) -> None:
        if self.result is None or self.where_channel.currentData() is None:
            return
        where = self.result.where[self.where_channel.currentData()]
        self.where_variable.blockSignals(True)
        self.where_variable.clear()
        for var in where.before:
            self.where_variable.addItem(VARIABLE_LABELS.get(var, var), var)
        # speed first: friction and offsets show there at a glance
        index = self.where_variable.findData("speed")
        self.where_variable.setCurrentIndex(max(0, index))
        self.where_variable.blockSignals(False)
        self._draw_where()

    def _draw_where(self, *_args) -> None:
        if self.result is None:
            return
        channel, var = self.where_channel.currentData(), self.where_variable.currentData()
        if channel is None or var is None:
            return
        where = self.result.where[channel]
        plot = self.where_plot
        _clear(plot)
        unit = unit_words(where.variable_units.get(var, ""))
        plot.getPlotItem().setTitle(f"{channel} residual against {VARIABLE_LABELS.get(var, var)}",
                                    color="#222", size="10pt")
        plot.getPlotItem().setLabel("bottom", f"{VARIABLE_LABELS.get(var, var)} ({unit})")
        plot.getPlotItem().setLabel("left", f"residual ({unit_words(where.unit)})")
        x = where.variables[var]
        plot.plot(x, where.residual_before, pen=None, symbol="o", symbolSize=3,
                  symbolBrush=pg.mkBrush(120, 120, 120, 90), symbolPen=None, name="residual (nominal)")
        for binned, color, label in ((where.before[var], COLORS["nominal"], "mean per bin, nominal"),
                                     (where.after[var], COLORS["updated"], "mean per bin, updated")):
            ok = binned.count > 0
            plot.plot(binned.centers[ok], binned.mean[ok], pen=pg.mkPen(color, width=2), symbol="s",
                      symbolSize=5, symbolBrush=color, name=label)
            plot.addItem(pg.ErrorBarItem(x=binned.centers[ok], y=binned.mean[ok], height=2 * binned.sem[ok],
                                         pen=pg.mkPen(color)))

    def _fill_effects(self, r: ModelCheckResult) -> None:
        table = self.effects_table
        table.setRowCount(0)
        for e in r.effects:
            row = table.rowCount()
            table.insertRow(row)
            size = "; ".join(
                param_words(k, v, e.units.get(k, ""), e.uncertainty.get(k)) for k, v in e.params.items()
            )
            if e.basis:  # read from a part of the recording (a coast), not the whole: a line each
                size += "\n" + e.basis.replace("; ", ";\n")
            also = " or ".join(label_of(a) for a in e.alternatives) or "—"
            for col, text in enumerate((e.label, size, also, e.advice)):
                item = QTableWidgetItem(text)
                item.setToolTip(text)
                table.setItem(row, col, item)
        if not r.effects:  # an empty table would say nothing: the findings below say why
            table.insertRow(0)
            item = QTableWidgetItem(NO_EFFECT)
            item.setToolTip(NO_EFFECT)
            table.setItem(0, 0, item)
            table.setSpan(0, 0, 1, table.columnCount())
        else:
            table.clearSpans()
        table.resizeRowsToContents()
        self.findings.setPlainText(manual_units_in_text("\n".join(_findings_in_words(r))))

    def _remove_gap_plots(self) -> None:
        """Take the held-out gap plots of the last result off the gap tab."""
        layout = self.gap_box.layout()
        assert isinstance(layout, QVBoxLayout)
        for plot in self.gap_plots.values():
            layout.removeWidget(plot)
            plot.deleteLater()
        self.gap_plots.clear()

    def _draw_gap(self, r: ModelCheckResult) -> None:
        self._remove_gap_plots()
        layout = self.gap_box.layout()
        assert isinstance(layout, QVBoxLayout)
        self.gap_empty.setVisible(not r.gap and not r.coasts)
        for name, gap in r.gap.items():
            unit = unit_words(gap.unit)
            plot = _plot(f"{_channel_name(name, r)}: {_num(gap.rms_before)} → {_num(gap.rms_after)} "
                         f"{unit} rms on held-out stretches (shaded): how much better the updated model "
                         "explains data it was not fitted on", unit, empty=False)
            for start, stop in gap.blocks:
                region = pg.LinearRegionItem((start, stop), movable=False,
                                             brush=pg.mkBrush(255, 200, 0, 40), pen=pg.mkPen(None))
                plot.addItem(region)
            plot.plot(gap.t_s, gap.measured, pen=pg.mkPen(COLORS["measured"], width=1),
                      name="measured residual of the nominal model")
            plot.plot(gap.t_s, gap.predicted_heldout, pen=pg.mkPen(COLORS["updated"], width=2),
                      name="predicted by the added effects (not fitted on these blocks)")
            self.gap_plots[name] = plot
            layout.addWidget(plot, 1)
        for coast in r.coasts:  # a coast after an alarm: the servo off, friction alone slows the axis
            before, after = _num(coast.rms_before_rpm), _num(coast.rms_after_rpm)
            title = (f"Coast after the alarm at {coast.alarm_s:.2f} s: speed {before} → {after} r/min rms "
                     "against the recorded one, each model from the coast's start")
            plot = _plot(title, "output speed (r/min)", empty=False)
            curves = ((coast.speed_measured_rpm, COLORS["measured"], 1, "measured"),
                      (coast.speed_nominal_rpm, COLORS["nominal"], 2, "nominal model (no friction)"),
                      (coast.speed_updated_rpm, COLORS["updated"], 2, "updated model"))
            for y, color, width, label in curves:
                plot.plot(coast.t_s, y, pen=pg.mkPen(color, width=width), name=label)
            self.gap_plots[f"coast {coast.alarm_s}"] = plot
            layout.addWidget(plot, 1)

    def _draw_resimulation(self, r: ModelCheckResult) -> None:
        _clear(self.resim_torque_plot)
        _clear(self.resim_pos_plot)
        s = r.resimulation
        if s is None:
            self.resim_torque_plot.getPlotItem().setTitle("No re-simulation for this recording")
            for plot in (self.resim_torque_plot, self.resim_pos_plot):
                _show_empty(plot, "No re-simulation for this recording")
            return
        column, _, how = s.command.partition(" ")  # "cmd_pos through the loop identified ..."
        command = " ".join([COMMAND_WORDS.get(column, column), *([how] if how else [])])
        self.resim_torque_plot.getPlotItem().setTitle(
            f"Re-simulation of the recorded {command}: torque {_num(s.rms_nominal_nm)} → "
            f"{_num(s.rms_updated_nm)} {unit_words('N m')} rms (nominal → updated)", color="#222", size="10pt"
        )
        for y, color, label in ((s.torque_measured_nm, COLORS["measured"], "measured"),
                                (s.torque_nominal_nm, COLORS["nominal"], "nominal model"),
                                (s.torque_updated_nm, COLORS["updated"], "updated model")):
            self.resim_torque_plot.plot(s.t_s, y, pen=pg.mkPen(color, width=1), name=label)
        arcsec = 3600.0
        for y, color, label in ((s.pos_nominal_deg, COLORS["nominal"], "nominal model"),
                                (s.pos_updated_deg, COLORS["updated"], "updated model")):
            self.resim_pos_plot.plot(s.t_s, (y - s.pos_measured_deg) * arcsec, pen=pg.mkPen(color, width=1),
                                     name=label)

    # ---------------------------------------------------------------- output
    def save_model(self, path: str | Path) -> Path:
        if self.result is None:
            raise ValueError("run the model check first")
        self.result.write_model(path)
        return Path(path)

    def save_report(self, path: str | Path) -> Path:
        if self.result is None:
            raise ValueError("run the model check first")
        fileio.write_text(path, json.dumps(self.result.to_json(), indent=2))
        return Path(path)

    def _save_model_clicked(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Save the updated model", "axis-model.toml",
                                              "TOML (*.toml)")
        if path:
            try:
                self.save_model(path)
            except (OSError, ValueError) as exc:  # fileio.FileProblem: one line naming the file
                QMessageBox.warning(self, "Model not saved", str(exc))

    def _save_report_clicked(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Save the report", "modelcheck.json", "JSON (*.json)")
        if path:
            try:
                self.save_report(path)
            except (OSError, ValueError) as exc:
                QMessageBox.warning(self, "Report not saved", str(exc))

    def showEvent(self, event) -> None:
        self._update_buttons()  # the scope may have been opened since
        super().showEvent(event)

    def shutdown(self) -> None:
        """End the analysis thread (waits for a running analysis to finish, at most 30 s)."""
        if self._thread.isRunning():
            self._thread.quit()
            if not self._thread.wait(30000):
                import logging

                logging.getLogger(__name__).error("model check thread did not stop")


def _stack(*widgets: QWidget) -> QWidget:
    box = QWidget()
    layout = QVBoxLayout(box)
    layout.setContentsMargins(0, 0, 0, 0)
    for w in widgets:
        layout.addWidget(w, 1)
    return box


def _num(x: float) -> str:
    if not np.isfinite(x):
        return "?"
    return f"{x:.3g}"


CHANNEL_WORDS = {
    "torque": "Torque (motor current)",
    "position": "Position (load encoder against motor encoder)",
    "current": "Motor current",
}
#: The torque channel of a recording without current: read through the speed loop.
TORQUE_THROUGH_LOOP = "Torque (read through the speed loop)"
#: The column a re-simulation was driven by.
COMMAND_WORDS = {"cmd_pos": "command position", "pos": "position"}


def _channel_name(name: str, r: ModelCheckResult) -> str:
    """A checked channel in words; the torque of a recording without current is not the motor
    current's (it is read through the loop from the following error and the speed)."""
    current = r.channel_status.get("current")
    if name == "torque" and current is not None and not current.checked:
        return TORQUE_THROUGH_LOOP
    return CHANNEL_WORDS.get(name, name)
GATE_WORDS = {
    "evidence": "the data do not show it clearly enough",
    "held_out": "it does not explain held-out data better",
    "floor": "too small to matter",
    "precision": "the recording does not pin its size down",
    "creep": "only the creep into a target shows it (the encoder's pulses rule the drive's speed there)",
    "noise_peak": "no larger than what noise gives at other frequencies",
    "sign": "its sign is not physical (friction cannot push)",
}


def _better(before: float, after: float) -> str:
    """How much better a model explains held-out data, in words."""
    if before <= 0 or not np.isfinite(before) or not np.isfinite(after):
        return "does not change how well held-out data are explained"
    change = 100.0 * (before - after) / before
    return f"explains held-out data {change:.0f} % better ({before:.3g} → {after:.3g}"


def _findings_in_words(r: ModelCheckResult) -> list[str]:
    """The Effects tab's text: how each effect was tried, in the words a person uses."""
    out = [f"Analysis bandwidth {r.bandwidth_hz:.3g} Hz: {r.window_reason}.", ""]
    for ch, status in r.channel_status.items():
        name = _channel_name(ch, r)
        if not status.checked:
            out.append(f"{name}: not checked, it {status.reason}.")
            continue
        report = r.channels.get(ch)
        out.append(f"{name}: checked.")
        if report is None:
            continue
        for number, step in enumerate(report.steps, 1):
            if step.kind == "nominal":
                verdict = "re-fitted" if step.chosen else "kept as declared (the data show no clear change)"
                out.append(f"  Step {number}: the declared inertia checked first: {verdict}.")
                continue
            if step.kind == "backward":
                dropped = label_of(step.chosen) if step.chosen else "nothing"
                out.append(f"  Step {number}: the named effects checked together; {dropped} dropped: "
                           "the others explain the data without it.")
                continue
            chosen = next((t for t in step.trials if t.id == step.chosen), None)
            if chosen is not None:
                better = _better(chosen.cv_rms_before, chosen.cv_rms_after)
                unit = unit_words(report.unit)
                out.append(f"  Step {number}: {label_of(chosen.id)} named: it {better} {unit} rms).")
            else:
                out.append(f"  Step {number}: no further effect passes every test.")
            for t in step.trials:
                if t.accepted or t.id == step.chosen:
                    continue
                why = "; ".join(GATE_WORDS.get(g, g) for g in t.failed) or "another explains it better"
                out.append(f"      {label_of(t.id)}: not named: {why}.")
    for e in r.effects:
        if e.basis:  # not one of the channel's steps above
            out.append(f"{e.label}: named {e.basis}.")
    for a in r.ambiguities:
        out.append(f"{label_of(a.chosen)} or {label_of(a.alternative)}: the data cannot tell them apart. "
                   f"To tell them apart: {a.separating_test}.")
    for st in r.structures:
        if st.spans:
            where = "at " + ", ".join(f"{x:.2f}-{y:.2f} s" for x, y, _ in st.spans[:8])
        else:
            where = f"against {VARIABLE_LABELS.get(st.variable, st.variable)}"
        out.append(f"A residual no effect explains in the {st.channel} channel, {where} "
                   f"({100 * st.fraction:.0f} % of what is left); shaded on the Residual tab.")
    if r.detection_limits:
        out.append("")
        out.append("The smallest effect of each kind this recording could have shown:")
        for d in r.detection_limits:
            if d.param_unit == "1":  # a ratio: how far from 1 it could have been seen
                out.append(f"  {LABELS.get(d.id, d.id)}: ±{100 * d.value:.2g} %")
            else:
                out.append(f"  {LABELS.get(d.id, d.id)}: {param_words(d.param, d.value, d.param_unit)}")
    out.append("")
    changes = ", ".join(e.label.lower() for e in r.effects) or "no change"
    out.append(f"Updated model (Save updated model… writes it for the simulated drive): {changes}.")
    return out
