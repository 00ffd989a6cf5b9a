"""What the scope writes as numbers reads as a person reads them: a cursor's current near zero is
"0.00007933 A", not "7.933e-05 A"; a spectrum's lines of an angle are in arc-sec, as the manual
gives the actuator's accuracy, with the plot's amplitude axis named."""

from __future__ import annotations

import numpy as np

from fha_studio.gui.pages.scope.cursor_table import CursorRow, CursorTable
from fha_studio.gui.pages.scope.spectrum_panel import SpectrumPanel
from fha_studio.logic.scope.analysis import spectrum
from fha_studio.logic.wording import plain_number


def test_plain_numbers_never_use_exponent_notation():
    assert plain_number(7.933e-05, 4) == "0.00007933"
    assert plain_number(-7.41e-05, 3) == "-0.0000741"
    assert plain_number(1.2e6, 4) == "1200000"
    assert plain_number(-0.28355, 5) == "-0.28355"
    assert plain_number(0.0) == "0"


def test_the_cursor_table_writes_a_small_current_in_plain_figures(qtbot):
    table = CursorTable()
    qtbot.addWidget(table)
    table.show_rows(-6.0, -3.5, [CursorRow("Motor current", "A", "#9467bd", 7.933e-05, -0.28355, -0.11345)])
    cells = [table.cell_text(1, column) for column in range(1, 5)]
    assert cells == ["0.00007933 A", "-0.28355 A", "-0.28363 A", "-0.11345 A/s"]
    assert table.cell_text(0, 1) == "-6 s"


def test_a_spectrum_of_an_angle_names_its_lines_in_arc_sec(qtbot):
    panel = SpectrumPanel()
    qtbot.addWidget(panel)
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
    assert panel.spectrum_plot.getPlotItem().getAxis("left").labelText == "amplitude (deg)"
