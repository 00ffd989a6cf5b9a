"""The Bench tab on a small screen, as a logic analyzer lays it out: eleven CN2 channels of the
simulated drive (the encoder outputs, the command pulses, IN-POS, ALARM, ALM-A ... D and SPD-MON)
with a move on hold. At 1366 x 740 (a 1366 x 768 screen), 1280 x 720 and 1024 x 600 no text is
cut, every logic lane keeps its height with its name whole beside it (no two names overlap),
and SPD-MON's and the counts' plots keep a readable height (what does not fit scrolls)."""

from __future__ import annotations

import itertools

from PySide6.QtCore import QPointF

from fha_studio.gui.pages.scope.bench_panel import LANE_PX, TRACE_VIEW_MIN_PX
from tests.gui.controller import bench_streaming, panel_done
from tests.gui.fit import laid_out

CODE = "FHA-25C-50-US250"
CHANNELS = "ENC_A,ENC_B,CMD_A,CMD_B,IN_POS,ALARM,ALM_A,ALM_B,ALM_C,ALM_D,SPD_MON"


def lane_problems(bench) -> list[str]:
    """Lanes lower than LANE_PX, names that overlap or stand outside their plot, traces of SPD-MON
    or of the counts drawn lower than TRACE_VIEW_MIN_PX."""
    found = []
    view = bench.plot.getViewBox()
    ticks = sorted(bench.plot.getAxis("right")._tickLevels[0], reverse=True)  # the top lane first
    centres = [(view.mapViewToScene(QPointF(0.0, y)).y(), name) for y, name in ticks]
    text_px = bench.lane_metrics.height()
    top, bottom = view.sceneBoundingRect().top(), view.sceneBoundingRect().bottom()
    for (y0, name0), (y1, name1) in itertools.pairwise(centres):
        if y1 - y0 < LANE_PX:
            found.append(f"lane {name1}: {y1 - y0:.1f} px below {name0}, not {LANE_PX}")
        if y1 - y0 < text_px:
            found.append(f"lane names {name0} and {name1} overlap ({y1 - y0:.1f} px apart, {text_px} high)")
    for y, name in centres:
        if y - text_px / 2 < top - 1 or y + text_px / 2 > bottom + 1:
            found.append(f"{name} outside its plot ({y:.0f} px; the plot {top:.0f} ... {bottom:.0f})")
    for plot, name in ((bench.analog_plot, bench.analog_names), (bench.counts_plot, bench.counts_name)):
        traces = plot.getViewBox().sceneBoundingRect().height()
        if traces < TRACE_VIEW_MIN_PX:
            found.append(f"{name}: its traces {traces:.0f} px high")
    return found


def test_the_bench_lanes_and_plots_fit_small_screens(documented_window, qtbot):
    from tests.gui.fit import cut_hints, cut_texts, hidden_actions

    window = documented_window(CODE)
    scope = window.show_page("scope")
    bench = scope.bench
    scope.view.plots.setCurrentWidget(bench)
    bench_streaming(qtbot, bench, CHANNELS, "250k", "ENC_A,ENC_B", "CMD_A,CMD_B", "IN_POS", "ALARM",
                    ("ALM_A", "ALM_B", "ALM_C", "ALM_D"))
    panel_done(window, qtbot, lambda: window.sim_panel.servo_check.setChecked(True))
    qtbot.waitUntil(lambda: window.link.status is not None and window.link.status.servo_on, timeout=10000)
    window.sim_panel.command_spin.setValue(10.0)
    panel_done(window, qtbot, window.sim_panel.fwd_button.click)
    # the worst case: the move on hold (its bar), its figures' lines and the alarm line shown
    qtbot.waitUntil(lambda: bench.move_figures is not None and bench.alarm_label.isVisible(), timeout=30000)
    assert not bench.hold_bar.isHidden()
    problems = []
    for size in ((1366, 740), (1280, 720), (1024, 600)):
        window.resize(*size)
        qtbot.waitUntil(lambda size=size: (window.width(), window.height()) == size, timeout=10000)
        laid_out(qtbot, window)
        found = hidden_actions(window) + cut_texts(window) + cut_hints(window) + lane_problems(bench)
        problems += [f"{size[0]}x{size[1]}: {p}" for p in found]
    assert not problems, "\n".join(problems)
    with qtbot.waitSignal(bench.source.sigStopped, timeout=10000):
        bench.start_button.click()


