"""The scope's time plot: one curve per shown channel, two cursors and their read-out line.

Live, the curves are drawn from pre-decimated min/max levels (``MinMaxLevels``): at most about
two points per pixel, already finite, so pyqtgraph's own downsampling, clipping and finiteness
check are switched off for them (they would cost more than the drawing). The time axis then
counts back from now (the newest sample at 0) and the y range moves only when the data leaves
it or uses less than half of it: the axes, whose text is the costliest part of a frame, are
repainted only when they change, not 30 times a second. A capture, a test or a file is drawn
whole once, with pyqtgraph's peak downsampling and clip to view for zooming, on absolute time.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np
import pyqtgraph as pg
from pyqtgraph import exporters
from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import QLabel, QVBoxLayout, QWidget

from fha_studio.logic.scope.channels import ScopeChannel
from fha_studio.logic.scope.levels import MinMaxLevels


class TimePlot(QWidget):
    """Curves against time, the cursors, and the cursor read-out line under the plot."""

    sigCursorsMoved = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        pg.setConfigOptions(antialias=False)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.plot = pg.PlotWidget()
        self.plot.setObjectName("scopePlot")
        self.plot.setBackground("#111")
        self.plot.setLabel("bottom", "time", units="s")
        self.plot.addLegend(offset=(-8, 8), brush=pg.mkBrush(17, 17, 17, 200), labelTextColor="#ddd")
        self.plot.plotItem.vb.enableAutoRange(axis="y", enable=True)
        self._grid_lines: list[pg.InfiniteLine] = []
        self._grid_pen = pg.mkPen(255, 255, 255, 50)
        self._grid_on = False
        self.plot.plotItem.vb.sigYRangeChanged.connect(self._update_grid_lines)
        self.show_grid_for_still_data(False)
        self.cursor1 = pg.InfiniteLine(angle=90, movable=True, pen=pg.mkPen("#ffffff", width=1))
        self.cursor2 = pg.InfiniteLine(angle=90, movable=True, pen=pg.mkPen("#ffffff", width=1,
                                                                             style=Qt.PenStyle.DashLine))
        for c in (self.cursor1, self.cursor2):
            c.sigPositionChanged.connect(self.sigCursorsMoved)
        layout.addWidget(self.plot, 1)
        self.cursor_label = QLabel("")
        self.cursor_label.setObjectName("scopeCursorReadout")
        self.cursor_label.setWordWrap(True)
        layout.addWidget(self.cursor_label)
        self._curves: dict[str, pg.PlotDataItem] = {}
        self._cursors_on = False
        self._live = False
        self._x_offset = 0.0  # live: the time shown as 0 (now) [s]; still data: 0
        self._live_span: float | None = None
        self._y_range: tuple[float, float] | None = None
        self.autoscale = True

    @property
    def view_box(self) -> pg.ViewBox:
        return self.plot.plotItem.vb

    def show_grid_for_still_data(self, still: bool) -> None:
        """Still data: the axes' grid. Live: no x grid (it would scroll every frame) and the y grid
        as plain lines: an axis that draws a grid covers the plot and repaints its text with
        every frame of the curves."""
        self.plot.showGrid(x=still, y=still, alpha=0.25)
        self._grid_on = not still
        self._update_grid_lines()

    def _update_grid_lines(self, *_args) -> None:
        """Horizontal lines at the left axis' major ticks (live only)."""
        for line in self._grid_lines:
            self.plot.removeItem(line)
        self._grid_lines = []
        if not self._grid_on:
            return
        _, (y0, y1) = self.view_box.viewRange()
        levels = self.plot.getAxis("left").tickValues(y0, y1, max(50, self.view_box.height()))
        for value in (levels[0][1] if levels else []):
            line = pg.InfiniteLine(pos=value, angle=0, movable=False, pen=self._grid_pen)
            self.plot.addItem(line, ignoreBounds=True)
            self._grid_lines.append(line)

    # -- curves ------------------------------------------------------------------------------------
    def set_curves(self, channels: Sequence[ScopeChannel], visible: Mapping[str, bool],
                   scale: Mapping[str, float], color: Callable[[str], str], live: bool) -> None:
        """One curve per visible channel, named with its unit and scale; ``live`` switches the
        time axis to "before now" and the y range to ``autoscale`` with hysteresis."""
        if live != self._live:
            self._live = live
            self._x_offset, self._live_span, self._y_range = 0.0, None, None
            self.plot.setLabel("bottom", "time before now" if live else "time", units="s")
            self.view_box.enableAutoRange(axis="y", enable=self.autoscale and not live)
        for curve in self._curves.values():
            self.plot.removeItem(curve)
        self._curves.clear()
        for c in channels:
            if not visible.get(c.key, True):
                continue
            factor = scale.get(c.key, 1.0)
            label = f"{c.name} [{c.unit}]" + (f" ×{factor:g}" if factor != 1 else "")
            curve = self.plot.plot(pen=pg.mkPen(color(c.key), width=1), name=label)
            if live:  # already decimated and finite (MinMaxLevels)
                curve.setDownsampling(ds=1, auto=False)
                curve.setClipToView(False)
                curve.setSkipFiniteCheck(True)
            else:
                curve.setDownsampling(auto=True, method="peak")
                curve.setClipToView(True)
            self._curves[c.key] = curve

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
        lo, hi = np.inf, -np.inf
        for j, c in enumerate(channels):
            curve = self._curves.get(c.key)
            if curve is not None:
                factor = scale.get(c.key, 1.0)
                column = y[:, j] * factor if factor != 1 else y[:, j]
                curve.setData(t, column)
                if len(column):
                    lo, hi = min(lo, float(column.min())), max(hi, float(column.max()))
        span = t1_s - t0_s
        if span != self._live_span:
            self._live_span = span
            self.view_box.setXRange(-span, 0.0, padding=0)
        if self.autoscale and lo <= hi:
            self._follow_y(lo, hi)

    def _follow_y(self, lo: float, hi: float) -> None:
        """Move the y range only when the data leaves it or fills less than half of it."""
        current = self._y_range
        if current is not None:
            c_lo, c_hi = current
            if c_lo <= lo and hi <= c_hi and (hi - lo) >= 0.5 * (c_hi - c_lo):
                return
        pad = 0.1 * (hi - lo) if hi > lo else max(1.0, abs(hi) * 0.1)
        self._y_range = (lo - pad, hi + pad)
        self.view_box.setYRange(*self._y_range, padding=0)

    def draw_rows(self, channels: Sequence[ScopeChannel], rows: np.ndarray,
                  scale: Mapping[str, float]) -> None:
        """Draw still data, rows ``[t_s, values...]``."""
        for j, c in enumerate(channels):
            curve = self._curves.get(c.key)
            if curve is not None:
                curve.setData(rows[:, 0], rows[:, j + 1] * scale.get(c.key, 1.0))

    def fit(self, rows: np.ndarray | None, columns: Sequence[int], factors: Sequence[float],
            autoscale: bool) -> None:
        """Show all of ``rows`` (x from the data, y over ``columns`` x ``factors``), or the
        curves' own range when there are no rows."""
        vb = self.view_box
        if rows is not None and len(rows):
            t = rows[:, 0]
            vb.setXRange(float(t[0]), float(t[-1]), padding=0.02)  # from the data, not from clipped curves
            if columns:
                y = rows[:, list(columns)] * list(factors)
                lo, hi = float(np.nanmin(y)), float(np.nanmax(y))
                vb.setYRange(lo, hi if hi > lo else lo + 1.0, padding=0.05)
        else:
            vb.autoRange(padding=0.02)
        if autoscale and not self._live:
            vb.enableAutoRange(axis="y", enable=True)
        self._y_range = self._live_span = None  # live: the next frame shows the time base again

    def set_autoscale(self, on: bool) -> None:
        self.autoscale = bool(on)
        self._y_range = None
        self.view_box.enableAutoRange(axis="y", enable=self.autoscale and not self._live)

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
        for c in (self.cursor1, self.cursor2):
            if on:
                self.plot.addItem(c, ignoreBounds=True)
            else:
                self.plot.removeItem(c)
        if on:
            x0, x1 = self.x_range()
            self.set_cursors(x0 + 0.3 * (x1 - x0), x0 + 0.7 * (x1 - x0))

    def set_cursors(self, t1_s: float, t2_s: float) -> None:
        """Put the cursors at these times of the data (live: they then stay that long before now)."""
        self.cursor1.setValue(t1_s - self._x_offset)
        self.cursor2.setValue(t2_s - self._x_offset)

    def cursor_times(self) -> tuple[float, float]:
        """The cursors' times in the data's own time [s]."""
        return float(self.cursor1.value()) + self._x_offset, float(self.cursor2.value()) + self._x_offset

    def export_png(self, path) -> None:
        exporter = exporters.ImageExporter(self.plot.plotItem)
        exporter.parameters()["width"] = max(800, self.plot.width())
        exporter.export(str(path))
