"""A bench instrument's stream on the scope's Time plot beside the CN3 channels, each trace named
with its source: on the documented profile the sim-cn2 encoder counts in output degrees share the
plot of CN3's positions while the CN3 live view runs."""

from __future__ import annotations

import pytest

from fha_studio.gui.pages.base import PageId
from tests.gui.controller import bench_streaming

CODE = "FHA-25C-50-S248"  # absolute: CN3 gives the position (DGR) while the servo is off


@pytest.fixture
def window(documented_window):
    return documented_window(CODE)


def test_bench_traces_are_drawn_beside_cn3s_named_with_their_source(window, qtbot, tmp_path):
    page = window.show_page("scope")
    view, bench = page.view, page.bench
    view.start_live()
    qtbot.waitUntil(lambda: view.time_plot.live, timeout=10000)
    bench_streaming(qtbot, bench, "ENC_A,ENC_B,IN_POS,SPD_MON", "100k", "ENC_A,ENC_B")
    label = "bench sim-cn2: ENC_A/ENC_B position (output) [°]"  # degrees as the manual prints them
    plot = view.time_plot
    qtbot.waitUntil(lambda: label in plot._bench and plot._bench[label][0].getData()[0] is not None,
                    timeout=10000)
    curve, item = plot._bench[label]
    t, _y = curve.getData()
    assert len(t) > 10 and t[-1] == 0.0 and t[0] < 0  # time before now, as the live view draws
    units = {p.unit: p.item for p in plot._plots}
    assert item is units["deg"]
    assert next(p.keys for p in plot._plots if p.unit == "deg")  # CN3's position on the same plot
    assert {"bench sim-cn2: SPD_MON [V]", "bench sim-cn2: IN_POS [bit]"} <= set(plot._bench)
    # each legend entry in one piece: the legend wraps between entries, never inside a name (its
    # spaces, hyphens and slashes in their no-break forms)
    assert "V" in units and "bench&nbsp;sim\u2011cn2:&nbsp;SPD_MON&nbsp;[V]" in plot.legend.text()
    assert "&nbsp;ENC_A/\u2060ENC_B&nbsp;position&nbsp;(output)&nbsp;[°]" in plot.legend.text()
    # a plot of it saved for the report says where its bench traces came from
    procedures = window.page(PageId.PROCEDURES)
    procedures.new_session(tmp_path / "session.json", CODE, "T. Trainee")
    saved = procedures.capture_scope_plot()
    assert saved is not None and saved.is_file()
    assert procedures.session.plots[-1]["title"].startswith(
        "Scope plot 1 (with bench sim-cn2 at 100 kHz: sim-cn2:ENC_A, sim-cn2:ENC_B, sim-cn2:IN_POS")
    with qtbot.waitSignal(bench.source.sigStopped, timeout=10000):
        bench.start_button.click()
    view.stop_live()


def test_the_scopes_recording_takes_the_bench_stream_beside_its_cn3_channels(make_window, qtbot, tmp_path):
    from fha_studio.recording import read_recording

    code = "FHA-25C-50-US250"
    window = make_window(connect=f"sim://{code}?paced=0")  # every CN3 channel the recording needs
    window.state.set_actuator(code, acknowledged=True)
    page = window.show_page("scope")
    view, bench = page.view, page.bench
    view.start_live()
    qtbot.waitUntil(lambda: view.time_plot.live, timeout=10000)
    bench_streaming(qtbot, bench, "ENC_A,ENC_B,SPD_MON", "100k", "ENC_A,ENC_B")
    qtbot.waitUntil(lambda: len(bench.source.started.ring) > 100, timeout=10000)
    path = tmp_path / "live.csv"
    view.start_recording(path)
    qtbot.waitUntil(lambda: view._recorder is not None and view._recorder.rows_written > 20, timeout=20000)
    view.stop_recording()
    with qtbot.waitSignal(bench.source.sigStopped, timeout=10000):
        bench.start_button.click()
    view.stop_live()
    recording = read_recording(path)
    channels = recording.channels
    assert {"pos", "current", "bench_enc_a", "bench_enc_b", "bench_spd_mon", "bench_pos"} <= set(channels)
    extra = recording.metadata.extra
    assert extra["source_bench_pos"] == ("bench sim-cn2: ENC_A/ENC_B counts x 360 / 500000 counts per "
                                         "output turn [deg]")
    assert extra["source_bench_spd_mon"].startswith("bench sim-cn2: SPD_MON (V,")
    assert set(channels["bench_enc_a"]) <= {0.0, 1.0}
