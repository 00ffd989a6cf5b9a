"""The Tuning page end to end on the embedded simulated drive (real client, protocol and trace; a
stepped drive, whose time the measurement moves on itself): the excitation is shown before it
starts, the countdown can be cancelled (nothing moves), the measured response is plotted with the
gear's resonance marked, the proposal is applied through the session's write path (backup first)
and measured again, and the commissioning report shows the tuning's plot, figures, who and when;
hold-to-run ends the excitation when the button is let go or the page left; a drive of the
manual's commands gets a front-panel worksheet."""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg
import pytest
from PySide6.QtCore import Qt
from PySide6.QtGui import QImage

from fha_studio.gui.pages.base import PageId

CODE = "FHA-25C-50-US250"
URL = f"sim://{CODE}?load_inertia=0.81&effects=torsional_compliance&paced=0&stepped=1"


def _planned(make_window, qtbot):
    """The Tuning page on the simulated axis (0.81 kg m^2 declared), servo on, its excitation
    planned: (window, page)."""
    window = make_window(connect=URL)
    page = window.show_page(PageId.TUNING)
    page.load_spin.setValue(0.81)
    window.servo_action.trigger()
    qtbot.waitUntil(lambda: window.link.status is not None and window.link.status.servo_on, timeout=10000)
    with qtbot.waitSignal(window.link.sigResult, timeout=20000):
        page.plan_button.click()
    return window, page


@pytest.mark.slow
def test_measure_propose_apply_end_to_end(make_window, qtbot, tmp_path):
    window, page = _planned(make_window, qtbot)
    qtbot.waitUntil(page.start_button.isEnabled, timeout=10000)
    # the manual's symbols on a page, not the terminal's ASCII
    assert "r/min" in page.plan_label.text() and "°" in page.plan_label.text()
    assert "+/-" not in page.plan_label.text() and " deg" not in page.plan_label.text()
    drive = window.link._worker._client.transaction.transport.inner.sim_drive
    before = drive.axis.output_pos_rad
    page.start_countdown()
    page.cancel_countdown()
    assert "nothing moved" in page.status_label.text()
    assert drive.axis.output_pos_rad == pytest.approx(before, abs=1e-6)
    with qtbot.waitSignal(page.sigMeasured, timeout=120000) as measured:
        page.start_countdown()
    result = measured.args[0]
    assert result["resonance_hz"] == pytest.approx(result["predicted_resonance_hz"], rel=0.1)
    assert len(page.markers) == 4  # resonance, anti-resonance, and their predictions
    assert "Resonance" in page.result_label.text()
    page.use_inertia_button.click()  # the estimate offered to the commissioning state
    assert window.session.state.load_inertia_kgm2 == pytest.approx(0.81, rel=0.1)
    with qtbot.waitSignal(page.sigProposed, timeout=120000):
        page.propose_button.click()
    assert page.table.item(0, 1) is not None
    # the text and the table say the same gain margin: the table's present one is the model's
    present_gm = page.table.item(len(page.proposal.proposed.items), 0).text()
    assert "(model)" in page.table.horizontalHeaderItem(0).text()
    if result["gain_margin_db"] is None and page.proposal.present.gain_margin_db is not None:
        assert f"gain margin {float(present_gm):.3g}\u00a0dB by the model" in page.result_label.text()
    assert page.apply_button.isEnabled()
    with qtbot.waitSignal(page.sigApplied, timeout=180000) as applied:
        page.apply_button.click()
    assert window.session.state.backup_path is not None and window.session.state.backup_path.exists()
    assert applied.args[0]["items"]["speed_loop_gain"] == page.proposal.proposed.items["speed_loop_gain"]
    assert page.table.item(len(page.proposal.proposed.items), 2) is not None
    ((note, _who),) = page.report_notes()  # the commissioning report's before / after
    assert "Applied" in note and "resonance" in note
    procedures = window.show_page(PageId.PROCEDURES)
    procedures.new_session(tmp_path / "axis1.json", CODE, operator="A. Tuner")
    html, pdf = procedures.write_report(tmp_path / "report.html", tmp_path / "report.pdf")
    text = html.read_text()
    assert "Tuning 1 (" in text and "A. Tuner" in text and "before (dashed) and after (solid)" in text
    (plot,) = [p for p in procedures.session.plots if p["title"].startswith("Tuning 1 (")]
    image = QImage(plot["path"])
    assert not image.isNull() and image.width() >= 1000
    assert plot["path"] in text and pdf.stat().st_size > 20000


@pytest.mark.parametrize("let_go", ["release", "leave the page"])
def test_hold_to_run_excites_only_while_held(make_window, qtbot, let_go):
    window, page = _planned(make_window, qtbot)
    qtbot.waitUntil(page.hold_button.isEnabled, timeout=10000)
    drive = window.link._worker._client.transaction.transport.inner.sim_drive
    qtbot.mousePress(page.hold_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: drive.excitation.active, timeout=20000)
    assert "let go to stop" in page.status_label.text()
    if let_go == "release":
        qtbot.mouseRelease(page.hold_button, Qt.MouseButton.LeftButton)
    else:
        window.show_page(PageId.JOG)  # the hold button hides: let go, as a jog's
    qtbot.waitUntil(lambda: "Let go" in page.status_label.text(), timeout=20000)
    assert not drive.excitation.active and page.result is None


def test_documented_drive_gets_a_front_panel_worksheet(make_window, qtbot):
    """... for a load of 10 x the actuator's own inertia, beyond the about 3 x of 2-1: the page
    says so and tunes softer."""
    from fha_studio.logic.tuning.session import declared_model

    window = make_window(connect=f"sim://{CODE}?paced=0&profile=documented")
    page = window.show_page(PageId.TUNING)
    assert "cannot be excited" in page.plan_label.text()
    page.actuator_edit.setText(CODE)  # the manual's commands do not say which actuator
    page.load_spin.setValue(10.0 * declared_model(CODE, 0.0).actuator_inertia_kgm2)
    with qtbot.waitSignal(page.sigProposed, timeout=60000):
        page.propose_button.click()
    text = page.worksheet.toPlainText()
    assert "tune item 0" in text and "->" in text
    assert not page.apply_button.isEnabled()
    warning = page.warning_label.text()
    assert page.warning_label.isVisible() and "2-1" in warning and "softer" in warning, warning


@pytest.mark.parametrize("size", [(1366, 768), (1280, 720)])
def test_the_resonance_labels_are_not_crossed_by_the_other_markers(make_window, qtbot, size):
    """A resonance is marked with its label on the higher side of its line, an anti-resonance on
    the lower side: neither label straddles the other marker's line (at 38 and 54 Hz a label on
    the same side read through the other line)."""
    import numpy as np

    window = make_window()
    window.resize(*size)
    page = window.show_page(PageId.TUNING)
    qtbot.waitExposed(window)
    f = np.geomspace(1.0, 500.0, 200)
    response = {"freq_hz": list(f), "magnitude_db": list(-20 * np.log10(1 + f / 30)),
                "phase_deg": list(-np.degrees(np.arctan(f / 30)))}
    page.show_result({"frequency_response": response, "plant_response": response, "resonance_hz": 54.3,
                      "antiresonance_hz": 38.0, "predicted_resonance_hz": 54.2,
                      "predicted_antiresonance_hz": 38.0})
    assert len(page.markers) == 4
    view = page.mag_plot.getViewBox()
    qtbot.waitUntil(lambda: view.viewRange()[0][1] > 2.5, timeout=5000)  # the data's range: to 500 Hz
    def x_of(line):
        return view.mapViewToScene(pg.Point(line.value(), 0)).x()

    for marker in (m for m in page.markers if m.label.isVisible()):  # a prediction at its place: said there
        text = marker.label.mapRectToScene(marker.label.boundingRect())
        for other in page.markers:  # a line beside its own (54.3 and 54.2 Hz) is the same place
            if abs(x_of(other) - x_of(marker)) > 5:
                crossed = text.left() < x_of(other) < text.right()
                assert not crossed, (marker.label.toPlainText(), other.value())
        assert view.sceneBoundingRect().contains(text), marker.label.toPlainText()  # whole, in the plot


def _two_mass_result(predicted_antiresonance_hz: float, predicted_resonance_hz: float, top_hz: float):
    """What a measurement of an axis on the gear's spring shows: the closed speed loop near 0 dB
    up to its anti-resonance (38 Hz) and resonance (54.3 Hz), the plant falling through both."""
    import numpy as np

    f = np.geomspace(1.2, top_hz, 400)
    s = 2j * np.pi * f
    wa, wr = 2 * np.pi * 38.0, 2 * np.pi * 54.3
    plant = 0.9 / s * (s**2 + 0.06 * wa * s + wa**2) / (s**2 + 0.1 * wr * s + wr**2) * (wr**2 / wa**2)
    loop = 170.0 * (1 + 1 / (0.02 * s)) * plant
    closed = loop / (1 + loop)

    def response(h):
        return {"freq_hz": list(f), "magnitude_db": list(20 * np.log10(abs(h))),
                "phase_deg": list(np.degrees(np.angle(h))), "coherence": list(np.ones_like(f))}

    return {"frequency_response": response(closed), "plant_response": response(plant),
            "resonance_hz": 54.3, "antiresonance_hz": 38.0, "predicted_resonance_hz": predicted_resonance_hz,
            "predicted_antiresonance_hz": predicted_antiresonance_hz}


@pytest.mark.parametrize("size", [(1366, 768), (1280, 720)])
@pytest.mark.parametrize("predicted_hz", [(38.0, 54.2, 500.0), (33.0, 62.0, 500.0), (38.0, 54.2, 70.0)],
                         ids=["at the measured", "apart", "measured to 70 Hz"])
def test_the_marker_labels_keep_off_the_curves_and_the_page_fits(make_window, qtbot, size, predicted_hz):
    """No curve runs through a resonance marker's label (the closed loop near 0 dB ran through the
    one put at the top), and the page shows the excitation, a warning, the outcome and the three
    plots whole without a vertical scroll bar. A prediction at the measured place is said in the
    measured marker's label (two labels there found no room between the curves)."""
    import itertools

    import numpy as np
    from PySide6.QtCore import QPoint, QPointF
    from PySide6.QtWidgets import QScrollArea

    window = make_window()
    window.resize(*size)
    page = window.show_page(PageId.TUNING)
    qtbot.waitExposed(window)
    result = _two_mass_result(*predicted_hz)
    # the longest plan: on a jog within a known range (in place, with its warning, is shorter)
    page.plan_label.setText(
        "Excitation: PRBS of ±0.753 r/min on the speed command on a jog of 1.82 r/min REV (CCW seen from "
        "the flange), which turns the axis up to about 66.7° REV (so it never reverses and sticks on its "
        "friction), bits of 4 servo periods, 5 records of 4092 samples (4.8 s); the output travels at most "
        "±0.113° about the jog's path (the drive stops at 0.236°), current at most 3.25 A; within the "
        "movable range: 120° to limit switch 1 (CCW end), 135° to limit switch 2 (CW end). Servo on, the "
        "axis free to move that far; STOP ends it at once.")
    page.show_result(result)
    page.warning_label.setText("Warning: the load is 10 x the actuator's inertia, beyond the about 3 x "
                               "of 2-1: tuned softer")
    view = page.mag_plot.getViewBox()
    lowest_db = min(result["plant_response"]["magnitude_db"])
    highest = np.log10(predicted_hz[2]) - 0.1
    qtbot.waitUntil(lambda: view.viewRange()[0][1] > highest and view.viewRange()[1][0] < lowest_db,
                    timeout=5000)

    area = page.findChild(QScrollArea)
    line_px = page.plan_label.fontMetrics().lineSpacing()

    def whole_without_scrolling() -> bool:
        if page.plan_label.height() < 2 * line_px or page.warning_label.height() < line_px:
            return False  # the new texts not laid out yet
        bottom = page.plots.mapTo(area.viewport(), QPoint(0, page.plots.height())).y()
        return (area.verticalScrollBar().maximum() == 0
                and bottom <= area.viewport().height()  # the plots not cut off below
                and page.plots.ci.geometry().height() <= page.plots.height())  # the frequency axis in

    qtbot.waitUntil(whole_without_scrolling, timeout=5000)
    assert page.warning_label.isVisible() and page.plan_label.isVisible()

    shown = [m.label.toPlainText() for m in page.markers if m.label.isVisible()]
    if predicted_hz == (38.0, 54.2, 500.0):
        assert shown == ["resonance 54.3 Hz (predicted 54.2 Hz)",
                         "anti-resonance 38.0 Hz (predicted 38.0 Hz)"]
    elif predicted_hz[2] < 100.0:  # no room right of 54.3 Hz for the prediction: the line above says it
        assert shown[0] == "resonance 54.3 Hz" and shown[1].startswith("anti-resonance 38.0 Hz")
    else:
        assert shown == ["resonance 54.3 Hz", "anti-resonance 38.0 Hz", "predicted 62.0 Hz",
                         "predicted 33.0 Hz"]
    for marker in (m for m in page.markers if m.label.isVisible()):
        box = marker.label.mapRectToScene(marker.label.boundingRect())
        assert view.sceneBoundingRect().contains(box), marker.label.toPlainText()
        for key in ("frequency_response", "plant_response"):
            x = np.log10(result[key]["freq_hz"])
            y = np.asarray(result[key]["magnitude_db"])
            # the curve as drawn, a point per pixel across the label: no segment reaches into it
            columns = np.arange(np.floor(box.left()) - 1, np.ceil(box.right()) + 2)
            at = np.interp([view.mapSceneToView(QPointF(c, 0)).x() for c in columns], x, y)
            rows = [view.mapViewToScene(QPointF(0, v)).y() for v in at]
            for top, low in itertools.pairwise(rows):
                crossed = min(top, low) < box.bottom() and box.top() < max(top, low)
                assert not crossed, (marker.label.toPlainText(), key)


def _plan_with(page, qtbot, window, bias: str) -> str:
    """Choose the bias speed by keyboard (the combo box's arrow keys) and show the plan: its text."""
    page.bias_combo.setFocus()
    target = page.bias_combo.findData(bias)
    for _ in range(page.bias_combo.count()):
        if page.bias_combo.currentIndex() == target:
            break
        down = page.bias_combo.currentIndex() < target
        qtbot.keyClick(page.bias_combo, Qt.Key.Key_Down if down else Qt.Key.Key_Up)
    assert page.bias_combo.currentData() == bias
    with qtbot.waitSignal(window.link.sigResult, timeout=20000):
        page.plan_button.click()
    return page.plan_label.text()


def test_the_bias_direction_is_chosen_shown_checked_and_remembered(make_window, qtbot, tmp_path):
    """REV: the plan says the jog's command and rotation in the manual's words (CCW with rotary
    direction 0) and how far, and that the range is not known; limit switches recorded in the
    procedures that leave too little room refuse the start in one line, naming the other choice;
    in place: the stick-slip warning before it starts. The choice is remembered with the window."""
    window, page = _planned(make_window, qtbot)
    assert page.bias_combo.currentData() == "fwd" and page.start_button.isEnabled()
    assert page.bias_combo.focusPolicy() & Qt.FocusPolicy.TabFocus
    label = next(w for w in page.findChildren(type(page.plan_label)) if w.buddy() is page.bias_combo)
    assert "&" in label.text()  # an Alt letter reaches it
    text = _plan_with(page, qtbot, window, "rev")
    assert "r/min REV (CCW seen from the flange)" in text and "° REV" in text
    assert "\u00a0r/min REV" in text and "\u00a0A" in text  # each figure keeps its unit where the line wraps
    assert "the movable range is not known" in text and page.start_button.isEnabled()
    # the procedures recorded limit switch 1 (CCW end) 20° from the axis, limit switch 2 far
    procedures = window.show_page(PageId.PROCEDURES)
    procedures.new_session(tmp_path / "axis1.json", CODE, operator="A. Tuner")
    procedures.session.sensor_angles_deg.update({"limit_switch_1": -20.0, "limit_switch_2": 300.0})
    window.show_page(PageId.TUNING)
    with qtbot.waitSignal(window.link.sigResult, timeout=20000):
        page.plan_button.click()
    refused = page.plan_label.text()
    assert refused.startswith("No excitation: on a REV (CCW seen from the flange) jog the excitation would "
                              "turn the axis up to about") and "\n" not in refused
    assert "only 20° to limit switch 1 (CCW end)" in refused
    assert "choose FWD (CW seen from the flange)" in refused
    assert not page.start_button.isEnabled() and not page.hold_button.isEnabled()
    latest = window.message_area.latest()  # the plan's answer, not a failed drive request
    assert latest is None or "failed" not in latest.text
    text = _plan_with(page, qtbot, window, "fwd")
    assert "within the movable range" in text and "limit switch 2 (CW end)" in text
    assert page.start_button.isEnabled()
    text = _plan_with(page, qtbot, window, "none")
    assert "jog" not in text and "sticks on its friction at every reversal" in text
    assert "not to be trusted" in text
    window.save_layout()
    again = make_window()
    assert again.show_page(PageId.TUNING).bias_combo.currentData() == "none"


def test_a_start_refused_by_the_range_is_said_once_on_the_page(make_window, qtbot, tmp_path):
    """The plan fitted the movable range; limit switch 2 (CW end) was recorded again since, only 30°
    from the axis (as after the axis was moved towards it): the check at the start refuses in the
    page's words, nothing moves, and the message bar does not call it a failed drive request."""
    window, page = _planned(make_window, qtbot)
    procedures = window.show_page(PageId.PROCEDURES)
    procedures.new_session(tmp_path / "axis1.json", CODE, operator="A. Tuner")
    procedures.session.sensor_angles_deg.update({"limit_switch_1": -300.0, "limit_switch_2": 300.0})
    window.show_page(PageId.TUNING)
    text = _plan_with(page, qtbot, window, "fwd")
    assert "within the movable range" in text and page.start_button.isEnabled()
    procedures.session.sensor_angles_deg["limit_switch_2"] = 30.0  # FWD: CW with rotary direction 0
    drive = window.link._worker._client.transaction.transport.inner.sim_drive
    before = drive.axis.output_pos_rad
    shown = window.message_area.latest()
    page.measure()  # where the countdown ends
    qtbot.waitUntil(lambda: page.status_label.text().startswith("Measurement not done"), timeout=60000)
    latest = window.message_area.latest()  # the range check's answer, not a failed drive request
    assert latest is shown or "failed" not in latest.text, latest.text
    said = page.status_label.text()
    assert "only 30° to limit switch 2 (CW end)" in said and " deg" not in said, said
    assert "\n" not in said and said.count("Measurement not done") == 1
    assert drive.axis.output_pos_rad == pytest.approx(before, abs=1e-6) and page.result is None


def test_the_frequency_axis_reads_hz_in_plain_numbers_above_1_khz(make_window, qtbot):
    """The Bode plots' frequency in Hz whatever the range (1000, 2000; never "1" under "kHz"),
    labelled 1, 2, 5 per decade as the scope's spectrum amplitude (one axis class)."""
    page = make_window().show_page(PageId.TUNING)
    page.coh_plot.setXRange(0.0, float(np.log10(2500.0)), padding=0)
    axis = page.coh_plot.getAxis("bottom")
    qtbot.waitUntil(lambda: axis.range[1] > 3.0, timeout=5000)
    assert axis.labelString().endswith("frequency (Hz)</span>"), axis.labelString()
    words = axis.logTickStrings(np.log10([1.0, 3.0, 1000.0, 2000.0]), axis.autoSIPrefixScale, 1.0)
    assert words == ["1", "", "1000", "2000"]
