"""The bench source of the scope on sigrok-cli's demo driver: rows through the ring, drained by
the GUI timer, labelled with their source; stop, an instrument that vanishes, a refusal."""

from __future__ import annotations

import os
import shutil
import signal

import numpy as np
import pytest

from fha_studio.gui.pages.scope.bench_source import BenchSettings, BenchSource, rows_as_columns
from fha_studio.logic.bench.display import CHANGED

pytestmark = pytest.mark.skipif(shutil.which("sigrok-cli") is None, reason="sigrok-cli is not installed")


@pytest.fixture
def source(qtbot):
    made = BenchSource()
    yield made
    made.shutdown()


def _rows_until(qtbot, source, count):
    got = []
    source.sigRows.connect(got.append)
    qtbot.waitUntil(lambda: sum(len(r) for r in got) >= count, timeout=10000)
    return got


def test_a_stream_comes_through_the_ring_at_the_display_rate_and_stops_cleanly(qtbot, source):
    with qtbot.waitSignal(source.sigStarted, timeout=10000) as started:
        source.start(BenchSettings("demo", ("D1", "D4"), 2e6))
    info = source.started
    assert info is not None and started.args[0] is info
    assert info.labels == ("demo:D1", "demo:D4") and info.sample_rate_hz == 2e6 and info.row_rate_hz == 1e4
    got = _rows_until(qtbot, source, 2000)
    with qtbot.waitSignal(source.sigStopped, timeout=10000) as stopped:
        source.stop()
    assert stopped.args == [""] and not source.running
    rows = np.concatenate(got)
    assert np.allclose(np.diff(rows[:, 0]), 1e-4)  # no row lost or doubled between drains
    columns = rows_as_columns(info, rows)
    # high or low all through a window, or both within it (the demo's lines change within one)
    assert set(np.unique(columns["demo:D1"])) <= {0.0, CHANGED, 1.0}
    assert source.status is not None and source.status.dropped == 0


def test_an_instrument_that_vanishes_is_said_and_what_came_stays(qtbot, source):
    with qtbot.waitSignal(source.sigStarted, timeout=10000):
        source.start(BenchSettings("demo", ("D0",), 1e6))
    got = _rows_until(qtbot, source, 1000)
    acquisition = source.worker._acquisition
    assert acquisition is not None and acquisition._process is not None
    with qtbot.waitSignal(source.sigStopped, timeout=10000) as stopped:
        os.kill(acquisition._process.pid, signal.SIGKILL)
    assert "demo: the instrument stopped sending" in stopped.args[0]
    assert sum(len(r) for r in got) >= 1000 and source.started is not None
    assert len(source.started.ring) >= 1000  # the ring still holds what came


def test_encoder_counts_come_as_a_last_column_equal_to_decoding_the_whole_stream(qtbot, source):
    from fha_studio.logic.bench.decode import quadrature

    with qtbot.waitSignal(source.sigStarted, timeout=10000):
        source.start(BenchSettings("demo", ("D0", "D1"), 10e3, encoder=("D0", "D1")))
    info = source.started
    assert info is not None and info.labels[-1] == "demo:D0/D1 counts"
    got = _rows_until(qtbot, source, 3000)
    with qtbot.waitSignal(source.sigStopped, timeout=10000):
        source.stop()
    rows = np.concatenate(got)  # 10 kHz: one row a sample, so the levels are the stream's own
    expected = quadrature(rows[:, 1] > 0.5, rows[:, 2] > 0.5).counts
    assert np.array_equal(rows[:, 3] - rows[0, 3], expected) and np.count_nonzero(np.diff(expected))


def test_a_channel_the_instrument_lacks_is_refused_in_one_line(qtbot, source):
    with qtbot.waitSignal(source.sigStopped, timeout=10000) as stopped:
        source.start(BenchSettings("demo", ("D9",), 1e6))
    assert stopped.args[0].startswith("demo: no channel D9") and "\n" not in stopped.args[0]
    assert source.started is None and not source.running


def test_the_scope_page_bench_tab_finds_the_demo_and_plots_it_beside_cn3(qtbot):
    from fha_studio.gui.pages.scope.bench_panel import BenchPanel

    panel = BenchPanel()
    qtbot.addWidget(panel)
    try:
        with qtbot.waitSignal(panel.sigDevicesListed, timeout=10000):
            panel.scan()
        assert panel.device_box.itemText(0).startswith("demo  (Demo device)")
        with qtbot.waitSignal(panel.source.sigStarted, timeout=10000):
            panel.start(panel.device_box.itemText(0), "D0, D2", "1m", "D0,D2")
        def plotted() -> int:
            x, _y = panel._curves[0].getData()
            return 0 if x is None else len(x)

        qtbot.waitUntil(lambda: plotted() > 100, timeout=10000)
        lanes = [name for _, name in panel.plot.getAxis("right")._tickLevels[0]]
        assert lanes == ["bench demo:D0", "bench demo:D2"]  # each logic lane named beside it
        assert panel.status_label.toolTip() == "demo:D0, demo:D2, demo:D0/D2 counts"
        assert panel.counts_plot.isVisibleTo(panel)  # the demo's D0/D2 counted as an encoder
        assert panel.counts_plot.plotItem.getAxis("left").labelText == "bench demo:D0/D2 counts"
        assert panel.status_label.text().startswith("LIVE from the bench: demo at 1 MHz")
        with qtbot.waitSignal(panel.source.sigStopped, timeout=10000):
            panel.start_button.click()
        assert not panel.start_button.isChecked() and panel.status_label.text().startswith("Stopped after")
        panel.rate_edit.setText("fast")
        panel.start_button.click()
        assert panel.status_label.text() == "Sample rate 'fast': a number of Hz, e.g. 200k or 1m."
    finally:
        panel.shutdown()
