"""The scope against the embedded simulated drive (and a drive of the manual's command set).

The driver runs in its own thread with the client, as it would in the link worker's thread;
the test talks to the drive only through the driver (CALL), never from the GUI thread.
"""

from __future__ import annotations

import itertools
import threading
import time

import numpy as np
import pytest
from PySide6.QtCore import Qt, QTimer

from fha_studio.gui.link import Call, MoveBy, Servo, SetMoveSpeed, Stop
from fha_studio.gui.pages.scope.driver import ScopeCmd, ScopeController
from fha_studio.gui.pages.scope.view import ScopeContext, ScopeView
from fha_studio.hardware import protocol as p
from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.transport import pipe_pair
from fha_studio.recording import read_recording
from tests.support.documented import DocumentedDrive
from tests.support.scripted import ScriptedDrive

ACTUATOR = "FHA-25C-50-US250"
SIM_URL = f"sim://{ACTUATOR}?paced=0"


@pytest.fixture
def scope(qtbot):
    """Factory: scope(client) -> ScopeView with its driver in a thread, holding ``client``."""
    made = []

    def make(client, ratio=50):
        controller = ScopeController()
        view = ScopeView(controller, ScopeContext(ACTUATOR, load_inertia_kgm2=0.5))
        qtbot.addWidget(view)
        view.resize(1200, 700)
        controller.attach(client, ratio)
        made.append((view, controller, client))
        return view

    yield make
    for view, controller, client in made:
        view.shutdown()
        assert controller.shutdown()
        client.close()


@pytest.fixture
def sim_client():
    return DriveClient.open(SIM_URL)


def call(view, function):
    """Run ``function(client)`` in the driver's thread (as the link worker would)."""
    view.controller.send(ScopeCmd.CALL, function)


def latest(view, key):
    live = view._live
    j = [c.key for c in live.channels].index(key) + 1
    return live.ring.window()[:, j]


def test_jog_shows_position_speed_and_current_live(qtbot, scope, sim_client):
    view = scope(sim_client)
    view.start_live()
    qtbot.waitUntil(lambda: view.indicator_text() == "LIVE", timeout=10000)
    call(view, lambda c: c.servo(True))
    jog = QTimer()
    jog.timeout.connect(lambda: call(view, lambda c: c.jog(20.0)))  # the button held: JOG every 40 ms
    jog.start(40)
    try:
        qtbot.waitUntil(lambda: abs(latest(view, "output_speed")[-1] - 20.0) < 0.5, timeout=10000)
    finally:
        jog.stop()
    position = latest(view, "feedback_position")
    assert position[-1] - position[0] > 1.0  # deg: the axis turned and the view saw it
    assert np.abs(latest(view, "motor_current")).max() > 0.01  # A: accelerating takes current
    assert view.frames > 0 and view._status.rate_hz > 50  # unpaced sim: far above the real line
    view.set_paused(True)
    assert view.indicator_text().startswith("PAUSED")
    view.set_paused(False)
    call(view, lambda c: c.servo(False))


def _left_tick_labels(plot_item):
    """The left axis' drawn tick labels (text, rectangle in the scene)."""
    from PySide6.QtGui import QImage, QPainter

    axis = plot_item.getAxis("left")
    image = QImage(10, 10, QImage.Format.Format_RGB32)
    painter = QPainter(image)
    try:
        _axis, _ticks, texts = axis.generateDrawSpecs(painter)
    finally:
        painter.end()
    return [(text, axis.mapRectToScene(rect)) for rect, _flags, text in texts]


@pytest.mark.parametrize("live", [False, True])
def test_the_stacked_plots_tick_labels_do_not_overlap(qtbot, scope, sim_client, live):
    """One plot per unit, stacked: a plot's top tick label never sits on the one above's bottom
    label; empty plots have no tick labels (they read "1.0" over "0" where they met)."""
    view = scope(sim_client)
    view.show()
    qtbot.waitExposed(view)
    if live:
        view.start_live()
        for _ in range(3):
            with qtbot.waitSignal(view.sigFrame, timeout=10000):
                pass
    items = view.time_plot.plot_items()
    assert len(items) >= 3
    labels = [_left_tick_labels(item) for item in items]
    if not live:  # no sample yet: no numbers on the value axes, so none to clash
        assert not any(labels), labels
        return
    assert all(labels)
    for above, below in itertools.pairwise(labels):
        clashes = [(a, b) for a, ra in above for b, rb in below if ra.intersects(rb)]
        assert not clashes, clashes


def test_a_live_plot_on_paper_says_which_now_its_time_axis_counts_back_from(
        qtbot, scope, sim_client, fixed_clock, monkeypatch, tmp_path):
    """A report's scope plot of the live view: "time before now" is read long after that now, so
    the picture names it (the clock time of the newest drawing); the page keeps "time before now"."""
    from pyqtgraph import exporters

    from fha_studio import clock

    view = scope(sim_client)
    view.start_live()
    with qtbot.waitSignal(view.sigFrame, timeout=10000):
        pass
    drawn_at = f"{clock.now_local():%H:%M:%S}"
    fixed_clock.advance(3600.0)  # the report written an hour later
    axis = view.time_plot._plots[-1].item.getAxis("bottom")
    real_export = exporters.ImageExporter.export
    on_paper = []

    def export(exporter, *args, **kwargs):
        on_paper.append(axis.labelText)
        return real_export(exporter, *args, **kwargs)

    monkeypatch.setattr(exporters.ImageExporter, "export", export)
    view.set_paused(True)  # as the report script does: the picture is what the page showed
    view.export_png(tmp_path / "live.png")
    assert on_paper == [f"time before {drawn_at}"]
    assert axis.labelText == "time before now"


@pytest.mark.parametrize("packed", [True, False])
def test_a_trace_read_out_shows_its_progress_and_time_left(qtbot, scope, packed):
    """On a paced line a read-out takes seconds: the view shows how far it is and how long is
    left, from a drive with packed blocks (TRP) and from one with text blocks only (TRB)."""
    view = scope(DriveClient.open(f"sim://{ACTUATOR}?packed_trace={int(packed)}"))
    view.trigger_kind.setCurrentIndex(view.trigger_kind.findData(p.TriggerKind.IMMEDIATE))
    view.trace_samples.setValue(512 if packed else 256)
    view.trace_pre.setValue(0)
    bar = view.readout_progress
    seen = []  # (done, total, seconds left, the bar's text, shown) after the view took each report

    def after_view(done, total, left):  # connected after the view's slot: sees what it made of it
        seen.append((done, total, left, bar.text(), not bar.isHidden()))

    view.controller.sigReadoutProgress.connect(after_view)
    with qtbot.waitSignal(view.sigTraceDone, timeout=30000) as done:
        view.arm_trace()
    total = 512 if packed else 256
    assert len(done.args[0].t_s) == total
    assert [d for d, *_ in seen] == list(range(0, total + 1, 64)) and seen[-1][2] == 0.0
    during = [(text, shown) for d, _t, _l, text, shown in seen if 0 < d < total]
    assert during and all(shown for _text, shown in during)
    assert all(text.startswith("Reading out the capture: ") and f" of {total} samples, about " in text
               and text.endswith(" s left") for text, _shown in during)
    assert view.readout_progress.isHidden()


def test_a_stuck_link_is_not_shown_as_live(qtbot, scope, sim_client):
    view = scope(sim_client)
    view.start_live()
    qtbot.waitUntil(lambda: view.indicator_text() == "LIVE", timeout=10000)
    release = threading.Event()
    call(view, lambda c: release.wait(5))  # the link thread is busy: no samples come
    try:
        qtbot.waitUntil(lambda: view.indicator_text().startswith("NOT LIVE: no new sample"), timeout=10000)
    finally:
        release.set()
    qtbot.waitUntil(lambda: view.indicator_text() == "LIVE", timeout=10000)


def test_triggered_move_is_captured_saved_and_loads_everywhere(qtbot, scope, sim_client, tmp_path):
    view = scope(sim_client)
    call(view, lambda c: (c.servo(True), c.set_move_speed(30.0)))
    view.trigger_kind.setCurrentIndex(view.trigger_kind.findData(p.TriggerKind.IO_BIT_RISES))
    view.trigger_channel.setCurrentIndex(view.trigger_channel.findData("moving"))
    view.trace_samples.setValue(1024)
    view.trace_rate.setValue(1000)
    view.trace_pre.setValue(10)
    view.arm_trace()
    qtbot.waitUntil(lambda: "waiting for the trigger" in view.trace_state.text(), timeout=10000)
    with qtbot.waitSignal(view.sigTraceDone, timeout=15000) as done:
        call(view, lambda c: c.move_by(20.0))
    result = done.args[0]
    assert len(result.t_s) == 1024 and result.t_s[102] == 0.0
    cmd = result.column("command_position")
    assert np.ptp(cmd[:100]) == 0  # still before the trigger
    assert cmd[-1] - cmd[0] == pytest.approx(20.0, abs=0.01)
    assert view.indicator_text().startswith("NOT LIVE: showing trace")
    path = view.save_capture(tmp_path / "move.csv")
    recording = read_recording(path)
    assert recording.metadata.sample_rate_hz == pytest.approx(1000)
    assert recording.pos_deg[-1] - recording.pos_deg[0] == pytest.approx(20.0, abs=0.05)
    assert recording.cmd_pos_deg is not None and recording.vel_rpm is not None
    plain = np.genfromtxt(path, delimiter=",", comments="#")[1:]
    assert plain.shape == (1024, 5) and not np.isnan(plain).any()
    # the spectrum of a captured channel, and the file opened back into the scope
    view.spectrum_channel.setCurrentIndex(view.spectrum_channel.findData("output_speed"))
    view.compute_spectrum()
    assert view.spectrum_label.text().startswith("Peaks:")
    view.open_recording(path)
    assert view.indicator_text() == "NOT LIVE: showing file move.csv"
    view.set_cursors(0.0, 0.5)
    readout = view.cursor_readout()
    assert readout["command_position"][0] == pytest.approx(0.5)
    assert view.export_png(tmp_path / "view.png").stat().st_size > 1000
    _the_png_has_the_legend_above_the_plots(view, tmp_path / "view.png")
    csv = np.loadtxt(view.export_csv(tmp_path / "view.csv"), delimiter=",", skiprows=1)
    assert csv.shape == (1024, 5)
    # a person reads degrees as the manual prints them (°); the files keep their ASCII units
    assert "command_position [deg]" in (tmp_path / "view.csv").read_text("utf-8").splitlines()[0]
    assert "°" not in path.read_text("utf-8")
    position_plot = view.time_plot.plot_of("command_position")
    assert position_plot is not None and position_plot.getAxis("left").labelText == "°"
    units = {view.channel_table.item(row, 0).text(): view.channel_table.item(row, 1).text()
             for row in range(view.channel_table.rowCount())}
    assert "deg" not in units.values() and "°" in units.values()


def _the_png_has_the_legend_above_the_plots(view, png) -> None:
    """The exported picture (the report's scope plot, the PNG… button) says which curve is which
    channel: the legend's lines in the channels' colours above the plots."""
    from pyqtgraph import exporters
    from PySide6.QtGui import QColor, QImage

    image = QImage(str(png))
    plots = exporters.ImageExporter(view.time_plot.plot.ci)
    plots.parameters()["width"] = image.width()
    band = image.height() - plots.export(toBytes=True).height()
    assert band > 10  # the legend's lines
    color = view.time_plot._shown[3]  # the channels' colours, as set_curves was given them
    wanted = {QColor(color(key)).rgb() & 0xFFFFFF for key in view.time_plot._curves}
    seen = {image.pixel(x, y) & 0xFFFFFF for y in range(band) for x in range(0, image.width())}
    assert wanted <= seen


def test_move_and_step_tests_report_overshoot_settling_and_in_position(qtbot, scope, sim_client):
    view = scope(sim_client)
    call(view, lambda c: c.servo(True))
    view.test_angle.setValue(30.0)
    view.test_speed.setValue(30.0)
    with qtbot.waitSignal(view.sigTestDone, timeout=20000) as done:
        view.run_test("move")
    result = done.args[0]
    assert result.error == "", result.error
    m = result.metrics
    assert m.target - m.start == pytest.approx(30.0, abs=0.01)
    assert m.in_position_time_s is not None and m.settling_time_s is not None
    assert abs(m.final_error) < 0.05
    assert result.capture.method == "trace"
    assert view.result_labels["overshoot"].text().endswith("°)")
    assert view.test_angle.suffix() == "°"
    assert view.tests.test_message.text() == "move test of 30° at 30\u00a0r/min done."  # unit kept
    with qtbot.waitSignal(view.sigTestDone, timeout=20000) as done:
        view.run_test("step")
    step = done.args[0]
    assert step.error == "", step.error
    assert step.metrics.rise_time_s is not None and step.metrics.rise_time_s < 0.2
    # the JOG acceleration is back where it was
    with qtbot.waitSignal(view.controller.sigCallDone, timeout=10000) as got:
        call(view, lambda c: c.read_parameter("test", 1))
    assert got.args[0] == 200


def test_recording_while_plotting_loads_in_numpy(qtbot, scope, sim_client, tmp_path):
    view = scope(sim_client)
    view.start_live()
    qtbot.waitUntil(lambda: view.indicator_text() == "LIVE", timeout=10000)
    view.start_recording(tmp_path / "live.csv")
    start = view._recorder.rows_written
    qtbot.waitUntil(lambda: view._recorder.rows_written > start + 50, timeout=10000)
    path = view.stop_recording()
    recording = read_recording(path)
    assert len(recording) > 50 and np.all(np.diff(recording.t_s) > 0)
    assert set(recording.channels) >= {"t", "pos", "current", "cmd_pos", "vel"}


def test_a_documented_only_drive_shows_dgr_position_and_backs_off_with_the_servo_on(qtbot, scope):
    documented = DocumentedDrive(position=204800)
    host, end = pipe_pair("documented")
    drive = ScriptedDrive(end, documented)
    try:
        client = DriveClient.attach(host)
        view = scope(client)
        view.start_live()
        qtbot.waitUntil(lambda: view.indicator_text() == "LIVE: position only (DGR, servo off)",
                        timeout=10000)
        assert view._live.channels[0].key == "feedback_position"
        qtbot.waitUntil(lambda: len(view._live.ring) > 0, timeout=10000)
        assert view._live.ring.window(1)[0, 1] == pytest.approx(204800 * 360 / (8192 * 50))
        documented.servo_on = True
        qtbot.waitUntil(lambda: view.indicator_text().startswith("NOT LIVE: servo on (controller)"),
                        timeout=10000)
        qtbot.waitUntil(lambda: view.info_label.text().startswith("—"), timeout=10000)  # rate cleared
        asked = len(drive.requests)
        qtbot.wait(3000)  # how often the drive is asked in 3 s is the behaviour under test
        assert len(drive.requests) - asked <= 4, "more than one DGR a second while the servo is on"
    finally:
        drive.close()


def test_the_main_window_scope_runs_in_the_link_thread(make_window, qtbot):
    window = make_window(connect=SIM_URL)
    page = window.show_page("scope")
    view = page.view
    assert page.controller.driver.thread() is window.link._thread  # no port of its own
    qtbot.waitUntil(lambda: view.controller.connected, timeout=10000)
    qtbot.waitUntil(lambda: view.indicator_text() == "NOT LIVE: not started", timeout=10000)
    view.start_live()
    qtbot.waitUntil(lambda: view.indicator_text() == "LIVE", timeout=10000)
    # the line is the scope's: the worker's status poll slows down while live
    qtbot.waitUntil(lambda: window.link._worker._poll_interval_ms == 500, timeout=10000)
    window.link.send(Servo(True))
    qtbot.waitUntil(lambda: window.link.servo_on, timeout=10000)
    window.link.jog_press(20.0)
    try:
        qtbot.waitUntil(lambda: abs(latest(view, "output_speed")[-1] - 20.0) < 0.5, timeout=10000)
    finally:
        window.link.jog_release()
    view.stop_live()
    qtbot.waitUntil(lambda: window.link._worker._poll_interval_ms == 100, timeout=10000)
    with qtbot.waitSignal(window.link.sigDisconnected, timeout=10000):
        window.link.close_link()
    qtbot.waitUntil(lambda: view.indicator_text().startswith("NOT LIVE"), timeout=10000)


PACED_URL = f"sim://{ACTUATOR}?paced=1"


@pytest.mark.slow
def test_stop_during_a_trace_read_out_reaches_the_drive_at_the_next_block(make_window, qtbot, time_ceiling):
    """The read-out of a trace holds the link thread for seconds on a real line; a STOP pressed
    then must reach the drive at the next block (TRP), and the capture is abandoned, not shown."""
    window = make_window(connect=PACED_URL)
    link = window.link
    page = window.show_page("scope")
    view = page.view
    qtbot.waitUntil(lambda: view.indicator_text() == "NOT LIVE: not started", timeout=10000)
    link.send(Servo(True))
    qtbot.waitUntil(lambda: link.servo_on, timeout=10000)
    link.send(SetMoveSpeed(5.0))
    link.send(MoveBy(360.0))  # 12 s at 5 r/min: the axis moves through the whole read-out
    qtbot.waitUntil(lambda: link.status is not None and abs(link.status.speed_rpm or 0.0) > 4.0,
                    timeout=10000)
    # two channels, 2048 samples at the servo rate: 32 packed blocks, each ~0.15 s of line time
    for box in view.trace_channels[2:]:
        box.setCurrentIndex(box.findData(None))
    view.trigger_kind.setCurrentIndex(view.trigger_kind.findData(p.TriggerKind.IMMEDIATE))
    view.trace_samples.setValue(2048)
    view.trace_rate.setValue(5000)
    view.trace_pre.setValue(0)
    assert len(view.trace_settings().items()) == 2
    done = []
    view.sigTraceDone.connect(done.append)
    sent = []  # requests on the line, seen in the link thread (the client's bus monitor)
    link.send(Call(lambda c: setattr(c, "trace_packet", lambda out, data: out and sent.append(data))))
    view.arm_trace()
    qtbot.waitUntil(lambda: view.trace_state.text().startswith("reading out 2048 samples"), timeout=10000)
    qtbot.waitUntil(lambda: sum(b"TRP" in d for d in sent) >= 2, timeout=10000)  # block 0 is in
    stops = []
    link.sigResult.connect(lambda r: stops.append((time.monotonic(), r)) if r.answers(Stop) else None)
    pressed = time.monotonic()
    qtbot.keyClick(window, Qt.Key.Key_Escape)  # the main window's STOP
    qtbot.waitUntil(lambda: bool(stops), timeout=10000)
    arrived, result = stops[0]
    assert result.ok, result.error
    # one block (~0.15 s) at most, not the ~5 s of the rest of the read-out; the read-out
    # abandoned after a few blocks (below) is the behaviour, the time only catches a hang
    time_ceiling("STOP during a trace read-out", arrived - pressed, 2.0)
    qtbot.waitUntil(lambda: view.trace_state.text().startswith("abandoned by STOP"), timeout=10000)
    read = int(view.trace_state.text().split("(")[1].split(" of ")[0])
    assert 64 <= read < 2048 and "of 2048 samples read" in view.trace_state.text() and not done
    qtbot.waitUntil(lambda: link.status is not None and abs(link.status.speed_rpm or 0.0) < 0.1
                    and not link.status.moving, timeout=10000)  # the axis stopped and holds
    assert link.servo_on


def test_every_file_action_has_its_dialog_and_what_it_does(qtbot):
    from fha_studio.gui.pages.scope.toolbar import FileAction

    controller = ScopeController()
    view = ScopeView(controller, ScopeContext(ACTUATOR))
    qtbot.addWidget(view)
    try:
        assert set(view.file_actions()) == set(FileAction)
        assert all(action.file_filter for action in FileAction)
        assert [a for a in FileAction if a.opens] == [FileAction.OPEN]
    finally:
        view.shutdown()
        assert controller.shutdown()
