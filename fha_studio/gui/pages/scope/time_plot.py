"""The scope's time plot: one plot per unit, stacked on one linked time axis, with the legend
above the plots, two cursors and the cursor table under them.

Channels of different units never share a y-axis (position in hundreds of degrees would flatten
speed and current): each unit has its own plot, the time axes are linked (zooming or panning one
moves all) and only the bottom one carries the time labels.

Live, the curves are drawn from pre-decimated min/max levels (``MinMaxLevels``): at most about
two points per pixel, already finite, so pyqtgraph's own downsampling, clipping and finiteness
check are switched off for them (they would cost more than the drawing). The time axis then
counts back from now (the newest sample at 0) and each plot's y range moves only when its data
leaves it or uses less than half of it: the axes, whose text is the costliest part of a frame, are
repainted only when they change, not 30 times a second. A capture, a test or a file is drawn
whole once, with pyqtgraph's peak downsampling and clip to view for zooming, on absolute time.
"""

from __future__ import annotations

import html
import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np
import pyqtgraph as pg
from pyqtgraph import exporters
from PySide6.QtCore import QBuffer, QIODevice, Qt, Signal
from PySide6.QtGui import QColor, QImage, QImageWriter, QPainter, QTextDocument
from PySide6.QtWidgets import QLabel, QVBoxLayout, QWidget

from fha_studio import clock, fileio
from fha_studio.logic.scope.channels import ScopeChannel
from fha_studio.logic.scope.levels import MinMaxLevels
from fha_studio.logic.wording import unit_words

from .cursor_table import CursorTable

#: The plots' background and the colour of their axes and text (a light plot: the channel
#: colours are the same on the plot, in the legend and in the channel table, all readable).
BACKGROUND = "#ffffff"
FOREGROUND = "#303030"
#: Room around the legend above an exported plot [px].
LEGEND_MARGIN_PX = 6


class _UnitPlot:
    """One plot of the stack: the channels of one unit, its y range and its live grid lines."""

    def __init__(self, item: pg.PlotItem, unit: str):
        self.item = item
        self.unit = unit
        self.keys: list[str] = []
        self.y_range: tuple[float, float] | None = None
        self.grid_lines: list[pg.InfiniteLine] = []
        self.cursors: tuple[pg.InfiniteLine, pg.InfiniteLine] | None = None
        #: a curve of this plot holds a sample: until then its value axis has no numbers (an
        #: empty plot's 0 to 1 would read as a channel that measures 0 to 1)
        self.has_data = True
        self._tick_length = item.getAxis("left").style["tickLength"]
        self.show_data(False)

    def show_data(self, has_data: bool) -> None:
        """The value axis' numbers and ticks with data; neither without (no made-up divisions)."""
        if has_data == self.has_data:
            return
        self.has_data = has_data
        self.item.getAxis("left").setStyle(showValues=has_data,
                                           tickLength=self._tick_length if has_data else 0)

    def holds_samples(self) -> bool:
        return any(curve.xData is not None and len(curve.xData) > 0 for curve in self.item.listDataItems())

    @property
    def view_box(self) -> pg.ViewBox:
        return self.item.vb


class TimePlot(QWidget):
    """Curves against time in one plot per unit, the legend, the cursors and their table."""

    sigCursorsMoved = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        pg.setConfigOptions(antialias=False)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(2)
        self.legend = QLabel("")
        self.legend.setObjectName("scopeLegend")
        self.legend.setWordWrap(True)
        self.legend.setTextFormat(Qt.TextFormat.RichText)
        layout.addWidget(self.legend)
        self.plot = pg.GraphicsLayoutWidget()
        self.plot.setObjectName("scopePlot")
        self.plot.setBackground(BACKGROUND)
        self.plot.ci.setSpacing(0)
        layout.addWidget(self.plot, 1)
        self.cursor_table = CursorTable()
        self.cursor_table.setVisible(False)
        layout.addWidget(self.cursor_table)
        self._plots: list[_UnitPlot] = []
        self._curves: dict[str, pg.PlotDataItem] = {}
        self._grid_pen = pg.mkPen(0, 0, 0, 40)
        self._grid_on = False
        self._cursors_on = False
        self._cursor_t = (0.0, 0.0)  # the cursors' positions on the plots' x axis
        self._live = False
        #: the clock time of the live view's newest drawing: "now" on its time axis
        self._live_now = ""
        self._x_offset = 0.0  # live: the time shown as 0 (now) [s]; still data: 0
        self._live_span: float | None = None
        self.autoscale = True
        self._legend_entries: list[str] = []  # the shown channels, as rich text
        self._note = ""
        self._shown: tuple | None = None  # what set_curves was given last
        # a bench instrument's traces beside CN3's (label -> curve, its plot), their units and legend
        self._bench: dict[str, tuple[pg.PlotDataItem, pg.PlotItem]] = {}
        self._bench_units: list[str] = []
        self._bench_entries: list[str] = []
        self._bench_ranges: dict[str, tuple[float, float]] = {}  # unit -> the bench traces' extent
        self._still_grid = False
        self._set_units([""])

    # -- the stack of plots ------------------------------------------------------------------------
    @property
    def view_box(self) -> pg.ViewBox:
        """The top plot's view box (the time axis is the same in every plot)."""
        return self._plots[0].view_box

    def plot_items(self) -> list[pg.PlotItem]:
        """The plots, top to bottom (one per unit of the shown channels)."""
        return [p.item for p in self._plots]

    def plot_of(self, key: str) -> pg.PlotItem | None:
        """The plot that shows channel ``key`` (None when it is not shown)."""
        return next((p.item for p in self._plots if key in p.keys), None)

    def _set_units(self, units: Sequence[str]) -> None:
        """One plot per unit, in this order, with a linked time axis (rebuilt only on change)."""
        if [p.unit for p in self._plots] == list(units):
            return
        (x0, x1), _ = self.view_box.viewRange() if self._plots else ((0.0, 1.0), None)
        self.plot.ci.clear()
        self._plots = []
        for row, unit in enumerate(units):
            item = pg.PlotItem()
            item.setMenuEnabled(False)
            for name in ("left", "bottom"):
                axis = item.getAxis(name)
                axis.setPen(FOREGROUND)
                axis.setTextPen(FOREGROUND)
            item.getAxis("left").setWidth(64)  # the same for all: the time axes line up
            item.getAxis("left").enableAutoSIPrefix(False)  # degrees stay degrees, not "kdeg"
            # stacked plots: a tick label at a plot's edge would sit on the next plot's ("1.0"
            # over "0"); only the labels within their own plot's height are drawn
            item.getAxis("left").setStyle(hideOverlappingLabels=True)
            item.setLabel("left", unit_words(unit) or "value")
            self.plot.addItem(item, row=row, col=0)
            plot = _UnitPlot(item, unit)
            item.vb.sigYRangeChanged.connect(lambda *_a, p=plot: self._update_grid_lines(p))
            if self._plots:
                item.setXLink(self._plots[0].item)
            self._plots.append(plot)
        for plot in self._plots[:-1]:
            plot.item.getAxis("bottom").setStyle(showValues=False)
        self._plots[-1].item.setLabel("bottom", "time before now" if self._live else "time", units="s")
        self.view_box.setXRange(x0, x1, padding=0)
        self._apply_grid()
        self._apply_autoscale()
        cursors_on, self._cursors_on = self._cursors_on, False
        if cursors_on:
            self._add_cursors()
            self._cursors_on = True

    def show_grid_for_still_data(self, still: bool) -> None:
        """Still data: the axes' grid. Live: no x grid (it would scroll every frame) and the y grid
        as plain lines: an axis that draws a grid covers the plot and repaints its text with
        every frame of the curves."""
        self._still_grid = still
        self._apply_grid()

    def _apply_grid(self) -> None:
        still = self._still_grid
        self._grid_on = not still
        for plot in self._plots:
            plot.item.showGrid(x=still, y=still, alpha=0.3)
            self._update_grid_lines(plot)

    def _update_grid_lines(self, plot: _UnitPlot) -> None:
        """Horizontal lines at the left axis' major ticks (live only)."""
        for line in plot.grid_lines:
            plot.item.removeItem(line)
        plot.grid_lines = []
        if not self._grid_on or not plot.has_data:  # an empty plot's lines would mark 0 to 1
            return
        _, (y0, y1) = plot.view_box.viewRange()
        levels = plot.item.getAxis("left").tickValues(y0, y1, max(50, plot.view_box.height()))
        for value in (levels[0][1] if levels else []):
            line = pg.InfiniteLine(pos=value, angle=0, movable=False, pen=self._grid_pen)
            plot.item.addItem(line, ignoreBounds=True)
            plot.grid_lines.append(line)

    # -- curves ------------------------------------------------------------------------------------
    def set_curves(self, channels: Sequence[ScopeChannel], visible: Mapping[str, bool],
                   scale: Mapping[str, float], color: Callable[[str], str], live: bool,
                   note: str = "") -> None:
        """One curve per visible channel, in the plot of its unit, named in the legend with its
        unit and scale; ``live`` switches the time axis to "before now" and the y range to
        ``autoscale`` with hysteresis. ``note`` goes after the legend (what is shown, and why)."""
        self._shown = (channels, visible, scale, color, live, note)
        live_changed = live != self._live
        if live_changed:
            self._live = live
            self._x_offset, self._live_span = 0.0, None
        shown = [c for c in channels if visible.get(c.key, True)]
        units = list(dict.fromkeys([c.unit for c in shown] + self._bench_units)) or [""]
        for plot in self._plots:
            for key in plot.keys:
                curve = self._curves.get(key)
                if curve is not None:
                    plot.item.removeItem(curve)
            plot.keys = []
        self._curves.clear()
        self._set_units(units)
        if live_changed:
            self._plots[-1].item.setLabel("bottom", "time before now" if live else "time", units="s")
            for plot in self._plots:
                plot.y_range = None
            self._apply_autoscale()
        entries = []
        for c in shown:
            plot = self._plots[units.index(c.unit)]
            factor = scale.get(c.key, 1.0)
            label = f"{c.name} [{unit_words(c.unit)}]" + (f" ×{factor:g}" if factor != 1 else "")
            curve = plot.item.plot(pen=pg.mkPen(color(c.key), width=1.5 if not live else 1))
            if live:  # already decimated and finite (MinMaxLevels)
                curve.setDownsampling(ds=1, auto=False)
                curve.setClipToView(False)
                curve.setSkipFiniteCheck(True)
            else:
                curve.setDownsampling(auto=True, method="peak")
                curve.setClipToView(True)
            plot.keys.append(c.key)
            self._curves[c.key] = curve
            entries.append(f"<span style='color:{color(c.key)}; font-weight:bold'>━━</span>&nbsp;"
                           f"{_unbroken(label)}")
        self._legend_entries = entries
        self.set_note(note)
        self._show_which_hold_data()

    def _show_which_hold_data(self) -> None:
        """Each plot's value axis gets its numbers with its first sample, and loses them when
        its curves are emptied."""
        for plot in self._plots:
            had = plot.has_data
            plot.show_data(plot.holds_samples())
            if plot.has_data != had:
                self._update_grid_lines(plot)

    def show_time_base(self, span_s: float) -> None:
        """Live: the time axis shows the time base, ``span_s`` before now to now, also before the
        first sample (an empty live view read 0 to 1 s "before now" under a 10 s time base)."""
        if self._live:
            self._live_span = span_s
            self.view_box.setXRange(-span_s, 0.0, padding=0)

    def set_note(self, note: str) -> None:
        """The line under the legend: what the plots show, and why."""
        self._note = note
        entries = self._legend_entries + self._bench_entries
        text = " &nbsp; ".join(entries) if entries else "No channel ticked: tick one in the table."
        if note:
            text += f"<br><span style='color:#555'>{html.escape(note)}</span>"
        self.legend.setText(text)

    def curve(self, key: str) -> pg.PlotDataItem | None:
        """The curve of channel ``key`` (None when it is not shown)."""
        return self._curves.get(key)

    def draw_levels(self, levels: MinMaxLevels, channels: Sequence[ScopeChannel], t0_s: float, t1_s: float,
                    scale: Mapping[str, float]) -> None:
        """Draw [t0_s, t1_s] of the live levels: about one min/max bin per pixel."""
        bins = max(200, self.plot.width())
        t, y = levels.window(t0_s, t1_s, bins)
        t -= t1_s
        self._x_offset = t1_s
        self._live_now = f"{clock.now_local():%H:%M:%S}"
        ranges: dict[str, tuple[float, float]] = {}
        for j, c in enumerate(channels):
            curve = self._curves.get(c.key)
            if curve is not None:
                factor = scale.get(c.key, 1.0)
                column = y[:, j] * factor if factor != 1 else y[:, j]
                curve.setData(t, column)
                if len(column):
                    lo, hi = ranges.get(c.unit, (np.inf, -np.inf))
                    ranges[c.unit] = min(lo, float(column.min())), max(hi, float(column.max()))
        span = t1_s - t0_s
        if span != self._live_span:
            self._live_span = span
            self.view_box.setXRange(-span, 0.0, padding=0)
        if self.autoscale:
            for plot in self._plots:
                lo, hi = ranges.get(plot.unit, (np.inf, -np.inf))
                b_lo, b_hi = self._bench_ranges.get(plot.unit, (np.inf, -np.inf))  # bench traces beside
                lo, hi = min(lo, b_lo), max(hi, b_hi)
                if lo <= hi:
                    self._follow_y(plot, lo, hi)
        if self._cursors_on:
            self._place_cursors()
        self._show_which_hold_data()

    @staticmethod
    def _follow_y(plot: _UnitPlot, lo: float, hi: float) -> None:
        """Move the y range only when the data leaves it or fills less than half of it."""
        current = plot.y_range
        if current is not None:
            c_lo, c_hi = current
            if c_lo <= lo and hi <= c_hi and (hi - lo) >= 0.5 * (c_hi - c_lo):
                return
        pad = 0.1 * (hi - lo) if hi > lo else max(1.0, abs(hi) * 0.1)
        plot.y_range = (lo - pad, hi + pad)
        plot.view_box.setYRange(*plot.y_range, padding=0)

    def draw_rows(self, channels: Sequence[ScopeChannel], rows: np.ndarray,
                  scale: Mapping[str, float]) -> None:
        """Draw still data, rows ``[t_s, values...]``."""
        for j, c in enumerate(channels):
            curve = self._curves.get(c.key)
            if curve is not None:
                curve.setData(rows[:, 0], rows[:, j + 1] * scale.get(c.key, 1.0))
        self._show_which_hold_data()

    def fit(self, rows: np.ndarray | None, columns: Mapping[str, Sequence[int]] | Sequence[int],
            factors: Mapping[str, Sequence[float]] | Sequence[float], autoscale: bool) -> None:
        """Show all of ``rows`` (x from the data; y of each plot over its ``columns[unit]`` x
        ``factors[unit]``), or the curves' own range when there are no rows."""
        if rows is not None and len(rows):
            t = rows[:, 0]
            self.view_box.setXRange(float(t[0]), float(t[-1]), padding=0.02)  # from the data
            by_unit_columns = columns if isinstance(columns, Mapping) else {"": columns}
            by_unit_factors = factors if isinstance(factors, Mapping) else {"": factors}
            for plot in self._plots:
                cols = list(by_unit_columns.get(plot.unit, ()))
                if cols:
                    y = rows[:, cols] * list(by_unit_factors.get(plot.unit, [1.0] * len(cols)))
                    lo, hi = float(np.nanmin(y)), float(np.nanmax(y))
                    plot.view_box.setYRange(lo, hi if hi > lo else lo + 1.0, padding=0.05)
        else:
            for plot in self._plots:
                plot.view_box.autoRange(padding=0.02)
        if autoscale and not self._live:
            for plot in self._plots:
                plot.view_box.enableAutoRange(axis="y", enable=True)
        self._live_span = None  # live: the next frame shows the time base again
        for plot in self._plots:
            plot.y_range = None
        self._show_which_hold_data()

    def set_autoscale(self, on: bool) -> None:
        self.autoscale = bool(on)
        for plot in self._plots:
            plot.y_range = None
        self._apply_autoscale()

    def _apply_autoscale(self) -> None:
        for plot in self._plots:
            plot.view_box.enableAutoRange(axis="y", enable=self.autoscale and not self._live)

    def x_range(self) -> tuple[float, float]:
        """The time range on show [s], in the data's own time (live: not "before now")."""
        (x0, x1), _ = self.view_box.viewRange()
        return float(x0) + self._x_offset, float(x1) + self._x_offset

    # -- cursors -----------------------------------------------------------------------------------
    @property
    def cursors_on(self) -> bool:
        return self._cursors_on

    def set_cursors_on(self, on: bool) -> None:
        if on == self._cursors_on:
            return
        self._cursors_on = on
        self.cursor_table.setVisible(on)
        if on:
            self._add_cursors()
            x0, x1 = self.x_range()
            self.set_cursors(x0 + 0.3 * (x1 - x0), x0 + 0.7 * (x1 - x0))
        else:
            for plot in self._plots:
                for line in plot.cursors or ():
                    plot.item.removeItem(line)
                plot.cursors = None

    def _add_cursors(self) -> None:
        """Cursor A (solid) and B (dashed) in every plot, moving together."""
        for plot in self._plots:
            a = pg.InfiniteLine(angle=90, movable=True, pen=pg.mkPen(FOREGROUND, width=1),
                                label="A" if plot is self._plots[0] else None,
                                labelOpts={"position": 0.95, "color": FOREGROUND})
            b = pg.InfiniteLine(angle=90, movable=True, pen=pg.mkPen(FOREGROUND, width=1,
                                                                     style=Qt.PenStyle.DashLine),
                                label="B" if plot is self._plots[0] else None,
                                labelOpts={"position": 0.95, "color": FOREGROUND})
            plot.cursors = (a, b)
            for index, line in enumerate((a, b)):
                line.setValue(self._cursor_t[index])
                plot.item.addItem(line, ignoreBounds=True)
                line.sigPositionChanged.connect(lambda ln, i=index: self._cursor_dragged(i, ln))

    def _cursor_dragged(self, index: int, line: pg.InfiniteLine) -> None:
        value = float(line.value())
        if value == self._cursor_t[index]:
            return
        t = list(self._cursor_t)
        t[index] = value
        self._cursor_t = (t[0], t[1])
        self._place_cursors()
        self.sigCursorsMoved.emit()

    def _place_cursors(self) -> None:
        for plot in self._plots:
            for index, line in enumerate(plot.cursors or ()):
                if float(line.value()) != self._cursor_t[index]:
                    line.setValue(self._cursor_t[index])

    def set_cursors(self, t1_s: float, t2_s: float) -> None:
        """Put the cursors at these times of the data (live: they then stay that long before now)."""
        self._cursor_t = (t1_s - self._x_offset, t2_s - self._x_offset)
        self._place_cursors()
        self.sigCursorsMoved.emit()

    def cursor_axis_times(self) -> tuple[float, float]:
        """The cursors' times as the time axis reads them [s] (live: before now, negative)."""
        return self._cursor_t

    @property
    def live(self) -> bool:
        return self._live

    @property
    def has_bench_curves(self) -> bool:
        return bool(self._bench)

    def set_bench_curves(self, traces: Mapping[str, tuple[str, np.ndarray, np.ndarray]],
                         colors: Sequence[str] = ("#555555",)) -> None:
        """A bench instrument's traces beside CN3's: label (with its source) -> (unit, time
        before now [s], values), each on the plot of its unit (one is added for a unit no CN3
        channel has), drawn as the live view draws (time before now). Empty: none."""
        units = list(dict.fromkeys(unit for unit, _t, _v in traces.values()))
        if units != self._bench_units:
            self._bench_units = units
            if self._shown is not None:  # CN3's curves again, in the plots of both
                channels, visible, scale, color, live, _note = self._shown
                self.set_curves(channels, visible, scale, color, live, self._note)
            else:
                self._set_units(units or [""])
        items = {p.unit: p for p in self._plots}
        current = {p.item for p in self._plots}
        for label in [k for k, (_c, item) in self._bench.items() if k not in traces or item not in current]:
            curve, item = self._bench.pop(label)
            if item in current:
                item.removeItem(curve)
        entries = []
        self._bench_ranges = {}
        for i, (label, (unit, t, values)) in enumerate(traces.items()):
            plot = items[unit]
            color = colors[i % len(colors)]
            known = self._bench.get(label)
            if known is None or known[1] is not plot.item:
                curve = plot.item.plot(pen=pg.mkPen(color, width=1, style=Qt.PenStyle.DashLine))
                self._bench[label] = (curve, plot.item)
            self._bench[label][0].setData(t, values)
            if len(values):
                lo, hi = self._bench_ranges.get(unit, (np.inf, -np.inf))
                self._bench_ranges[unit] = min(lo, float(np.min(values))), max(hi, float(np.max(values)))
            entries.append(f"<span style='color:{color}; font-weight:bold'>╌╌</span>&nbsp;"
                           f"{_unbroken(label)}")
        for plot in self._plots:  # a plot of bench traces only follows them here (CN3's: each frame)
            if not plot.keys and self.autoscale and plot.unit in self._bench_ranges:
                self._follow_y(plot, *self._bench_ranges[plot.unit])
        if entries != self._bench_entries:
            self._bench_entries = entries
            self.set_note(self._note)
        self._show_which_hold_data()

    def cursor_times(self) -> tuple[float, float]:
        """The cursors' times in the data's own time [s]."""
        return self._cursor_t[0] + self._x_offset, self._cursor_t[1] + self._x_offset

    def export_png(self, path) -> None:
        """The plots as a PNG with the legend above them (which curve is which channel, in its
        colour: a report's reader has no channel table beside the picture). The live view's
        "time before now" says which now on paper: the clock time of its newest drawing."""
        exporter = exporters.ImageExporter(self.plot.ci)
        exporter.parameters()["width"] = max(800, self.plot.width())
        bottom = self._plots[-1].item.getAxis("bottom")
        shown = bottom.labelText
        if self._live and self._live_now:
            bottom.setLabel(f"time before {self._live_now}", units="s")
        try:
            plots = exporter.export(toBytes=True)
        finally:
            bottom.setLabel(shown, units="s")
        entries = self._legend_entries + self._bench_entries
        document = QTextDocument()
        document.setDefaultFont(self.legend.font())
        document.setHtml(" &nbsp; ".join(entries))
        document.setTextWidth(plots.width() - 2 * LEGEND_MARGIN_PX)
        legend_height = math.ceil(document.size().height()) + 2 * LEGEND_MARGIN_PX if entries else 0
        image = QImage(plots.width(), plots.height() + legend_height, QImage.Format.Format_RGB32)
        image.fill(QColor(BACKGROUND))
        painter = QPainter(image)
        try:
            if entries:
                painter.translate(LEGEND_MARGIN_PX, LEGEND_MARGIN_PX)
                document.drawContents(painter)
                painter.resetTransform()
            painter.drawImage(0, legend_height, plots)
        finally:
            painter.end()
        buffer = QBuffer()
        buffer.open(QIODevice.OpenModeFlag.WriteOnly)
        writer = QImageWriter(buffer, b"PNG")
        if not writer.write(image):
            raise OSError(f"{path}: the plot could not be turned into a PNG ({writer.errorString()})")
        fileio.write_bytes(path, bytes(buffer.data().data()))  # whole or not at all


#: Where Qt would break a line inside a legend entry, and what keeps it whole there: a space, a
#: hyphen ("sim-cn2") and a slash ("CMD_A/CMD_B") take their no-break forms (a word joiner after
#: the slash).
_NO_BREAK = {" ": "&nbsp;", "-": "\u2011", "/": "/\u2060"}


def _unbroken(label: str) -> str:
    """A legend entry as HTML that wraps between entries, never inside one ("bench sim-" at a
    line's end and "cn2: ALM_A [bit]" on the next)."""
    return "".join(_NO_BREAK.get(ch, ch) for ch in html.escape(label))
