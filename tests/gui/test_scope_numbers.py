"""What the scope writes as numbers reads as a person reads them: a cursor's current near zero is
"0.00007933 A", not "7.933e-05 A"; a spectrum's lines of an angle are in arc-sec, as the manual
gives the actuator's accuracy, with the plot's amplitude axis named."""

from __future__ import annotations

import re

import numpy as np
from PySide6.QtGui import QImage, QPainter

from fha_studio.gui.pages.scope.cursor_table import CursorRow, CursorTable
from fha_studio.gui.pages.scope.spectrum_panel import SpectrumPanel
from fha_studio.logic.scope.analysis import spectrum
from fha_studio.logic.wording import fixed_number, fixed_words, plain_number, unit_words


def test_plain_numbers_never_use_exponent_notation():
    assert plain_number(7.933e-05, 4) == "0.00007933"
    assert plain_number(-7.41e-05, 3) == "-0.0000741"
    assert plain_number(1.2e6, 4) == "1200000"
    assert plain_number(-0.28355, 5) == "-0.28355"
    assert plain_number(0.0) == "0"


def test_degrees_read_as_the_manual_prints_them_and_files_keep_ascii():
    assert unit_words("deg") == "°" and unit_words("deg/s") == "°/s" and unit_words("r/min/s") == "r/min/s"
    assert fixed_words(90.0, "deg") == "90.0000°" and fixed_words(2.5, "deg/s") == "2.5000 °/s"
    assert fixed_number(90.0, "deg") == "90.0000 deg"  # for a file or a terminal


def test_the_cursor_table_writes_a_small_current_in_plain_figures(qtbot):
    """Fixed decimals per unit: no exponent, no "-0.000" for a current below the monitor's 1 mA."""
    table = CursorTable()
    qtbot.addWidget(table)
    table.show_rows(-6.0, -3.5, [CursorRow("Motor current", "A", "#9467bd", -7.933e-05, -0.28355, -0.11345)])
    cells = [table.cell_text(1, column) for column in range(1, 5)]
    assert cells == ["0.000 A", "-0.284 A", "-0.283 A", "-0.113 A/s"]
    assert [table.cell_text(0, column) for column in range(1, 5)] == [
        "-6.0000 s", "-3.5000 s", "2500.0 ms", "1/Δt = 0.40 Hz"]


def test_the_cursor_table_gives_each_unit_its_own_fixed_digits(qtbot):
    """A speed reads "0.32 r/min" (not "0.32499 r/min") and "12.00 r/min": a column's digits line up."""
    table = CursorTable()
    qtbot.addWidget(table)
    table.show_rows(0.0, 0.5, [
        CursorRow("Output speed", "r/min", "#1f77b4", 0.32499, 12.0, 23.35002),
        CursorRow("Output position", "deg", "#ff7f0e", 1.0 / 3.0, 90.0, 179.33333),
        CursorRow("Position error", "pulse", "#2ca02c", 3.0, -12.0, -30.0),
        CursorRow("Output torque", "N·m", "#d62728", 0.123456, 7.0, 13.753088),
    ])
    got = {table.cell_text(r, 0): [table.cell_text(r, c) for c in range(1, 5)] for r in range(1, 5)}
    assert got == {
        "Output speed": ["0.32 r/min", "12.00 r/min", "11.68 r/min", "23.35 r/min/s"],
        "Output position": ["0.3333°", "90.0000°", "89.6667°", "179.3333 °/s"],
        "Position error": ["3 pulse", "-12 pulse", "-15 pulse", "-30 pulse/s"],
        "Output torque": ["0.12 N·m", "7.00 N·m", "6.88 N·m", "13.75 N·m/s"],
    }
    assert fixed_number(0.5, "furlong") == "0.5 furlong"  # a unit without its decimals: 4 digits


def test_a_spectrum_of_an_angle_names_its_lines_in_arc_sec(qtbot):
    panel = SpectrumPanel()
    qtbot.addWidget(panel)
    panel.resize(600, 400)
    panel.show()
    qtbot.waitExposed(panel)
    t = np.arange(2048) / 1000.0
    line_deg = 40.0 / 3600.0  # a kinematic error of 40 arc-sec at 16.6 Hz
    angle = 120.0 + 10.0 * t + line_deg * np.sin(2 * np.pi * 16.6 * t) + 1e-5 * np.sin(2 * np.pi * 233.4 * t)
    panel.show_spectrum(spectrum(t, angle), "deg")
    text = panel.spectrum_label.text()
    assert text.startswith("Peaks: ") and "deg" not in text and "e-0" not in text
    lines = {hz: amplitude.rstrip(")") for hz, amplitude in
             (part.split(" Hz (") for part in text[len("Peaks: "):].split(". Resolution")[0].split(", "))}
    assert set(lines) == {"16.60", "233.40"}
    assert lines["16.60"].endswith(" arc-sec") and 30.0 < float(lines["16.60"].split()[0]) < 41.0
    assert lines["233.40"] == "0.036 arc-sec"  # 1e-5 deg, not 1e-05 deg
    axis = panel.spectrum_plot.getPlotItem().getAxis("left")  # the plot in arc-sec too, no SI scale
    assert axis.labelText == "amplitude (arc-sec)" and "(x" not in axis.labelString()
    assert 30.0 < 10 ** max(panel.spectrum_curve.getData()[1]) < 41.0  # as drawn: its log10
    # the decades in plain numbers, all alike: "10" beside "1" and "0.1", never "10¹" or "10⁻⁴"
    def labels() -> list[str]:
        image = QImage(10, 10, QImage.Format.Format_RGB32)
        painter = QPainter(image)
        try:
            return [text for _rect, _flags, text in axis.generateDrawSpecs(painter)[2]]
        finally:
            painter.end()

    # which decades are drawn follows the plot's height (the layout's, not this test's): the
    # words for given decades are checked as such, then every drawn one is a plain number
    decades = np.log10([0.001, 0.1, 1.0, 2.0, 3.0, 10.0, 50.0, 1e5])
    assert axis.logTickStrings(decades, 1.0, 1.0) == ["0.001", "0.1", "1", "2", "", "10", "50", "100000"]
    qtbot.waitUntil(lambda: len(labels()) >= 2, timeout=5000)  # the view took the curve's range
    shown = labels()
    assert all(re.fullmatch(r"\d+(\.\d+)?", text) for text in shown), shown
