"""The scope's bench source on the documented profile, where CN3 answers only DGR and is silent
(``s``) while the servo is on: the simulated controller (the sim panel: servo-ON and a command
pulse train on CN2) moves the axis, the running drive's CN2 streams live as the ``sim-cn2``
instrument, and the move test's figures come from that capture (overshoot, settling, the
in-position time from IN-POS, following error = command counts - encoder counts)."""

from __future__ import annotations

import numpy as np
import pytest

from fha_studio.hardware.sim import cn2_live
from tests.gui.controller import bench_standing, bench_streaming, documented_url, panel_done

CODE = "FHA-25C-50-US250"
URL = documented_url(CODE)
COUNTS_PER_OUTPUT_TURN = 500000  # 10000 counts per motor turn (x4) x 50


@pytest.fixture
def window(documented_window):
    return documented_window(CODE)


def test_a_controller_move_is_shown_live_from_cn2_with_the_move_tests_figures(window, qtbot):
    drive = window.link._worker._client.transaction.transport.inner.sim_drive
    assert window.link.info.documented_only and window.sim_panel.isVisible()
    bench = window.show_page("scope").bench
    with qtbot.waitSignal(bench.sigDevicesListed, timeout=20000):
        bench.scan()
    assert bench.device_box.itemText(0) == f"sim-cn2  (FHA Studio simulated drive {CODE} (CN2))"
    assert bench.counts_per_output_turn == COUNTS_PER_OUTPUT_TURN
    with qtbot.waitSignal(bench.source.sigStarted, timeout=10000):
        bench.start(bench.device_box.itemText(0), "ENC_A,ENC_B,CMD_A,CMD_B,IN_POS,SPD_MON", "250k",
                    "ENC_A,ENC_B", "CMD_A,CMD_B", "IN_POS")
    started = bench.source.started
    assert started.labels[:2] == ("sim-cn2:ENC_A", "sim-cn2:ENC_B")
    assert started.labels[-2:] == ("sim-cn2:ENC_A/ENC_B counts", "sim-cn2:CMD_A/CMD_B command counts")
    assert started.logic == ("ENC_A", "ENC_B", "CMD_A", "CMD_B", "IN_POS")
    assert bench.status_label.text().startswith("LIVE from the bench: sim-cn2 at 250 kHz")

    panel_done(window, qtbot, lambda: window.sim_panel.servo_check.setChecked(True))
    qtbot.waitUntil(lambda: window.link.status is not None and window.link.status.servo_on, timeout=10000)
    bench_standing(qtbot, bench)  # standing under servo: what the move starts from
    with drive.lock:
        before = drive.axis.feedback_pulses
    window.sim_panel.command_spin.setValue(10.0)
    panel_done(window, qtbot, window.sim_panel.fwd_button.click)
    qtbot.waitUntil(lambda: bench.move_figures is not None, timeout=30000)
    with drive.lock:
        after = drive.axis.feedback_pulses
        commanded = drive.axis.command_pulses

    figures = bench.move_figures
    m = figures.metrics
    step_counts = round(10.0 / 360.0 * COUNTS_PER_OUTPUT_TURN)
    assert m.target - m.start == pytest.approx(step_counts * 360.0 / COUNTS_PER_OUTPUT_TURN, abs=1e-9)
    # the bench's encoder counts are the drive's own feedback over the move
    assert abs((m.target - m.start - m.final_error) * COUNTS_PER_OUTPUT_TURN / 360.0
               - (after - before)) <= 1.5
    assert commanded == step_counts  # the controller's pulses, as the drive counted them
    assert figures.in_position_time_s is not None and figures.in_position_time_s < 0.5
    assert m.settling_time_s is not None and m.overshoot_percent >= 0.0
    assert figures.following_error_peak_counts > 10  # the error counter fills while the axis runs
    assert abs(figures.following_error_end_counts) <= 10  # within the in-position range (tune 4)
    text = bench.move_label.text()
    for words in ("Move from the bench: +10.000°", "overshoot", "settling time", "in-position (IN-POS)",
                  "following error (command − encoder)", "at the end"):
        assert words in text, text
    assert f"overshoot {m.overshoot_percent:.2f}\u00a0%" in text  # its unit kept on its line
    # counted as a sentence counts: "1 count", "11 channels", never "1 counts" or "channel(s)"
    assert " 1 counts" not in text and "(s)" not in bench.status_label.text()
    x, y = bench._curves[0].getData()
    assert x is not None and len(x) > 1000 and set(np.unique(np.round(y % 1.2, 3))) <= {0.0, 0.8}
    # the logic lanes named at the right beside each, the analog channel at its own plot's right
    lanes = [name for _, name in bench.plot.getAxis("right")._tickLevels[0]]
    assert lanes[0] == "bench sim-cn2:ENC_A" and lanes[-1] == "bench sim-cn2:IN_POS" and len(lanes) == 5
    analog = [name for _, name in bench.analog_plot.getAxis("right")._tickLevels[0]]
    assert analog == ["bench sim-cn2:SPD_MON"]
    with qtbot.waitSignal(bench.source.sigStopped, timeout=10000):
        bench.start_button.click()


def test_the_analysed_move_stays_on_the_plots_while_the_stream_goes_on(window, qtbot):
    """The figures describe a move the technician can see: the plots hold it (the live window
    shows only the newest 2 s) until Back to live, and the stream is received meanwhile."""
    from fha_studio.gui.pages.scope.bench_panel import STEP_S, WINDOW_S

    bench = window.show_page("scope").bench
    bench_streaming(qtbot, bench, "ENC_A,ENC_B,CMD_A,CMD_B,IN_POS", "250k", "ENC_A,ENC_B", "CMD_A,CMD_B",
                    "IN_POS")
    assert bench.hold_bar.isHidden()
    panel_done(window, qtbot, lambda: window.sim_panel.servo_check.setChecked(True))
    qtbot.waitUntil(lambda: window.link.status is not None and window.link.status.servo_on, timeout=10000)
    window.sim_panel.command_spin.setValue(10.0)
    panel_done(window, qtbot, window.sim_panel.fwd_button.click)
    qtbot.waitUntil(lambda: bench.move_figures is not None, timeout=30000)
    assert "Showing the move at " in bench.showing_label.text() and not bench.hold_bar.isHidden()
    ring = bench.source.started.ring
    shown_until = float(bench._counts_curve.getData()[0][-1])
    # the stream goes on past the live window: a live view would show none of the move now
    qtbot.waitUntil(lambda: float(ring.window(1)[0, 0]) > shown_until + WINDOW_S + STEP_S, timeout=20000)
    t, counts = bench._counts_curve.getData()
    step_counts = round(10.0 / 360.0 * COUNTS_PER_OUTPUT_TURN)
    # from standing before the command to standing in position after it: within the in-position
    # range (tune 4: 10 counts) of the move's counts
    assert abs((counts[-1] - counts[0]) - step_counts) <= 10
    assert float(t[-1]) == shown_until  # still the move, not the newest rows
    low, high = bench.plot.getViewBox().viewRange()[0]
    assert low <= float(t[0]) and float(t[-1]) <= high
    # back to the newest seconds: the rows received while the move was on show are there
    bench.back_button.click()
    assert bench.hold_bar.isHidden()
    qtbot.waitUntil(lambda: float(bench._counts_curve.getData()[0][-1]) > shown_until + WINDOW_S,
                    timeout=10000)
    with qtbot.waitSignal(bench.source.sigStopped, timeout=10000):
        bench.start_button.click()


def test_the_instrument_goes_when_its_drive_does(make_window, qtbot):
    window = make_window(connect=URL)
    assert [d.spec for d in cn2_live.devices()] == ["sim-cn2"]
    with qtbot.waitSignal(window.link.sigDisconnected, timeout=10000):
        window.disconnect_drive()
    assert cn2_live.devices() == []
