"""The Tuning page: the speed loop's frequency response with the gear's resonance marked, the
load inertia from it, margins with the present gains, and proposed tune items.

The work is the logic's (``logic/tuning``); it runs in the link thread (``Call``), STOP ends it
(``link.abort_event``). The excitation is shown before it starts, and it starts either after a
countdown the person can cancel, or while a hold-to-run button is held (``HoldButton``, as jog's:
letting go, leaving the page or the window ends it, and so does a GUI that stops renewing the
hold's lease, as a held jog's). Applying the proposal goes through the session's write path
(backup before the first write, each write verified), then the response is measured again. A drive
that cannot be excited (the manual's commands only) gets the proposal as a front-panel worksheet.
"""

from __future__ import annotations

import html
import time
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
import pyqtgraph as pg
from pyqtgraph import exporters
from PySide6.QtCore import QBuffer, QIODevice, QRectF, QSettings, Qt, QTimer, Signal
from PySide6.QtWidgets import (
    QComboBox,
    QDoubleSpinBox,
    QGridLayout,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QPlainTextEdit,
    QPushButton,
    QSizePolicy,
    QSplitter,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from fha_studio import clock, fileio
from fha_studio.gui.link import JOG_LEASE_RENEW_MS, JOG_LEASE_S
from fha_studio.gui.link_requests import Call, LinkInfo, LinkReply
from fha_studio.gui.motion_controls import HoldButton
from fha_studio.gui.pages.base import BasePage, PageId
from fha_studio.gui.pages.tuning_bench import BenchTuningPanel
from fha_studio.gui.plot_axes import PlainDecadeAxis
from fha_studio.gui.unit_spacing import units_kept
from fha_studio.gui.widgets import HiddenWhileEmptyLabel, scrolling
from fha_studio.hardware.parameters import Mode
from fha_studio.hardware.sim.axis import DEFAULT_SERVO_RATE_HZ
from fha_studio.logic.tuning.excitation import BiasDirection, plan_excitation
from fha_studio.logic.tuning.measure import NEEDED
from fha_studio.logic.tuning.propose import AIMS, TUNE_KEYS, Proposal, Tuner
from fha_studio.logic.tuning.record import TuningRecord, result_figure_words, tuning_notes
from fha_studio.logic.tuning.response import COHERENCE_TRUSTED
from fha_studio.logic.tuning.session import (
    declared_model,
    drive_clock,
    measure_report,
    planned_travel,
    tuner_for,
)
from fha_studio.logic.tuning.travel import TravelRefused

COUNTDOWN_S = 3
#: the plots' rows (magnitude, phase, coherence): the least height of each [px] and its share of more;
#: the magnitude plot keeps room for its four markers' labels beside its curves
PLOT_ROWS = {1: (135, 5), 2: (68, 3), 3: (92, 2)}
#: the clear space kept around a marker's label [px]
MARKER_LABEL_MARGIN_PX = 3.0
#: a marker label's line with its margins above and below [px]
MARKER_LABEL_ROOM_PX = 28
#: the plots' margin and the space between their rows [px]
PLOTS_SPACING_PX = 2
#: the space between the page's rows above the plots [px]
PANEL_SPACING_PX = 3
#: the plots' least height: the rows', the legend's line (22 px), the spaces between and the margins
PLOTS_MIN_HEIGHT_PX = sum(least_px for least_px, _stretch in PLOT_ROWS.values()) + 22 + 5 * PLOTS_SPACING_PX
HOLD_TIP = ("Hold (mouse or Space key) to run the excitation until the measurement is done; letting go, "
            "leaving the page or the window ends it")
#: the bias speed's choices: (words, BiasDirection); the jog's rotation (CW/CCW) is in the plan
BIAS_CHOICES = (("FWD jog", BiasDirection.FWD), ("REV jog", BiasDirection.REV),
                ("In place (no jog)", BiasDirection.NONE))
BIAS_TIP = ("The slow jog the excitation rides on, so the axis never reverses and sticks on its friction: "
            "FWD or REV, whichever way the axis has room to turn (the plan says how far, and checks it "
            "against the limit switches' angles where the procedures recorded them). In place: for an "
            "axis that may not turn that far; the friction then spoils the low frequencies")
FIGURE_ROWS = ("gain_margin_db", "phase_margin_deg", "overshoot_pct", "settling_ms")
#: the table's words for the figures beside the tune items
FIGURE_WORDS = {"gain_margin_db": "Gain margin [dB]", "phase_margin_deg": "Phase margin [°]",
                "overshoot_pct": "Overshoot of a move [%]", "settling_ms": "Settling time of a move [ms]"}


def _cell(key: str, value: Any, measured_to_hz: float | None = None) -> str:
    """A figure in the table: a gain margin without a phase crossing (a measured one: none within
    the measured band, ``measured_to_hz``), and a move in position as its command arrives, in words."""
    if value is None:
        if key != "gain_margin_db":
            return "—"
        return f"none to {measured_to_hz:.0f} Hz" if measured_to_hz else "none: phase never −180°"
    if key == "settling_ms" and value == 0:
        return "0 (at arrival)"
    return f"{value:g}"


def _item_words(item: Any) -> str:
    """A tune item as the front panel knows it (tune mode): its number, name and unit."""
    return f"{item.number} {item.name}" + (f" [{item.unit}]" if item.unit else "")


def _dashed(colour: str) -> Any:
    return pg.mkPen(colour, width=1, style=pg.QtCore.Qt.PenStyle.DashLine)


def tuning_plot_title(n: int, record: TuningRecord, who: str) -> str:
    """The report's words over a tuning's plot: when, who, the aim and the figures before / after."""
    def fig(result: Any, key: str, unit: str) -> str:
        return result_figure_words(result or {}, key, unit, manual_units=True)

    words = f"Tuning {n} ({record.at}, {record.who or who or 'operator not named'}): "
    b, a = record.before, record.after
    if a is None:
        return (words + f"frequency response measured: resonance {fig(b, 'resonance_hz', 'Hz')}, gain margin "
                f"{fig(b, 'gain_margin_db', 'dB')}, phase margin {fig(b, 'phase_margin_deg', 'deg')}")
    return (words + f"before (dashed) and after (solid) the {record.aim} gains;\nresonance "
            f"{fig(b, 'resonance_hz', 'Hz')}; gain margin {fig(b, 'gain_margin_db', 'dB')} -> "
            f"{fig(a, 'gain_margin_db', 'dB')}, phase margin {fig(b, 'phase_margin_deg', 'deg')} -> "
            f"{fig(a, 'phase_margin_deg', 'deg')}, bandwidth {fig(b, 'bandwidth_hz', 'Hz')} -> "
            f"{fig(a, 'bandwidth_hz', 'Hz')}")


def _trusted_curve(data: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frequency, magnitude and phase of a measured response at its trusted bins (coherence at
    least 0.9; the others NaN, a gap in the curve), the phase unwrapped over those bins alone."""
    f = np.asarray(data["freq_hz"], float)
    mag = np.asarray(data["magnitude_db"], float).copy()
    phase = np.asarray(data["phase_deg"], float).copy()
    ok = np.asarray(data["coherence"], float) >= COHERENCE_TRUSTED
    if ok.any():
        kept = np.degrees(np.unwrap(np.radians(phase[ok])))
        phase[ok] = kept - 360.0 * np.round(kept[0] / 360.0)  # the first trusted bin within +/-180 deg
    mag[~ok] = np.nan
    phase[~ok] = np.nan
    return f, mag, phase


def export_response_png(record: TuningRecord, title: str, path: Path) -> Path:
    """Magnitude and phase of a tuning's measurements (the closed speed loop and the plant, at the
    bins of coherence at least 0.9; before dashed, after solid) drawn on white for paper and written
    as a PNG, whole or not at all."""
    width, height = 1100, 760
    view = pg.GraphicsLayoutWidget()
    view.setBackground("w")
    head, _, figures = title.partition("\n")
    view.addLabel(f"{html.escape(head)}<br>{html.escape(figures)}" if figures else html.escape(title),
                  row=0, col=0, color="k", size="10pt")
    legend = pg.LegendItem(colCount=2, labelTextColor="k")
    view.addItem(legend, row=1, col=0)
    mag = view.addPlot(row=2, col=0, title="Magnitude [dB]", axisItems={"bottom": PlainDecadeAxis("bottom")})
    phase = view.addPlot(row=3, col=0, title="Phase [°]", axisItems={"bottom": PlainDecadeAxis("bottom")})
    phase.setLabel("bottom", "frequency (bins of coherence at least 0.9)", units="Hz")
    phase.getAxis("bottom").enableAutoSIPrefix(False)  # a Bode plot in Hz, 1000 not 1 kHz
    for plot in (mag, phase):
        plot.setLogMode(x=True, y=False)
        plot.showGrid(x=True, y=True, alpha=0.3)
        for side in ("left", "bottom"):
            plot.getAxis(side).setTextPen("k")
    phase.setXLink(mag)
    for result, style, when in ((record.before, Qt.PenStyle.DashLine, "before"),
                                (record.after, Qt.PenStyle.SolidLine, "after")):
        if result is None:
            continue
        for key, colour, words in (("frequency_response", "#1f4e9c", "speed loop"),
                                   ("plant_response", "#c05000", "plant")):
            data = result.get(key)
            if not data:
                continue
            pen = pg.mkPen(colour, width=2, style=style)
            f, m, p = _trusted_curve(data)
            legend.addItem(mag.plot(f, m, pen=pen, connect="finite"), f"{words}, {when}")
            phase.plot(f, p, pen=pen, connect="finite")
    view.ci.setGeometry(QRectF(0.0, 0.0, width, height))  # not shown: lay it out at the paper's size
    exporter = exporters.ImageExporter(view.ci)
    exporter.parameters()["width"] = width
    image = exporter.export(toBytes=True)
    view.deleteLater()
    buffer = QBuffer()
    buffer.open(QIODevice.OpenModeFlag.WriteOnly)
    if not image.save(buffer, "PNG"):
        raise OSError(f"{path}: the tuning plot could not be made a PNG")
    fileio.write_bytes(path, bytes(buffer.data().data()))
    return path


def _same_place(measured_hz: float, predicted_hz: float) -> bool:
    """A prediction that marks the measured place on the plot (within 3 %, a few pixels)."""
    return abs(predicted_hz / measured_hz - 1.0) <= 0.03


def _overlaps(bands: list[tuple[float, float]], low: float, high: float) -> int:
    """How many of the (bottom, top) ``bands`` reach into ``low`` ... ``high``."""
    return sum(1 for bottom, top in bands if bottom < high and low < top)


class TuningPage(BasePage):
    """See the module docstring."""

    sigMeasured = Signal(object)  # the measurement's dict (tune measure's JSON)
    sigProposed = Signal(object)  # Proposal
    sigApplied = Signal(object)  # the measurement after the writes

    def __init__(self, session: Any, main_window: Any = None) -> None:
        super().__init__()
        self.session = session
        self.main_window = main_window
        self.link = session.link
        self.result: dict[str, Any] | None = None
        self.proposal: Proposal | None = None
        self.records: list[TuningRecord] = []
        self._countdown = 0
        self._timer = QTimer(self)
        self._timer.setInterval(1000)
        self._timer.timeout.connect(self._tick)
        self._excitable = False

        # two fields a row: four rows of one field took the height the plots need at 1280 x 720
        form = QGridLayout()
        self.actuator_edit = QLineEdit(session.state.actuator_code or "")
        self.actuator_edit.setPlaceholderText("model code, e.g. FHA-25C-50-US250")
        self.load_spin = QDoubleSpinBox()
        self.load_spin.setRange(0.0, 1.0e5)
        self.load_spin.setDecimals(4)
        self.load_spin.setSuffix(" kg·m²")
        self.load_spin.setValue(float(session.state.load_inertia_kgm2))
        self.aim_combo = QComboBox()
        self.aim_combo.addItems(list(AIMS))
        self.aim_combo.setCurrentText("standard")
        self.amplitude_spin = QDoubleSpinBox()
        self.amplitude_spin.setRange(0.0, 100.0)
        self.amplitude_spin.setDecimals(4)
        self.amplitude_spin.setSpecialValueText("the largest the axis allows")
        self.amplitude_spin.setSuffix(" r/min")
        self.bias_combo = QComboBox()
        for words, direction in BIAS_CHOICES:
            self.bias_combo.addItem(words, direction.value)
        self.bias_combo.setToolTip(BIAS_TIP)
        # a new choice is a new plan: the excitation is shown again before it starts
        self.bias_combo.currentIndexChanged.connect(self._plan_outdated)
        # three fields a row: more rows took the height the plots need at 1280 x 720
        for n, (words, field) in enumerate((("Actuator", self.actuator_edit),
                                            ("Declared load inertia", self.load_spin),
                                            ("Aim", self.aim_combo),
                                            ("Excitation amplitude", self.amplitude_spin),
                                            ("&Bias speed", self.bias_combo))):
            label = QLabel(words)
            label.setBuddy(field)
            form.addWidget(label, n // 3, 2 * (n % 3))
            form.addWidget(field, n // 3, 2 * (n % 3) + 1)
        for column in (1, 3, 5):
            form.setColumnStretch(column, 1)

        buttons = QHBoxLayout()
        self.plan_button = QPushButton("Show the excitation")
        self.start_button = QPushButton(f"Start measuring ({COUNTDOWN_S} s countdown)")
        self.cancel_button = QPushButton("Cancel")
        self.hold_button = HoldButton("Hold to measure")
        self.hold_button.setToolTip(HOLD_TIP)
        self.hold_button.setEnabled(False)
        self.hold_button.sigHeld.connect(self.hold_started)
        self.hold_button.sigReleased.connect(self._hold_released)
        self._held = False  # read in the link thread: the hold's state and its lease
        self._lease_s = 0.0
        self._lease_timer = QTimer(self)
        self._lease_timer.setInterval(JOG_LEASE_RENEW_MS)
        self._lease_timer.timeout.connect(self._renew_lease)
        self.propose_button = QPushButton("Propose gains")
        self.apply_button = QPushButton("Apply proposed gains")
        self.use_inertia_button = QPushButton("Use the estimate as the load inertia")
        self.use_inertia_button.setEnabled(False)
        self.use_inertia_button.clicked.connect(self.use_inertia_estimate)
        for b in (self.plan_button, self.start_button, self.cancel_button, self.hold_button,
                  self.propose_button, self.apply_button, self.use_inertia_button):
            buttons.addWidget(b)
        self.start_button.setEnabled(False)
        self.cancel_button.setEnabled(False)
        self.apply_button.setEnabled(False)
        self.plan_button.clicked.connect(self.show_plan)
        self.start_button.clicked.connect(self.start_countdown)
        self.cancel_button.clicked.connect(self.cancel_countdown)
        self.propose_button.clicked.connect(self.propose)
        self.apply_button.clicked.connect(self.apply)

        self.plan_label = QLabel("Connect a drive, then show the excitation before it starts.")
        self.plan_label.setWordWrap(True)
        self.status_label = HiddenWhileEmptyLabel()
        self.result_label = HiddenWhileEmptyLabel()
        self.warning_label = HiddenWhileEmptyLabel()
        self.warning_label.setStyleSheet("color: #b00000; font-weight: bold")

        self.plots = pg.GraphicsLayoutWidget()
        self.plots.setBackground("w")
        # the legend in a row of its own above the plots (as the scope's): inside the magnitude
        # plot it covered the resonance markers' labels
        self.legend = pg.LegendItem(colCount=3, labelTextColor="#303030")
        self.legend.layout.setContentsMargins(4, 0, 4, 0)  # a line of its own, no more
        self.plots.addItem(self.legend, row=0, col=0)
        # each plot's quantity on its value axis, not in a title line of its own: the page fits
        # at 1280 x 720 with the magnitude plot high enough for its markers' labels
        self.mag_plot = self.plots.addPlot(row=1, col=0, axisItems={"bottom": PlainDecadeAxis("bottom")})
        self.phase_plot = self.plots.addPlot(row=2, col=0, axisItems={"bottom": PlainDecadeAxis("bottom")})
        self.coh_plot = self.plots.addPlot(row=3, col=0, axisItems={"bottom": PlainDecadeAxis("bottom")})
        for plot, words, units in ((self.mag_plot, "Magnitude", "dB"), (self.phase_plot, "Phase", "°"),
                                   (self.coh_plot, "Coherence", None)):
            plot.setLogMode(x=True, y=False)
            plot.showGrid(x=True, y=True, alpha=0.3)
            plot.setLabel("left", words, units=units)
            plot.getAxis("left").setWidth(62)  # the three value axes line up
            plot.getAxis("left").enableAutoSIPrefix(False)  # dB and degrees take no k or m
        self.phase_plot.setXLink(self.mag_plot)
        self.coh_plot.setXLink(self.mag_plot)
        self.coh_plot.setLabel("bottom", "frequency", units="Hz")
        self.coh_plot.getAxis("bottom").enableAutoSIPrefix(False)  # a Bode plot in Hz, 1000 not 1 kHz
        for plot in (self.mag_plot, self.phase_plot):  # one frequency scale, under the three (a Bode plot's)
            plot.getAxis("bottom").setStyle(showValues=False)
        self.mag_plot.getViewBox().sigRangeChanged.connect(self._place_marker_labels)
        self.mag_plot.getViewBox().sigResized.connect(self._magnitude_resized)
        self.coh_plot.setYRange(0.0, 1.05)
        self.curves = {
            "closed": (self.mag_plot.plot(pen=pg.mkPen("#1f4e9c", width=2)),
                       self.phase_plot.plot(pen=pg.mkPen("#1f4e9c", width=2)),
                       self.coh_plot.plot(pen=pg.mkPen("#1f4e9c", width=2))),
            "plant": (self.mag_plot.plot(pen=pg.mkPen("#c05000", width=2)),
                      self.phase_plot.plot(pen=pg.mkPen("#c05000", width=2)),
                      self.coh_plot.plot(pen=pg.mkPen("#c05000", width=2))),
            # what the linearised loop predicts, beside a bench measurement
            "predicted": (self.mag_plot.plot(pen=_dashed("#1f4e9c")),
                          self.phase_plot.plot(pen=_dashed("#1f4e9c")), self.coh_plot.plot()),
        }
        self.legend.addItem(self.curves["closed"][0], "speed loop (closed)")
        self.legend.addItem(self.curves["plant"][0], "plant (speed per torque)")
        self.markers: list[Any] = []

        self.table = QTableWidget(len(TUNE_KEYS) + len(FIGURE_ROWS), 3)
        # the present and proposed figures are the model's (the proposal is computed on it), the
        # measured ones are beside the plots and in the last column
        self.table.setHorizontalHeaderLabels(["present\n(model)", "proposed\n(model)", "measured\nafter"])
        self.table.setToolTip("Tune mode items of the front panel, and the figures the model gives with "
                              "them; a move that settles in 0 ms is within the in-position range as its "
                              "command arrives")
        model = session.parameter_model
        self.table.setVerticalHeaderLabels(
            [*(_item_words(model.by_key(k)) for k in TUNE_KEYS), *(FIGURE_WORDS[k] for k in FIGURE_ROWS)])
        self.worksheet = QPlainTextEdit()
        self.worksheet.setReadOnly(True)
        self.worksheet.setPlaceholderText("The front-panel worksheet appears here for a drive without "
                                          "parameter access over CN3.")
        # the plots take the width, the figures and the worksheet a column beside them; the
        # magnitude plot (where the resonances are marked) has half the plots' height, the
        # coherence (0 to 1) the least. Below these heights the page scrolls instead of squeezing
        # the plots into a line each: the page fits at 1280 x 720
        self.plots.setMinimumHeight(PLOTS_MIN_HEIGHT_PX)
        self.plots.ci.setContentsMargins(*(PLOTS_SPACING_PX,) * 4)
        self.plots.ci.layout.setSpacing(PLOTS_SPACING_PX)
        for row, (least_px, stretch) in PLOT_ROWS.items():
            self.plots.ci.layout.setRowMinimumHeight(row, least_px)
            self.plots.ci.layout.setRowStretchFactor(row, stretch)
        self.table.setMinimumHeight(200)
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        self.table.verticalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        side = QWidget()
        side_layout = QVBoxLayout(side)
        side_layout.setContentsMargins(0, 0, 0, 0)
        side_layout.addWidget(self.table, 3)
        side_layout.addWidget(self.worksheet, 2)
        lower = QSplitter(Qt.Orientation.Horizontal)
        lower.addWidget(self.plots)
        lower.addWidget(side)
        lower.setStretchFactor(0, 1)
        lower.setStretchFactor(1, 1)
        lower.setSizes([760, 560])
        # the height left over, down to the plots' least: their preferred height (a page's worth)
        # would make the scroll area scroll (its wrapped labels ask it for the preferred height)
        lower.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Ignored)
        lower.setMinimumHeight(PLOTS_MIN_HEIGHT_PX)

        self.bench = BenchTuningPanel(self)
        panel = QWidget()
        layout = QVBoxLayout(panel)
        # rows closer than the style's 6 px: the plan of a jog within a known range takes three lines
        # at 1280 x 720, and the plots keep their height
        layout.setSpacing(PANEL_SPACING_PX)
        layout.addLayout(form)
        layout.addLayout(buttons)
        layout.addWidget(self.bench)
        layout.addWidget(self.plan_label)
        said = QHBoxLayout()  # the outcome and its warning on one line: the plots keep their height
        said.addWidget(self.status_label)
        said.addWidget(self.warning_label, 1)
        layout.addLayout(said)
        layout.addWidget(self.result_label)
        layout.addWidget(lower, 1)
        outer = QVBoxLayout(self)
        outer.setContentsMargins(0, 0, 0, 0)
        outer.addWidget(scrolling(panel))

    # ----- settings ------------------------------------------------------------------------------
    def restore_settings(self, settings: QSettings) -> None:
        index = self.bias_combo.findData(str(settings.value("tuning/bias", BiasDirection.FWD.value)))
        self.bias_combo.setCurrentIndex(max(index, 0))

    def save_settings(self, settings: QSettings) -> None:
        settings.setValue("tuning/bias", self.bias_combo.currentData())

    def bias(self) -> BiasDirection:
        return BiasDirection(self.bias_combo.currentData())

    def switch_angles_deg(self) -> dict[str, float]:
        """The limit switches' switching angles the procedures recorded for this axis (none where
        no procedure session is open or they are not recorded yet)."""
        if self.main_window is None:
            return {}
        procedures = self.main_window.built_page(PageId.PROCEDURES)
        session = getattr(procedures, "session", None)
        return dict(session.sensor_angles_deg) if session is not None else {}

    def _plan_outdated(self) -> None:
        if self.start_button.isEnabled() or self.hold_button.isEnabled():
            self.plan_label.setText("The bias speed changed: show the excitation again before it starts.")
        self.start_button.setEnabled(False)
        self.hold_button.setEnabled(False)

    # ----- the link ------------------------------------------------------------------------------
    def link_connected(self, info: LinkInfo) -> None:
        code = info.adjusted_for or self.session.state.actuator_code
        if code:
            self.actuator_edit.setText(code)
        self._excitable = not info.documented_only and info.can_move
        if not self._excitable:
            self.plan_label.setText("This drive answers only its manual's commands: it cannot be excited "
                                    "over CN3. Propose gains for the front-panel worksheet, or measure on "
                                    "the bench (SPD-CMD from a DAQ's output, SPD-MON recorded).")

    def link_disconnected(self, reason: str, lost: bool) -> None:
        self.cancel_countdown()
        self.hold_button.release()
        self.start_button.setEnabled(False)
        self.hold_button.setEnabled(False)
        self.apply_button.setEnabled(False)

    def shutdown(self) -> None:
        self._timer.stop()
        self.bench.shutdown()
        self.hold_button.release()

    def release_held(self) -> None:
        """STOP (or the window letting go of what is held): a countdown ends, a held excitation
        is let go."""
        self.cancel_countdown()
        self.hold_button.release()

    # ----- excitation, countdown, measurement ----------------------------------------------------
    def _code(self) -> str:
        return self.actuator_edit.text().strip()

    def _amplitude(self) -> float | None:
        value = self.amplitude_spin.value()
        return value if value > 0 else None

    def show_plan(self) -> None:
        """Compute and show the excitation (in the link thread: it reads the drive's items)."""
        code, load, amplitude = self._code(), self.load_spin.value(), self._amplitude()
        bias, angles = self.bias(), self.switch_angles_deg()

        def plan(client: Any) -> Any:
            if NEEDED - set(client.capabilities.commands):
                return None
            tuner = tuner_for(client, self.session.parameter_model, declared_model(code, load))
            planned = plan_excitation(tuner.loop({}), amplitude, bias)
            try:
                return planned, planned_travel(client, tuner, planned, angles, manual_units=True)
            except TravelRefused as refused:  # the plan's answer, not a failed request: said on the page
                return None, str(refused)

        self.link.send(Call(plan), self._planned)

    def _no_plan(self, why: str) -> None:
        """No excitation, and nothing may start on an earlier plan either."""
        self.start_button.setEnabled(False)
        self.hold_button.setEnabled(False)
        self.plan_label.setText(units_kept(f"No excitation: {why}"))

    def _planned(self, reply: LinkReply[Any]) -> None:
        if not reply.ok:
            self._no_plan(str(reply.error))
            return
        if reply.value is None:
            self.plan_label.setText("This drive has no excitation over CN3: the proposal is a front-panel "
                                    "worksheet.")
            return
        plan, words = reply.value
        if plan is None:  # it does not fit the movable range
            self._no_plan(words)
            return
        self.plan = plan
        self.plan_label.setText(units_kept(f"{words[0].upper()}{words[1:]}. Servo on, the axis free to move "
                                           "that far; STOP ends it at once."))
        self.start_button.setEnabled(True)
        self.hold_button.setEnabled(True)

    # hold-to-run: the excitation runs while the button is held and the GUI renews the lease
    def hold_started(self) -> None:
        """The hold button went down: measure at once, for as long as it stays held."""
        if self._held:
            return
        self._held = True
        self._renew_lease()
        self._lease_timer.start()
        self.start_button.setEnabled(False)
        self.measure(held=True)

    def _renew_lease(self) -> None:
        self._lease_s = time.monotonic()

    def _hold_released(self) -> None:
        self._held = False
        self._lease_timer.stop()

    def hold_let_go(self) -> bool:
        """True once the hold is let go, or its lease is older than a held jog's may be (a GUI
        that stopped renewing it): asked in the link thread between two looks at the drive."""
        return not self._held or time.monotonic() - self._lease_s > JOG_LEASE_S

    def start_countdown(self) -> None:
        self._countdown = COUNTDOWN_S
        self.cancel_button.setEnabled(True)
        self.start_button.setEnabled(False)
        self.status_label.setText(f"The excitation starts in {self._countdown} s (Cancel stops it) …")
        self._timer.start()

    def cancel_countdown(self) -> None:
        if self._timer.isActive():
            self._timer.stop()
            self.status_label.setText("Cancelled: nothing moved.")
            self.start_button.setEnabled(True)
        self.cancel_button.setEnabled(False)

    def _tick(self) -> None:
        self._countdown -= 1
        if self._countdown > 0:
            self.status_label.setText(f"The excitation starts in {self._countdown} s (Cancel stops it) …")
            return
        self._timer.stop()
        self.cancel_button.setEnabled(False)
        self.measure()

    def measure(self, then: Any = None, held: bool = False) -> None:
        code, load, amplitude = self._code(), self.load_spin.value(), self._amplitude()
        bias, angles = self.bias(), self.switch_angles_deg()
        abort = self.link.abort_event.is_set
        stop = (lambda: abort() or self.hold_let_go()) if held else abort
        self.status_label.setText("Measuring while the button is held: let go to stop …" if held else
                                  "Measuring: the axis is excited …")

        def run(client: Any) -> dict[str, Any] | str:
            tuner = tuner_for(client, self.session.parameter_model, declared_model(code, load))
            pace, now = drive_clock(client)
            try:
                return measure_report(client, tuner, pace, now, amplitude, should_stop=stop, bias=bias,
                                      switch_angles_deg=angles, manual_units=True)
            except TravelRefused as refused:  # the range check's answer (the axis moved since the
                return str(refused)  # plan), not a failed request: said on the page, once

        self.link.send(Call(run), partial(self._measured, then, held))

    def _measured(self, then: Any, held: bool, reply: LinkReply[dict[str, Any] | str]) -> None:
        self.start_button.setEnabled(True)
        let_go = held and self.hold_let_go()
        if held:
            self.hold_button.release()
        result = reply.value
        if isinstance(result, str):  # refused before anything moved
            self.status_label.setText(units_kept(f"Measurement not done: {result}"))
            return
        if not reply.ok or result is None:
            if let_go:
                self.status_label.setText("Let go: the excitation stopped, nothing measured (hold until "
                                          "the measurement is done).")
            else:
                self.status_label.setText(f"Measurement not done: {reply.error}")
            return
        self.show_result(result)
        if then is None:
            stamp = clock.now_utc().strftime("%Y-%m-%d %H:%M:%S UTC")
            self.records.append(TuningRecord(at=stamp, who="", before=result))
        if then is not None:
            then(result)
        else:
            self.sigMeasured.emit(result)

    def show_result(self, result: dict[str, Any]) -> None:
        """Plot a measurement (tune measure's dict) and mark the resonances."""
        self.result = result
        for key, name in (("closed", "frequency_response"), ("plant", "plant_response"),
                          ("predicted", "predicted_response")):
            # a bench measurement brings the prediction; a loop fitted to a move has no plant and no
            # coherence (nothing was measured in frequency)
            data = result.get(name) or {"freq_hz": [], "magnitude_db": [], "phase_deg": []}
            f = np.asarray(data["freq_hz"], float)
            mag, phase, coh = (self.curves[key][i] for i in range(3))
            mag.setData(f, np.asarray(data["magnitude_db"], float))
            phase.setData(f, np.asarray(data["phase_deg"], float))
            coherence = np.asarray(data.get("coherence", []), float)
            coh.setData(f if len(coherence) == len(f) else [], coherence if len(coherence) == len(f) else [])
        # the prediction is in the legend while it is on the plot
        legend, predicted = self.legend, self.curves["predicted"][0]
        legend.removeItem(predicted)
        if result.get("predicted_response"):
            legend.addItem(predicted, "speed loop (predicted)")
        for marker in self.markers:
            self.mag_plot.removeItem(marker)
        self.markers = []
        # a resonance's label on the higher side of its line, an anti-resonance's on the lower side
        # (a label never reads through the other marker's line); the measured ones in a line kept
        # free above the curves, each at the height nearest its own where no curve runs through
        # it (_place_marker_labels). A prediction at the measured place is said in its label: two
        # labels there left no room between the curves
        above, below = [(0.0, 0.5)] * 2, [(1.0, 0.5)] * 2
        for key, colour, style, label, where, side in (
            ("resonance_hz", "#008000", None, "resonance", 1.0, above),
            ("antiresonance_hz", "#800080", None, "anti-resonance", 1.0, below),
            ("predicted_resonance_hz", "#008000", pg.QtCore.Qt.PenStyle.DashLine, "predicted", 0.0, above),
            ("predicted_antiresonance_hz", "#800080", pg.QtCore.Qt.PenStyle.DashLine, "predicted", 0.0,
             below),
        ):
            value = result.get(key)
            if not value:
                continue
            words = f"{label} {value:.1f} Hz"
            prediction = result.get(f"predicted_{key}")
            if prediction and _same_place(value, prediction):
                words += f" (predicted {prediction:.1f} Hz)"
            measured = result.get(key.removeprefix("predicted_")) if key.startswith("predicted_") else None
            pen = pg.mkPen(colour, width=2, style=style) if style else pg.mkPen(colour, width=2)
            line = pg.InfiniteLine(pos=np.log10(value), angle=90, pen=pen, label=words,
                                   labelOpts={"position": where, "color": colour, "anchors": side})
            line.preferred_height = where  # the share of the view's height it is put nearest
            line.words, line.short_words, line.side = words, f"{label} {value:.1f} Hz", side[0][0]
            if measured and _same_place(measured, value):
                line.label.setVisible(False)  # the measured marker's label says it
            self.mag_plot.addItem(line)
            self.markers.append(line)
        self._magnitude_resized()

        def fmt(key: str, unit: str) -> str:
            return result_figure_words(result, key, unit, manual_units=True)

        self.status_label.setText("Measured.")
        if result.get("stick_slip_warning"):  # measured about standstill: the friction shows
            self.warning_label.setText(f"Warning: {result['stick_slip_warning']}.")
        uncertainty = result.get("load_inertia_uncertainty_kgm2")  # a bench measurement says it
        spread = f" ± {uncertainty:.2g}" if uncertainty and result.get("load_inertia_estimate_kgm2") else ""
        self.use_inertia_button.setEnabled(result.get("load_inertia_estimate_kgm2") is not None)
        self.result_label.setText(
            f"Resonance {fmt('resonance_hz', 'Hz')} (predicted {fmt('predicted_resonance_hz', 'Hz')}), "
            f"anti-resonance {fmt('antiresonance_hz', 'Hz')}; load inertia estimate "
            f"{fmt('load_inertia_estimate_kgm2', 'kg·m²')}{spread}; "
            f"gain margin {fmt('gain_margin_db', 'dB')}, "
            f"phase margin {fmt('phase_margin_deg', 'deg')}, crossover {fmt('crossover_hz', 'Hz')}, "
            f"bandwidth {fmt('bandwidth_hz', 'Hz')}")

    def _magnitude_resized(self) -> None:
        """A new result or size: the room above the curves, then the labels in it."""
        self._leave_room_for_labels()
        self._place_marker_labels()

    def _leave_room_for_labels(self) -> None:
        """With markers, the magnitude plot's values from the curves' lowest to a label's line
        above their highest (near 0 dB the closed loop left no room at the top for a label), two
        lines where the measured markers' labels must sit on the same side (a resonance at the
        end of the measured band); without, its values follow the curves. Again when the plot is
        resized."""
        view = self.mag_plot.getViewBox()
        values = [np.asarray(curves[0].getData()[1] if curves[0].getData()[1] is not None else [], float)
                  for curves in self.curves.values()]
        finite = np.concatenate([v[np.isfinite(v)] for v in values]) if values else np.array([])
        height_px = view.boundingRect().height()
        shown = [m for m in self.markers if m.label.isVisible()]
        if not shown or not finite.size or height_px < 4 * MARKER_LABEL_ROOM_PX:
            view.enableAutoRange(axis=pg.ViewBox.YAxis)
            return
        room_px = MARKER_LABEL_ROOM_PX * self._measured_label_lines()
        low, high = float(finite.min()), float(finite.max())
        margin = 0.03 * max(high - low, 1.0)
        per_px = (high - low + 2 * margin) / max(height_px - room_px, MARKER_LABEL_ROOM_PX)
        view.setYRange(low - margin, high + margin + room_px * per_px, padding=0.0)

    def _measured_label_lines(self) -> int:
        """How many lines the measured markers' labels take above the curves: one, or two where
        they reach over each other (``_fit_beside`` put one on the other's side)."""
        view = self.mag_plot.getViewBox()
        (x0, x1), _ = view.viewRange()
        try:
            x_per_px, y_per_px = view.viewPixelSize()
        except (ZeroDivisionError, ValueError):
            return 1
        spans = [self._fit_beside(m, float(m.value()), x0, x1, x_per_px, y_per_px, MARKER_LABEL_MARGIN_PX)[:2]
                 for m in self.markers if m.label.isVisible() and m.preferred_height == 1.0]
        over = any(a[0] < b[1] and b[0] < a[1] for i, a in enumerate(spans) for b in spans[i + 1:])
        return 2 if over else 1

    @staticmethod
    def _fit_beside(marker: Any, at: float, x0: float, x1: float, x_per_px: float, y_per_px: float,
                    margin_px: float) -> tuple[float, float, float]:
        """Puts ``marker``'s label on its own side of its line with its words (the prediction at
        its place included); where that runs out of the plot, without the prediction (the
        outcome's line above says it), then on the other side. Its (left, right, half height)."""
        label = marker.label
        for words, side in ((marker.words, marker.side), (marker.short_words, marker.side),
                            (marker.short_words, 1.0 - marker.side)):
            if label.format != words:
                label.setFormat(words)
            if label.anchors[0][0] != side:
                label.anchors = [(side, 0.5)] * 2
                label.updatePosition()
            size = label.mapRectToScene(label.boundingRect())
            width = (size.width() + margin_px) * x_per_px
            left, right = (at, at + width) if side == 0.0 else (at - width, at)
            if x0 <= left and right <= x1:
                break
        return left, right, (size.height() / 2 + margin_px) * y_per_px

    def _place_marker_labels(self) -> None:
        """Each marker's label beside its line at the height nearest its preferred one where no
        curve of the magnitude plot and no label placed before it runs through it, whole in the
        plot (the closed loop near 0 dB ran through a resonance label put at the top). Again
        whenever the plot's range or size changes."""
        view = self.mag_plot.getViewBox()
        (x0, x1), (y0, y1) = view.viewRange()
        try:
            x_per_px, y_per_px = view.viewPixelSize()
        except (ZeroDivisionError, ValueError):  # not laid out yet: placed when it is
            return
        if not self.markers or not (x_per_px > 0 and y_per_px > 0 and y1 > y0):
            return
        curves = []
        for key in ("closed", "plant", "predicted"):
            x, y = self.curves[key][0].getData()  # as drawn: log10 of the frequency
            if x is not None and len(x):
                curves.append((np.asarray(x, float), np.asarray(y, float)))
        margin_px = MARKER_LABEL_MARGIN_PX
        placed: list[tuple[float, float, float, float]] = []  # labels' (left, right, bottom, top)
        for marker in self.markers:
            label = marker.label
            if not label.isVisible():
                continue
            at = float(marker.value())
            left, right, half = self._fit_beside(marker, at, x0, x1, x_per_px, y_per_px, margin_px)
            # the heights the curves take between the label's left and right edges
            taken: list[tuple[float, float]] = []
            for x, y in curves:
                ends = np.column_stack((x[:-1], x[1:], y[:-1], y[1:]))
                near = ends[(np.maximum(ends[:, 0], ends[:, 1]) >= left)
                            & (np.minimum(ends[:, 0], ends[:, 1]) <= right)]
                near = near[np.isfinite(near).all(axis=1)]
                taken += [(min(a, b), max(a, b)) for a, b in near[:, 2:]]
            labels = [(bottom, top) for l_, r_, bottom, top in placed if l_ < right and left < r_]
            span = y1 - y0
            lowest, highest = half / span, 1.0 - half / span
            if highest <= lowest:
                continue
            best, best_cost = None, None
            for share in np.linspace(lowest, highest, 61):
                centre = y0 + share * span
                low, high = centre - half, centre + half
                # a label over another cannot be read at all; over a curve it can
                cost = (_overlaps(labels, low, high), _overlaps(taken, low, high),
                        abs(share - marker.preferred_height))
                if best_cost is None or cost < best_cost:
                    best, best_cost = float(share), cost
            if best is None:
                continue
            label.setPosition(best)
            centre = y0 + best * span
            placed.append((left, right, centre - half, centre + half))

    # ----- proposal, apply, worksheet ------------------------------------------------------------
    def _offline_items(self) -> dict[str, int]:
        model = self.session.parameter_model
        items = {it.key: int(it.default) for it in model if it.mode in (Mode.TUNE, Mode.SYSTEM)
                 and it.default is not None}
        for it in model:
            known = self.session.state.value_of(str(it.mode), it.number)
            if known is not None:
                items[it.key] = int(known)
        return items

    def propose(self) -> None:
        code, load, aim = self._code(), self.load_spin.value(), self.aim_combo.currentText()
        parameters = self.session.parameter_model
        if not self._excitable:
            try:
                # the gains are for the axis at work, in position mode (speed mode is how the
                # bench measures it: SPD-CMD drives the speed loop)
                tuner = Tuner(declared_model(code, load), {**self._offline_items(), "control_mode": 0},
                              parameters, DEFAULT_SERVO_RATE_HZ)
                proposal = tuner.propose(aim)
            except ValueError as exc:
                self.status_label.setText(f"No proposal: {exc}")
                return
            self._proposed(None, direct=proposal)
            return

        def run(client: Any) -> Proposal:
            return tuner_for(client, parameters, declared_model(code, load)).propose(aim)

        self.status_label.setText("Proposing gains …")
        self.link.send(Call(run), self._proposed)

    def _proposed(self, reply: Any, direct: Proposal | None = None) -> None:
        if direct is None:
            if not reply.ok:
                self.status_label.setText(f"No proposal: {reply.error}")
                return
            direct = reply.value
        proposal: Proposal = direct
        self.proposal = proposal
        self.warning_label.setText(f"Warning: {proposal.warning}" if proposal.warning else "")
        for col, figs in ((0, proposal.present), (1, proposal.proposed)):
            values = figs.to_dict()
            for row, key in enumerate((*TUNE_KEYS, *FIGURE_ROWS)):
                self.table.setItem(row, col, QTableWidgetItem(_cell(key, values.get(key))))
        self.apply_button.setEnabled(self._excitable)
        self.worksheet.setPlainText(self.worksheet_text(proposal))
        self.status_label.setText(f"Proposed for the aim {proposal.used_aim}.")
        self.sigProposed.emit(proposal)

    def worksheet_text(self, proposal: Proposal) -> str:
        """The proposal as front-panel entries (tune mode items), for a drive without CN3 access."""
        model = self.session.parameter_model
        lines = ["Front-panel worksheet (tune mode): set, then verify with a move."]
        for key in TUNE_KEYS:
            item = model.by_key(key)
            lines.append(f"  tune item {item.number} {item.name}: {proposal.present.items.get(key)} -> "
                         f"{proposal.proposed.items[key]} {item.unit}")
        lines.append("Then capture on the bench (the controller's move, or the SPD-CMD excitation again) and "
                     "Verify the proposal from the capture: measured against predicted.")
        return "\n".join(lines)

    def apply(self) -> None:
        """Write the proposed tune items (the session's path: backup first, verified), then
        measure again."""
        if self.proposal is None:
            return
        model = self.session.parameter_model
        writes = [(Mode.TUNE, model.by_key(k).number, int(v))
                  for k, v in self.proposal.proposed.items.items()]
        self.session.sigWritesDone.connect(self._written)
        self.status_label.setText("Writing the proposed gains (backup first) …")
        self.session.write(writes)

    def _written(self, entries: list[Any]) -> None:
        self.session.sigWritesDone.disconnect(self._written)
        if not entries or not all(e.get("verified") for e in entries):
            self.status_label.setText("The proposed gains were not all written and verified: "
                                      "nothing measured.")
            return
        self.measure(then=self._measured_after)

    def use_inertia_estimate(self) -> None:
        """Offer the measured load inertia to the commissioning state (the declared load)."""
        estimate = (self.result or {}).get("load_inertia_estimate_kgm2")
        if estimate is None:
            return
        value = max(0.0, float(estimate))
        self.session.state.set_load_inertia(value)
        self.load_spin.setValue(value)
        self.status_label.setText(f"The declared load inertia is now {value:.4g} kg·m² (measured).")

    def report_notes(self) -> list[tuple[str, str]]:
        """What the commissioning report says of the tunings of this session (before / after)."""
        return tuning_notes(self.records, self.session.parameter_model)

    def report_plots(self, session_path: Path, who: str) -> list[tuple[str, Path]]:
        """Each tuning of this session as a PNG beside the session (``<stem>-tuning<n>.png``): the
        magnitude and phase before and after, its figures, who and when; (title, path) for the
        report's plots. The same record gives the same file (rewritten once it has its after)."""
        out = []
        for n, record in enumerate(self.records, start=1):
            path = session_path.with_name(f"{session_path.stem}-tuning{n}.png")
            title = tuning_plot_title(n, record, who)
            export_response_png(record, title, path)
            out.append((title, path))
        return out

    def _measured_after(self, result: dict[str, Any]) -> None:
        if self.records and self.proposal is not None:
            self.records[-1] = replace(self.records[-1], items=dict(self.proposal.proposed.items),
                                       aim=self.proposal.used_aim, warning=self.proposal.warning,
                                       after=result)
        for row, key in enumerate((*TUNE_KEYS, *FIGURE_ROWS)):
            value = self.proposal.proposed.items.get(key) if key in TUNE_KEYS else result.get(key)
            self.table.setItem(row, 2, QTableWidgetItem(_cell(key, value, result.get("measured_to_hz"))))
        self.sigApplied.emit(result)
