"""The scope's "Bench" tab: a bench instrument streamed through sigrok-cli beside CN3 polling.

A real HA-655 answers CN3 with ``s`` while its servo is on; its CN2 monitor outputs (SPD-MON,
encoder A/B/Z, IN-POS, ALARM) still show on a logic analyzer or an oscilloscope. This tab lists
the instruments sigrok-cli finds, streams the channels asked for (``BenchSource``) and plots the
newest seconds as a logic analyzer does (each logic channel a lane of a fixed height, ALM-A ... D
one lane showing the code, the analog channels and the encoder's counts in plots of their own, all
scrolling where the screen is too low), every trace named with its source (``bench demo:D0``) so
nobody takes it for a CN3 channel; ALARM and the alarm code on ALM-A ... D are shown in the
manual's words as they come. Once a move's figures come, the plots hold that move (from a little
before its command until a little after IN-POS came on) while the stream goes on, until the next
move or "Back to live". Where sigrok-cli is missing the tab says how to install it.
"""

from __future__ import annotations

import datetime
import math
import shutil
import time
from collections.abc import Sequence

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt, Signal, Slot
from PySide6.QtGui import QFont, QFontMetrics
from PySide6.QtWidgets import (
    QComboBox,
    QGridLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QScrollArea,
    QVBoxLayout,
    QWidget,
)

from fha_studio import clock
from fha_studio.gui.unit_spacing import units_kept
from fha_studio.gui.widgets import hint_whole
from fha_studio.hardware.bench import sigrok
from fha_studio.hardware.parameters import load_cn2
from fha_studio.logic.bench import alarm_code
from fha_studio.logic.bench.checks import BenchCheck, bench_checks, source_words
from fha_studio.logic.bench.display import CHANGED, peak_rows
from fha_studio.logic.bench.importer import DriveSettings
from fha_studio.logic.bench.move import BenchMoveFigures, bench_move_figures

from . import bench_mappings
from .bench_source import BenchSettings, BenchSource, BenchStarted

#: Seconds of the newest rows on show.
WINDOW_S = 2.0
#: The time axis moves on in steps of this [s].
STEP_S = 0.5
#: A move's figures are taken once its command has stood this long [s] (the axis settles first).
MOVE_SETTLED_S = 0.5
#: A command standing still this long before a change marks where a move began [s].
MOVE_GAP_S = 0.2
#: The move on hold is shown from this long before its command began [s].
MOVE_BEFORE_S = 0.2
#: ... until this long after IN-POS came on [s] (without IN-POS: until its figures were taken).
MOVE_AFTER_S = 0.2
#: The checks as the move's line names them.
CHECK_WORDS = {"bench_encoder": "encoder outputs follow the command", "bench_direction": "direction",
               "bench_in_position": "IN-POS", "bench_alarm": "ALARM"}
VERDICT = {True: "pass", False: "FAIL", None: "recorded"}
#: The width of both plots' left axes [px] (room for "-1000000").
LEFT_AXIS_PX = 62
#: The counts' plot shows at least this many counts above and below what it draws.
MIN_COUNTS_PAD = 5.0
#: The analog plot shows at least this much above and below what it draws [V] (noise is no band).
MIN_ANALOG_PAD_V = 0.1
#: A logic lane's height [px], as a logic analyzer's: its name (the lane font) whole beside it.
LANE_PX = 16
#: A lane's height in the lanes' plot [its units]; the trace takes LANE_HIGH of it.
LANE_STEP = 1.2
LANE_HIGH = 0.8
#: The analog channels' plot and the counts' plot draw their traces at least this high [px] (room
#: to read a trace's shape and three of its axis's numbers); the time axis comes on top.
TRACE_VIEW_MIN_PX = 50
#: A plot's height besides its view [px] (the scene's margins); the time axis below adds its own.
PLOT_MARGINS_PX = 6
_COLORS = ("#1f77b4", "#d62728", "#2ca02c", "#e07000", "#9467bd", "#8c564b", "#e377c2", "#008b8b")


def _names_at_right(plot: pg.PlotWidget, names: list[str], y_range: tuple[float, float]) -> None:
    """The traces of ``plot`` named at its right, as the lanes are (a legend row above it would
    take the height its traces need on a small screen)."""
    low, high = y_range
    ticks = [(low + (high - low) * (len(names) - n - 0.5) / len(names), name) for n, name in enumerate(names)]
    plot.getAxis("right").setTicks([ticks, []])


def _counted(n: float, noun: str) -> str:
    """``"1 count"``, ``"11 channels"``: a whole number of things as a sentence says it."""
    whole = round(n)
    return f"{whole} {noun}" if abs(whole) == 1 else f"{whole} {noun}s"


def _flange(check: BenchCheck) -> str:
    """`` (FWD rotation, CW viewing the output flange)`` for a direction check that knows it."""
    flange = check.values.get("flange") if check.check == "bench_direction" else None
    return f" ({check.values['rotation']}, {flange} viewing the output flange)" if flange else ""


def _busy_as_band(rows: np.ndarray, lanes: Sequence[float | None]) -> np.ndarray:
    """``rows`` with each lane's windows where the line changed (:data:`CHANGED`) drawn low and
    high in turn, so that a line toggling faster than the rows fills its lane as a logic analyzer
    shows it (a busy band), instead of a line at half height."""
    busy = [1 + i for i, lane in enumerate(lanes) if lane is not None and np.any(rows[:, 1 + i] == CHANGED)]
    if not busy:
        return rows
    rows = rows.copy()  # the ring's rows stay as they were
    turn = (np.arange(len(rows)) & 1).astype(float)
    for column in busy:
        changed = rows[:, column] == CHANGED
        rows[changed, column] = turn[changed]
    return rows


def _rate(text: str) -> float | None:
    """``1m``, ``200k``, ``24 MHz``, ``500000`` -> Hz; empty: None (the instrument's own)."""
    t = text.strip().lower().replace(" ", "").removesuffix("hz")
    if not t:
        return None
    factor = {"k": 1e3, "m": 1e6, "g": 1e9}.get(t[-1], 1.0)
    number = t[:-1] if factor != 1.0 else t
    value = float(number)
    if not value > 0:
        raise ValueError
    return value * factor


class BenchPanel(QWidget):
    """Instrument, channels and rate; Start/Stop; a plot of the stream."""

    sigDevicesListed = Signal(int)  # in the GUI thread: how many instruments the scan found
    sigChecks = Signal(object)  # list of BenchCheck: a move's DGR checks from CN2, once it settled

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.setObjectName("scopeBench")
        self.source = BenchSource(self)
        self.source.worker.sigDevices.connect(self._on_devices)
        self.source.sigStarted.connect(self._on_started)
        self.source.sigRows.connect(self._on_rows)
        self.source.sigStopped.connect(self._on_stopped)
        self._curves: list[pg.PlotDataItem] = []
        self._lanes: list[float | None] = []  # each curve's lane offset (a logic channel), else None
        self._named = 0  # analog channels, in their own plot
        self.analog_names: list[str] = []  # as named at the analog plot's right
        self.counts_name = ""  # as named at the counts' plot's right
        # ALM-A ... D in one lane, "ALM-D C B A", showing the code (as the front panel's LEDs would)
        self._code_bits: list[tuple[int, int]] = []  # (bit, the channel's index) of the mapped lines
        self._code_lane: float | None = None
        self._code_edges = [pg.PlotDataItem(pen=pg.mkPen("#7f3f00", width=1)) for _ in range(2)]
        self._code_texts: list[pg.TextItem] = []
        self._started: BenchStarted | None = None

        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        grid = QGridLayout()
        grid.addWidget(QLabel("Instrument"), 0, 0)
        self.device_box = QComboBox()
        self.device_box.setEditable(True)  # a driver with options may be typed: demo:analog_channels=2
        self.device_box.setToolTip("the sigrok driver (and its options) of the instrument")
        grid.addWidget(self.device_box, 0, 1, 1, 2)
        self.device_box.currentTextChanged.connect(self._offer_mapping)
        self.scan_button = QPushButton("Find")
        self.scan_button.setToolTip("list the instruments sigrok-cli finds")
        self.scan_button.clicked.connect(self.scan)
        grid.addWidget(self.scan_button, 0, 3)
        grid.addWidget(QLabel("Channels"), 1, 0)
        self.channels_edit = QLineEdit("D0,D1,D2")
        self.channels_edit.setToolTip("the instrument's channels, e.g. D0,D1,D2 (logic) or A0 (analog)")
        grid.addWidget(self.channels_edit, 1, 1)
        self.rate_edit = QLineEdit("1m")
        self.rate_edit.setToolTip("sample rate, e.g. 200k, 1m, 24m (empty: the instrument's own)")
        self.rate_edit.setMaximumWidth(70)
        grid.addWidget(self.rate_edit, 1, 2)
        self.start_button = QPushButton("Start")
        self.start_button.setCheckable(True)
        self.start_button.clicked.connect(self._start_clicked)
        grid.addWidget(self.start_button, 1, 3)
        # the roles in two rows: the plots get the height
        cn2 = load_cn2()
        roles = QHBoxLayout()
        roles.addWidget(QLabel("Encoder"))
        self.encoder_edit = QLineEdit("")
        # the hints are examples, short enough to be whole on a 1024 px screen (the tooltips say more)
        self.encoder_edit.setPlaceholderText("D0,D1")
        self.encoder_edit.setToolTip("encoder A and B among the channels, e.g. D0,D1: counted x4 as they "
                                     "come")
        roles.addWidget(self.encoder_edit, 1)
        roles.addWidget(QLabel("Command"))
        self.command_edit = QLineEdit("")
        self.command_edit.setPlaceholderText("D2,D3")
        self.command_edit.setToolTip("the command pulse lines into CN2 among the channels, e.g. D2,D3 (A, "
                                     "and B for two-pulse, the sign or two-phase), decoded by parameters "
                                     "1, 2, 3 and 4")
        roles.addWidget(self.command_edit, 1)
        roles.addWidget(QLabel("IN-POS"))
        self.in_position_edit = QLineEdit("")
        self.in_position_edit.setPlaceholderText("D4")
        self.in_position_edit.setToolTip(f"the drive's in-position output ({cn2.pins_text('in_position')}) "
                                         "among the channels: the move's in-position time is taken from it")
        roles.addWidget(self.in_position_edit, 1)
        grid.addLayout(roles, 2, 0, 1, 4)
        alarms = QHBoxLayout()
        alarms.addWidget(QLabel("ALARM"))
        self.alarm_edit = QLineEdit("")
        self.alarm_edit.setPlaceholderText("D5")
        self.alarm_edit.setToolTip(f"the drive's ALARM output ({cn2.pins_text('alarm')}) among the channels: "
                                   "the checks of a move say whether it came on")
        alarms.addWidget(self.alarm_edit, 1)
        self.alm_edits: list[QLineEdit] = []
        roles_lines = zip(("alm_a", "alm_b", "alm_c", "alm_d"), alarm_code.LINES, strict=True)
        for n, (role, line) in enumerate(roles_lines):
            alarms.addWidget(QLabel(line))
            edit = QLineEdit("")
            edit.setObjectName(f"scopeBench_{role}")
            edit.setPlaceholderText(f"D{6 + n}")
            edit.setToolTip(f"the alarm code line {line} ({cn2.pins_text(role)}) among the channels: the "
                            "code (ALM-D C B A, ON = 1) is shown as the alarms it can be")
            alarms.addWidget(edit, 1)
            self.alm_edits.append(edit)
        for edit in (self.encoder_edit, self.command_edit, self.in_position_edit, self.alarm_edit,
                     *self.alm_edits):
            hint_whole(edit)
        grid.addLayout(alarms, 3, 0, 1, 4)
        grid.setColumnStretch(1, 1)
        layout.addLayout(grid)
        # while a move is on hold: which, and the way back to the newest seconds (hidden while
        # live: the plots keep their height on a small screen)
        self.hold_bar = QWidget()
        showing = QHBoxLayout(self.hold_bar)
        showing.setContentsMargins(0, 0, 0, 0)
        self.showing_label = QLabel("")
        self.showing_label.setObjectName("scopeBenchShowing")
        showing.addWidget(self.showing_label, 1)
        self.back_button = QPushButton("Back to live")
        self.back_button.setObjectName("scopeBenchBack")
        self.back_button.setToolTip("Leave the move on show and return to the newest seconds of the stream")
        self.back_button.clicked.connect(self.back_to_live)
        showing.addWidget(self.back_button)
        self.hold_bar.setVisible(False)
        layout.addWidget(self.hold_bar)
        self._held: np.ndarray | None = None  # the move's rows on show (a copy), else None: live
        # the plots as a logic analyzer lays them out: each logic lane a fixed height with its name
        # beside it, the analog channels (SPD-MON) and the encoder's counts below in plots of their
        # own that keep a readable height; where the screen is too low for all of them they scroll
        self.plots = QWidget()
        self.plots.setObjectName("scopeBenchPlots")
        plots = QVBoxLayout(self.plots)
        plots.setContentsMargins(0, 0, 0, 0)
        plots.setSpacing(0)
        self.plots_scroll = QScrollArea()
        self.plots_scroll.setObjectName("scopeBenchPlotsScroll")
        self.plots_scroll.setWidgetResizable(True)
        self.plots_scroll.setFrameShape(QScrollArea.Shape.NoFrame)
        self.plots_scroll.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.plots_scroll.setWidget(self.plots)
        layout.addWidget(self.plots_scroll, 1)
        self.plot = pg.PlotWidget(background="w")  # the logic lanes
        self.plot.setMouseEnabled(x=True, y=False)
        self.plot.getAxis("left").setTicks([[], []])  # the lanes' names are at the right
        plots.addWidget(self.plot)
        # the traces' names at the right, a little smaller than the plots' numbers (many lanes)
        lane_font = QFont(self.font())
        lane_font.setPointSizeF(max(6.0, lane_font.pointSizeF() * 0.8))
        self._lane_font = lane_font
        self.lane_metrics = QFontMetrics(lane_font)
        self.lane_px = max(LANE_PX, self.lane_metrics.height())
        self.analog_plot = pg.PlotWidget(background="w")
        self.analog_plot.setLabel("left", units="V")
        plots.addWidget(self.analog_plot, 1)
        self.counts_plot = pg.PlotWidget(background="w")
        self.counts_plot.setLabel("left", "counts")
        for plot in (self.analog_plot, self.counts_plot):
            plot.setXLink(self.plot)
        for plot in (self.plot, self.analog_plot, self.counts_plot):  # equal left axes: times line up
            plot.getAxis("left").setWidth(LEFT_AXIS_PX)
            plot.getAxis("right").setTickFont(lane_font)  # every trace's name at the right
            plot.setLabel("bottom", "time", units="s")
        self.counts_plot.setVisible(False)
        self._counts_curve = self.counts_plot.plot([], [], pen=pg.mkPen("#333333", width=1))
        self._counts_curve.setSkipFiniteCheck(True)
        self.counts_plot.enableAutoRange(enable=False)  # ranges set per frame, not from the data's bounds
        self._y_range: tuple[float, float] | None = None
        self._x_range: tuple[float, float] | None = None
        self._counts_range: tuple[float, float] | None = None
        plots.addWidget(self.counts_plot, 1)
        self.alarm_label = QLabel("")
        self.alarm_label.setObjectName("scopeBenchAlarm")
        self.alarm_label.setWordWrap(True)
        self.alarm_label.setVisible(False)
        layout.addWidget(self.alarm_label)
        self._alarm_shown: tuple[bool | None, int | None] | None = None
        self.move_label = QLabel("")
        self.move_label.setObjectName("scopeBenchMove")
        self.move_label.setWordWrap(True)
        self.move_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        layout.addWidget(self.move_label)
        self.move_figures: BenchMoveFigures | None = None
        self.checks: list[BenchCheck] = []
        self.parameter_8: int | None = None  # rotary direction, as the drive or its panel gave it
        self._move_seen_at: float | None = None
        self._last_command_change: float | None = None
        self.drive = DriveSettings(0, 4, 1, 1, 3000.0)
        self.counts_per_output_turn = 0
        self.status_label = QLabel("")
        self.status_label.setObjectName("scopeBenchStatus")
        self.status_label.setWordWrap(True)
        layout.addWidget(self.status_label)
        if shutil.which(sigrok.SIGROK_CLI) is None:
            self.status_label.setText(sigrok.INSTALL_HINT)
            for widget in (self.scan_button, self.start_button):
                widget.setEnabled(False)
        else:
            self.status_label.setText("Bench instruments through sigrok-cli: Find lists them.")

    # -- actions --

    def scan(self) -> None:
        self.scan_button.setEnabled(False)
        self.status_label.setText("Looking for instruments …")
        self.source.sigScan.emit("")

    def set_axis(self, counts_per_output_turn: int, drive: DriveSettings) -> None:
        """The axis's encoder counts per output turn and the parameters that decode its command
        pulses (from the drive or the front panel)."""
        self.counts_per_output_turn = counts_per_output_turn
        self.drive = drive

    def start(self, device: str, channels: str, rate: str = "", encoder: str = "", command: str = "",
              in_position: str = "", alarm: str = "", alm: tuple[str, ...] = ()) -> None:
        """Stream (what the Start button does with the fields' text); ``alm``: the channels of
        ALM-A, ALM-B, ALM-C, ALM-D ("" for a line not mapped)."""
        self.device_box.setEditText(device)  # first: a mapping it offers is then replaced
        self.alarm_edit.setText(alarm)
        for edit, name in zip(self.alm_edits, tuple(alm) + ("",) * (4 - len(alm)), strict=True):
            edit.setText(name)
        self.encoder_edit.setText(encoder)
        self.command_edit.setText(command)
        self.in_position_edit.setText(in_position)
        self.channels_edit.setText(channels)
        self.channels_edit.setCursorPosition(0)  # a long list shows its first channels, not its end
        self.rate_edit.setText(rate)
        self.start_button.setChecked(True)
        self._start_clicked(True)

    def stop(self) -> None:
        self.source.stop()

    def back_to_live(self) -> None:
        """The newest seconds again (the stream went on meanwhile: nothing of it is lost)."""
        if self._held is None:
            return
        self._held = None
        self.hold_bar.setVisible(False)
        self._x_range = self._y_range = self._counts_range = None
        self._draw_live()

    def _hold(self, started: BenchStarted, rows: np.ndarray) -> None:
        """The move's rows on the plots until the next move or Back to live."""
        self._held = rows
        # the move's start by the one clock every stamp reads (its time since, by the stream's own)
        ago_s = time.monotonic() - started.t0 - float(rows[0, 0])
        at = (clock.now_utc() - datetime.timedelta(seconds=ago_s)).astimezone()
        self.showing_label.setText(f"Showing the move at {at:%H:%M:%S}"
                                   f" ({float(rows[-1, 0] - rows[0, 0]):.2f} s) while the stream goes on.")
        self.hold_bar.setVisible(True)
        self._x_range = self._y_range = self._counts_range = None
        self._draw(started, rows, (float(rows[0, 0]), float(rows[-1, 0])))

    def shutdown(self) -> None:
        self.source.shutdown()

    # -- slots --

    def _start_clicked(self, checked: bool) -> None:
        if not checked:
            self.stop()
            return
        device = self.device_box.currentText().split(" ", 1)[0].strip()
        names = tuple(c.strip() for c in self.channels_edit.text().split(",") if c.strip())
        try:
            rate = _rate(self.rate_edit.text())
        except ValueError:
            self._refuse(f"Sample rate '{self.rate_edit.text()}': a number of Hz, e.g. 200k or 1m.")
            return
        if not device or not names:
            self._refuse("Give the instrument (Find lists them) and its channels.")
            return
        phases = tuple(c.strip() for c in self.encoder_edit.text().split(",") if c.strip())
        if phases and len(phases) != 2:
            self._refuse("Encoder: its A and B channels, e.g. D0,D1.")
            return
        encoder = (phases[0], phases[1]) if phases else None
        lines = tuple(c.strip() for c in self.command_edit.text().split(",") if c.strip())
        if len(lines) > 2:
            self._refuse("Command: its A line and, where there is one, its B line, e.g. D2,D3.")
            return
        command = (lines[0], lines[1] if len(lines) > 1 else None) if lines else None
        in_position = self.in_position_edit.text().strip()
        if in_position and in_position not in names:
            self._refuse(f"IN-POS {in_position}: it must be among the channels ({', '.join(names)}).")
            return
        for line, name in (("ALARM", self.alarm_edit.text().strip()),
                           *zip(alarm_code.LINES, self._alm_names(), strict=True)):
            if name and name not in names:
                self._refuse(f"{line} {name}: it must be among the channels ({', '.join(names)}).")
                return
        self._alarm_shown = None
        self.alarm_label.setVisible(False)
        self.move_figures = None
        self.checks = []
        self._move_seen_at = None
        self._last_command_change = None
        self.move_label.setText("")
        self._held = None
        self.hold_bar.setVisible(False)
        self.status_label.setText(f"Starting {device} …")
        self.source.start(BenchSettings(device, names, rate, encoder, command, self.drive))

    def _refuse(self, text: str) -> None:
        self.start_button.setChecked(False)
        self.status_label.setText(text)

    @Slot(object, str)
    def _on_devices(self, devices: list, why: str) -> None:
        self.scan_button.setEnabled(True)
        current = self.device_box.currentText()
        self.device_box.clear()
        for device in devices:
            self.device_box.addItem(f"{device.spec}  ({device.description})")
        if current and not devices:
            self.device_box.setEditText(current)
        if why:
            self.status_label.setText(why)
        else:
            self.status_label.setText(f"{len(devices)} instrument(s) found." if devices
                                      else "sigrok-cli finds no instrument (is it plugged in?)")
        self.sigDevicesListed.emit(len(devices))

    def _alm_names(self) -> tuple[str, ...]:
        """The channels of ALM-A ... ALM-D ("" for a line not mapped)."""
        return tuple(edit.text().strip() for edit in self.alm_edits)

    def _fields(self) -> dict[str, str]:
        fields = {"channels": self.channels_edit.text(), "rate": self.rate_edit.text(),
                  "encoder": self.encoder_edit.text(), "command": self.command_edit.text(),
                  "in_position": self.in_position_edit.text(), "alarm": self.alarm_edit.text()}
        fields.update({f"alm_{'abcd'[i]}": edit.text() for i, edit in enumerate(self.alm_edits)})
        return fields

    def _offer_mapping(self, text: str) -> None:
        """The channels and roles last used with this instrument, if it was used before."""
        spec = text.split(" ", 1)[0].strip()
        fields = bench_mappings.saved(spec)
        if fields is None or self.source.running:
            return
        self.channels_edit.setText(fields.get("channels", ""))
        self.channels_edit.setCursorPosition(0)
        self.rate_edit.setText(fields.get("rate", ""))
        self.encoder_edit.setText(fields.get("encoder", ""))
        self.command_edit.setText(fields.get("command", ""))
        self.in_position_edit.setText(fields.get("in_position", ""))
        self.alarm_edit.setText(fields.get("alarm", ""))
        for i, edit in enumerate(self.alm_edits):
            edit.setText(fields.get(f"alm_{'abcd'[i]}", ""))
        self.status_label.setText(f"Channels and roles as last used with {spec}.")

    def _on_started(self, started: BenchStarted) -> None:
        bench_mappings.save(started.device, self._fields())
        self._started = started
        self.plot.clear()
        self.analog_plot.clear()
        self._curves = []
        # a logic analyzer's look: one lane per logic channel (the first at the top), named at the
        # right beside it, the code lines ALM-A ... D in one lane where the first of them would be;
        # the analog ones in volts in their own plot, named at its right too
        self._code_bits = [(bit, started.channels.index(name)) for bit, name in enumerate(self._alm_names())
                           if name in started.channels and name in started.logic]
        code_first = min((i for _, i in self._code_bits), default=None)
        in_code = {i for _, i in self._code_bits}
        rows = [i for i, name in enumerate(started.channels)
                if name in started.logic and (i not in in_code or i == code_first)]
        offsets = {i: LANE_STEP * (len(rows) - 1 - n) for n, i in enumerate(rows)}
        self._lanes = [offsets[i] if i in offsets and i not in in_code else None
                       for i in range(len(started.channels))]
        self._code_lane = offsets.get(code_first) if code_first is not None else None
        for i in range(len(started.channels)):
            pen = pg.mkPen(_COLORS[i % len(_COLORS)], width=1)
            if i in in_code:  # drawn in the code's lane
                curve = pg.PlotDataItem()
            else:
                lane = self._lanes[i] is not None
                plot = self.plot if lane else self.analog_plot
                curve = plot.plot([], [], pen=pen)
            curve.setSkipFiniteCheck(True)  # display rows are finite, and already one or two a pixel
            self._curves.append(curve)
        lanes = [(offsets[i] + LANE_HIGH / 2, f"bench {started.labels[i]}") for i in rows if i not in in_code]
        if self._code_lane is not None:
            lanes.append((self._code_lane + LANE_HIGH / 2, f"bench {started.device}:"
                          + " ".join(["ALM-D", "C", "B", "A"])))
            for edge in self._code_edges:
                self.plot.addItem(edge)
        self._code_texts = []
        self.analog_names = [f"bench {started.labels[i]}" for i, name in enumerate(started.channels)
                             if name not in started.logic]
        self._named = len(self.analog_names)
        self.counts_name = (f"bench {started.labels[len(started.channels) + started.extra.index('counts')]}"
                            if "counts" in started.extra else "")
        counting = "counts" in started.extra
        self.plot.setVisible(bool(lanes))
        self.analog_plot.setVisible(bool(self._named))
        self.counts_plot.setVisible(counting)
        shown = [p for p in (self.plot, self.analog_plot, self.counts_plot) if not p.isHidden()]
        for plot in (self.plot, self.analog_plot, self.counts_plot):  # one time axis: the lowest plot's
            plot.showAxis("bottom", bool(shown) and plot is shown[-1])
        self.plot.getAxis("right").setTicks([lanes, []] if lanes else None)
        # every plot's right axis as wide as the longest name, so times align
        names = [name for _, name in lanes] + self.analog_names + [self.counts_name]
        width = max(self.lane_metrics.horizontalAdvance(name) for name in names) + 12
        for plot in (self.plot, self.analog_plot, self.counts_plot):
            plot.showAxis("right", True)
            plot.getAxis("right").setWidth(width)
        # the lanes at a fixed height each: their plot is as high as they need, the others stretch
        # from a readable least height
        def time_axis_px(plot: pg.PlotWidget) -> int:
            return int(plot.getAxis("bottom").height()) if plot is shown[-1] else 0

        for plot in (self.analog_plot, self.counts_plot):
            plot.setMinimumHeight(TRACE_VIEW_MIN_PX + PLOT_MARGINS_PX + time_axis_px(plot))
        if lanes:
            self.plot.setFixedHeight(len(lanes) * self.lane_px + PLOT_MARGINS_PX + time_axis_px(self.plot))
            gap = (LANE_STEP - LANE_HIGH) / 2  # half a lane's gap above the top one and below the lowest
            self.plot.setYRange(-gap, len(lanes) * LANE_STEP - gap, padding=0)
        for plot in (self.plot, self.analog_plot, self.counts_plot):
            plot.enableAutoRange(enable=False)  # set per frame: lanes, analog, counts
        self._y_range = self._counts_range = self._x_range = None
        self._counts_curve.setData([], [])
        if counting:
            label = started.labels[len(started.channels) + started.extra.index("counts")]
            # named at the right (a vertical axis label of this length is cut at this height)
            self.counts_plot.setLabel("left", f"bench {label}")
            self.counts_plot.getAxis("left").showLabel(False)
        # one line: every trace is named on the plot, and all of them in the tooltip
        decoded = len(started.labels) - len(started.channels)
        self.status_label.setText(f"LIVE from the bench: {started.device} at "
                                  f"{sigrok.rate_text(started.sample_rate_hz)}, "
                                  f"{_counted(len(started.channels), 'channel')}"
                                  + (f" and {decoded} decoded" if decoded else ""))
        self.status_label.setToolTip(", ".join(started.labels))

    def _on_rows(self, _rows: np.ndarray) -> None:
        started = self._started
        if started is None:
            return
        newest = self._draw_live() if self._held is None else started.ring.window(1)
        if not len(newest):
            return
        self._show_alarm(started, newest[-1])
        self._measure_move(started, _rows)

    def _draw_live(self) -> np.ndarray:
        """The newest WINDOW_S of the stream on the plots; the rows drawn (none: nothing yet)."""
        started = self._started
        if started is None:
            return np.empty((0, 1))
        rows = started.ring.window(int((WINDOW_S + STEP_S) * started.row_rate_hz))
        if not len(rows):
            return rows
        # the time axis steps on every STEP_S instead of scrolling each frame (a new range lays
        # its ticks out again, which costs more than the traces): the newest WINDOW_S always shows
        right = (math.floor(float(rows[-1, 0]) / STEP_S) + 1) * STEP_S
        return self._draw(started, rows, (max(0.0, right - WINDOW_S - STEP_S), max(right, WINDOW_S + STEP_S)))

    def _draw(self, started: BenchStarted, rows: np.ndarray, x_range: tuple[float, float]) -> np.ndarray:
        """``rows`` on the plots over ``x_range`` [s]; the rows as drawn."""
        # drawn as the plot's pixels show it (each pixel's least and largest value), over a fixed
        # window: a redraw neither walks every row nor looks for the data's bounds
        rows = peak_rows(_busy_as_band(rows, self._lanes), max(200, self.plots.width() - LEFT_AXIS_PX))
        if x_range != self._x_range:
            self._x_range = x_range
            for plot in (self.plot, self.analog_plot, self.counts_plot):  # linked, also where hidden
                plot.setXRange(*x_range, padding=0)
        low, high = math.inf, -math.inf
        in_code = {i for _, i in self._code_bits}
        for i, (curve, lane) in enumerate(zip(self._curves, self._lanes, strict=True)):
            values = rows[:, 1 + i]
            if lane is not None:
                values = values * LANE_HIGH + lane
            else:
                low, high = min(low, float(values.min())), max(high, float(values.max()))
            if i not in in_code:
                curve.setData(rows[:, 0], values)
        if self._code_lane is not None:
            self._draw_code(rows, x_range)
        if self._named:
            # the analog range moves only when a trace leaves it or fills less than half of it (a
            # new range lays the axis out again, which costs more than the traces)
            shown = self._y_range
            if (shown is None or low < shown[0] or high > shown[1]
                    or (high - low) < 0.5 * (shown[1] - shown[0])):
                pad = max(0.1 * (high - low), MIN_ANALOG_PAD_V)
                self._y_range = (low - pad, high + pad)
                self.analog_plot.setYRange(*self._y_range, padding=0)
                _names_at_right(self.analog_plot, self.analog_names, self._y_range)
        if "counts" in started.extra:
            counts = rows[:, 1 + len(started.channels)]
            self._counts_curve.setData(rows[:, 0], counts)
            lo, hi = float(counts.min()), float(counts.max())
            shown = self._counts_range
            # the counts' range moves only when they leave it or fill less than half of it
            if shown is None or lo < shown[0] or hi > shown[1] or (hi - lo) < 0.5 * (shown[1] - shown[0]):
                pad = max(0.1 * (hi - lo), MIN_COUNTS_PAD)  # a count's dither at standstill is no band
                self._counts_range = (lo - pad, hi + pad)
                self.counts_plot.setYRange(*self._counts_range, padding=0)
                _names_at_right(self.counts_plot, [self.counts_name], self._counts_range)
        return rows

    def _draw_code(self, rows: np.ndarray, x_range: tuple[float, float]) -> None:
        """The alarm code's lane as a logic analyzer draws a bus: a band that crosses where the
        code changes, the code (ALM-D C B A, "?" for a line not mapped) written in each stretch
        wide enough for it."""
        assert self._code_lane is not None
        t = rows[:, 0]
        code = np.zeros(len(rows), dtype=int)
        for bit, i in self._code_bits:
            code |= (rows[:, 1 + i] >= CHANGED).astype(int) << bit
        changes = np.flatnonzero(np.diff(code) != 0) + 1
        low, high = self._code_lane, self._code_lane + LANE_HIGH
        middle = (low + high) / 2
        px = max(1, self.plot.getViewBox().width())
        half = 3.0 * (x_range[1] - x_range[0]) / px  # the crossing's half width: 3 px
        at = t[changes]
        xs = np.concatenate([[t[0]], np.column_stack([at - half, at, at + half]).ravel(), [t[-1]]])
        for edge, side in zip(self._code_edges, (high, low), strict=True):
            ys = np.concatenate([[side], np.tile([side, middle, side], len(at)), [side]])
            edge.setData(xs, ys)
        mapped = {bit for bit, _ in self._code_bits}
        starts = np.concatenate([[0], changes])
        ends = np.concatenate([changes, [len(t) - 1]])
        shown = 0
        for start, end in zip(starts, ends, strict=True):
            digits = "".join(str(code[start] >> bit & 1) if bit in mapped else "?" for bit in (3, 2, 1, 0))
            width_px = (t[end] - t[start]) * px / (x_range[1] - x_range[0])
            if width_px < self.lane_metrics.horizontalAdvance(digits) + 10:
                continue
            if shown == len(self._code_texts):
                if shown >= 16:  # a code that flickers: its crossings say so
                    break
                text = pg.TextItem(color="#7f3f00", anchor=(0.5, 0.5))
                text.setFont(self._lane_font)
                self.plot.addItem(text)
                self._code_texts.append(text)
            text = self._code_texts[shown]
            text.setText(digits)
            text.setPos((max(t[start], x_range[0]) + min(t[end], x_range[1])) / 2, middle)
            text.setVisible(True)
            shown += 1
        for text in self._code_texts[shown:]:
            text.setVisible(False)

    def _alarm_columns(self, started: BenchStarted) -> tuple[int | None, list[int | None]]:
        """The row columns of ALARM and of ALM-A ... D (None: not mapped)."""
        def column(name: str) -> int | None:
            return 1 + started.channels.index(name) if name and name in started.channels else None

        return column(self.alarm_edit.text().strip()), [column(name) for name in self._alm_names()]

    def _show_alarm(self, started: BenchStarted, row: np.ndarray) -> None:
        """ALARM and the code on ALM-D C B A as the newest row has them, in the manual's words."""
        alarm_column, alm_columns = self._alarm_columns(started)
        if alarm_column is None and all(c is None for c in alm_columns):
            return
        on = None if alarm_column is None else bool(row[alarm_column] >= CHANGED)
        code = None
        if any(c is not None for c in alm_columns):
            code = sum(1 << bit for bit, c in enumerate(alm_columns) if c is not None and row[c] >= CHANGED)
        if (on, code) == self._alarm_shown:
            return
        self._alarm_shown = (on, code)
        parts = [] if on is None else [f"ALARM {'ON' if on else 'off'}"]
        if code is not None:
            unmapped = [line for line, c in zip(alarm_code.LINES, alm_columns, strict=True) if c is None]
            parts.append(alarm_code.code_text(code, unmapped=unmapped))
        alarmed = bool(on) or bool(code)
        self.alarm_label.setText(("Alarm from the bench: " if alarmed else "") + "; ".join(parts)
                                 + ("; the front panel's 2-digit code and the Alarms page say more" if alarmed
                                    else ""))
        self.alarm_label.setStyleSheet("color: #b00000; font-weight: bold;" if alarmed else "")
        self.alarm_label.setVisible(True)

    def _measure_move(self, started: BenchStarted, new_rows: np.ndarray) -> None:
        """The move test's figures of the last move the command made, once it has settled."""
        if not {"counts", "command"} <= set(started.extra) or self.counts_per_output_turn <= 0:
            return
        column = 1 + len(started.channels) + started.extra.index("command")
        if len(new_rows) > 1:
            moved = np.flatnonzero(np.diff(new_rows[:, column]) != 0)
            if moved.size:
                self._last_command_change = float(new_rows[moved[-1] + 1, 0])
        last = self._last_command_change
        if (last is None or last == self._move_seen_at or not len(new_rows)
                or new_rows[-1, 0] - last < MOVE_SETTLED_S):
            return
        rows = started.ring.window(copy=True)  # the whole ring: a view would be overwritten meanwhile
        if len(rows) < 3:
            return
        t = rows[:, 0]
        first = 1 + len(started.channels)
        enc = rows[:, first + started.extra.index("counts")]
        cmd = rows[:, first + started.extra.index("command")]
        changes = np.flatnonzero(np.diff(cmd) != 0)
        if changes.size == 0:
            return
        self._move_seen_at = last
        gaps = np.flatnonzero(np.diff(t[changes + 1]) >= MOVE_GAP_S)
        begun = int(changes[gaps[-1] + 1]) if gaps.size else int(changes[0])
        start = max(0, int(np.searchsorted(t, t[begun] - 0.05)))
        in_position = self.in_position_edit.text().strip()
        in_pos = (rows[start:, 1 + started.channels.index(in_position)]
                  if in_position in started.channels else None)
        try:
            figures = bench_move_figures(t[start:], cmd[start:], enc[start:], in_pos,
                                         self.counts_per_output_turn / 360.0)
        except ValueError:
            return
        self.move_figures = figures
        # the move on show: from a little before its command began until a little after IN-POS
        # came on (without IN-POS: all the rows its figures were taken from)
        end = t[-1]
        if figures.in_position_time_s is not None:
            end = min(end, t[changes[-1] + 1] + figures.in_position_time_s + MOVE_AFTER_S)
        first_shown = int(np.searchsorted(t, t[begun] - MOVE_BEFORE_S))
        self._hold(started, rows[first_shown: int(np.searchsorted(t, end, side="right"))].copy())
        alarm_name = self.alarm_edit.text().strip()
        alarm_column, alm_columns = self._alarm_columns(started)
        alarm = rows[start:, alarm_column] if alarm_column is not None else None
        code = None
        if any(c is not None for c in alm_columns):
            code = sum((rows[start:, c] >= CHANGED).astype(int) << bit for bit, c in enumerate(alm_columns)
                       if c is not None)
        unmapped = [line for line, c in zip(alarm_code.LINES, alm_columns, strict=True) if c is None]
        wired: list[tuple[str, Sequence[str]]] = [
            ("encoder A, B", self.encoder_edit.text().split(",")),
            ("command pulses", self.command_edit.text().split(",")),
            ("IN-POS", (in_position,)), ("ALARM", (alarm_name,))]
        wired += [(line, (name,)) for line, name in zip(alarm_code.LINES, self._alm_names(), strict=True)]
        self.checks = bench_checks(t[start:], cmd[start:], enc[start:], in_position=in_pos, alarm=alarm,
                                   in_position_time_s=figures.in_position_time_s,
                                   parameter_8=self.parameter_8,
                                   source=source_words(started.device, wired),
                                   alarm_code=code, alarm_lines_unmapped=unmapped)
        m = figures.metrics

        def ms(value: float | None) -> str:
            return "not reached" if value is None else f"{value * 1000:.1f} ms"

        inpos = ms(figures.in_position_time_s) if in_pos is not None else "no IN-POS channel"
        self.move_label.setText(units_kept(
            f"Move from the bench: {m.target - m.start:+.3f}°; overshoot {m.overshoot_percent:.2f} % "
            f"({m.overshoot:.4f}°); settling time {ms(m.settling_time_s)} "
            f"(band ±{m.settling_band:.3g}°); in-position (IN-POS) {inpos} after the command ended; "
            f"following error (command − encoder) at most "
            f"{_counted(figures.following_error_peak_counts, 'count')}, "
            f"{_counted(figures.following_error_end_counts, 'count')} at the end\n"
            + "; ".join(f"{CHECK_WORDS[c.check]}: {VERDICT[c.passed]}{_flange(c)}" for c in self.checks)))
        self.sigChecks.emit(list(self.checks))

    def _on_stopped(self, why: str) -> None:
        self.start_button.setChecked(False)
        samples = self.source.status.samples if self.source.status is not None else 0
        if why:
            self.status_label.setText(f"NOT LIVE: {why}")
        else:
            self.status_label.setText(f"Stopped after {samples} samples.")
