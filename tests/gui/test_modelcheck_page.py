"""The model check in the main window, on a move captured in the GUI from the embedded drive.

The simulated drive has a hidden Coulomb friction the catalogue model lacks; the trainee captures
a back-and-forth move with the scope, hands it to the model check page, and sees the effect
named, its size, and the gap shrink on held-out data. Nobody tells the page which effect it is.
"""

from __future__ import annotations

import json

import pytest

from fha_studio.gui.link import Call
from fha_studio.hardware import protocol as p
from fha_studio.recording import RecordingError

FRICTION_NM = 12.0
URL = f"sim://FHA-25C-50-US250?paced=0&load_inertia=0.5&effects=coulomb_friction:torque_nm={FRICTION_NM}"


def _back_and_forth(client) -> None:
    """Runs in the link thread: servo on, +90 deg then -90 deg at 20 r/min, each move until the
    drive says the output stands still (the moving bit clears after its standstill time)."""
    import time

    client.servo(True)
    client.set_move_speed(20.0)
    for angle in (90.0, -90.0):
        client.move_by(angle)  # the moving bit is set with the command
        deadline = time.monotonic() + 30.0  # only a hang: a move takes about 1 s
        while client.io_state().moving:
            assert time.monotonic() < deadline, f"a {angle} deg move at 20 r/min still runs after 30 s"
            time.sleep(0.02)  # a look at the bit every 20 ms, not a hold of the motion


def capture_a_move(window, qtbot) -> None:
    """A 1 kHz trace in the scope, triggered as the axis starts moving, of :func:`_back_and_forth`."""
    scope = window.show_page("scope").view
    scope.trace_rate.setValue(1000)
    scope.trace_samples.setValue(p.TRACE_MAX_SAMPLES)
    scope.trace_pre.setValue(2)
    scope.trigger_kind.setCurrentIndex(scope.trigger_kind.findData(p.TriggerKind.IO_BIT_RISES))
    scope.trigger_channel.setCurrentIndex(scope.trigger_channel.findData("moving"))
    scope.arm_trace()
    qtbot.waitUntil(lambda: "waiting for the trigger" in scope.trace_state.text(), timeout=10000)
    with qtbot.waitSignal(scope.sigTraceDone, timeout=30000):
        window.link.send(Call(_back_and_forth))


@pytest.mark.slow
def test_a_move_captured_in_the_scope_tells_the_missing_friction(make_window, qtbot, tmp_path):
    window = make_window(connect=URL)
    page = window.show_page("modelcheck")
    assert not page.run_button.isEnabled()  # nothing loaded yet
    with pytest.raises(ValueError, match="Scope page"):
        page.take_scope_capture()

    scope = window.show_page("scope").view
    scope.load_inertia.setValue(0.5)  # the trainee declares the load, as written into recordings
    capture_a_move(window, qtbot)

    page = window.show_page("modelcheck")
    path = page.take_scope_capture()
    assert path.exists() and str(tmp_path) in str(path)  # the test's data dir, never the user's
    assert page.run_button.isEnabled()
    assert page.inertia_spin.value() == pytest.approx(0.5)
    with qtbot.waitSignal(page.sigFinished, timeout=60000) as done:
        qtbot.mouseClick(page.run_button, pg_left())
    result = done.args[0]
    ids = [e.id for e in result.effects]
    assert ids == ["coulomb_friction"], page.summary.toPlainText()  # and no noise named beside it
    friction = next(e for e in result.effects if e.id == "coulomb_friction")
    assert friction.params["torque_nm"] == pytest.approx(FRICTION_NM, rel=0.25)
    gap = result.gap["torque"]
    assert gap.rms_after < 0.5 * gap.rms_before
    # every step is on show
    assert "Coulomb friction" in page.summary.toPlainText()
    assert page.effects_table.rowCount() == len(result.effects)
    assert page.where_variable.currentData() == "speed"
    assert "torque" in page.gap_plots
    assert len(page.torque_plot.getPlotItem().listDataItems()) == 2
    # drawn plots have their numbers back and no "nothing yet" note
    assert page.torque_plot.empty_note is None and page.resim_pos_plot.empty_note is None
    assert page.torque_plot.getPlotItem().getAxis("left").style["showValues"] and page.gap_empty.isHidden()
    # and the updated model and the report are written
    model = page.save_model(tmp_path / "axis.toml")
    assert "coulomb_friction" in model.read_text()
    report = json.loads(page.save_report(tmp_path / "report.json").read_text())
    assert report["gap"]["torque"]["rms_after"] < report["gap"]["torque"]["rms_before"]


def test_a_bad_recording_is_refused_and_nothing_changes(make_window, qtbot, tmp_path):
    window = make_window()
    page = window.show_page("modelcheck")
    bad = tmp_path / "bad.csv"
    bad.write_text("# format: fha-recording/1\n# actuator: FHA-25C-50-US250\n# load_inertia_kgm2: 1\n"
                   "t,pos\n0,0\n0.001,0\n", encoding="utf-8")
    with pytest.raises(RecordingError, match="current"):
        page.load_recording(bad)
    assert page.recording is None and not page.run_button.isEnabled()


def pg_left():
    from PySide6.QtCore import Qt

    return Qt.MouseButton.LeftButton
