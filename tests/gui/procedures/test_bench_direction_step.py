"""The Procedures page's rotary-direction check (1-10) on a drive whose CN3 is silent while the
servo is on (the documented profile): with the Scope's Bench tab streaming the simulated drive's
CN2, the controller's FWD move answers the FWD step from the encoder outputs, and which way the
flange turned from them and parameter 8, recorded with who and when and in the report (a REV move
that cannot answer it: tests/procedures/test_bench_steps.py)."""

from __future__ import annotations

import re

from tests.gui.controller import bench_standing, panel_done

CODE = "FHA-25C-50-US250"

def test_the_fwd_step_and_the_flange_are_taken_from_the_bench(documented_window, qtbot, tmp_path):
    window = documented_window(CODE)
    page = window.show_page("procedures")
    page.operator_edit.setText("T. Technician")
    page.new_session(tmp_path / "axis.json", CODE)
    page.select_procedure("rotary-direction")
    page.choice_combo.setCurrentText("CW")
    page.choice_button.click()
    with qtbot.waitSignal(page.sigLiveDone, timeout=20000):
        page.live_button.click()  # parameter 8: the drive cannot tell, the panel shows 0
    page.by_hand_edit.setText("0")
    assert page.answer_by_hand() and page.current_step().id == "jog-fwd"
    assert page.bench_note.text().startswith("A bench instrument on CN2 can answer this step")

    bench = window.show_page("scope").bench  # the technician starts the bench there, and comes back
    with qtbot.waitSignal(bench.source.sigStarted, timeout=10000):
        bench.start("sim-cn2", "ENC_A,ENC_B,CMD_A,CMD_B", "250k", "ENC_A,ENC_B", "CMD_A,CMD_B")
    window.show_page("procedures")
    assert page.bench_note.text() == (
        "The bench watches CN2 on sim-cn2 (encoder ENC_A,ENC_B, command CMD_A,CMD_B): have the controller "
        "give servo-ON and a short FWD command: this step is taken from the encoder outputs once the move "
        "has settled.")
    panel_done(window, qtbot, lambda: window.sim_panel.servo_check.setChecked(True))
    qtbot.waitUntil(lambda: window.link.status is not None and window.link.status.servo_on, timeout=10000)
    bench_standing(qtbot, bench)  # standing under servo: what the move starts from
    window.sim_panel.command_spin.setValue(10.0)
    with qtbot.waitSignal(bench.sigChecks, timeout=30000):
        panel_done(window, qtbot, window.sim_panel.fwd_button.click)
    assert page.run.completed, page.message_label.text()
    jog, seen = page.run.state.records[-2:]
    assert (jog.step_id, jog.passed, jog.who) == ("jog-fwd", True, "T. Technician")
    # the encoder ends within a count or two of the command (the servo holds it at standstill)
    counted = re.fullmatch(r"FWD \(\+(\d+) counts for \+13889 commanded\)", jog.value)
    assert counted and abs(int(counted.group(1)) - 13889) <= 2, jog.value
    assert jog.detail.startswith("from CN2: a FWD command (+13889 counts) turned the axis FWD as the encoder "
                                 "outputs count it from the bench instrument sim-cn2")
    assert (seen.step_id, seen.value, seen.passed) == ("seen-direction", "CW", True) and seen.at_utc
    assert "with parameter 8 = 0: FWD rotation, CW viewing the output flange (1-10)" in seen.detail
    assert page.message_label.text() == (f"Recorded from the move on the bench: {jog.value}, then CW (each "
                                         "record says where from)")
    assert page.history.item(2, 1).toolTip() == jog.detail  # where the value came from, on the value
    html, _pdf = page.write_report(tmp_path / "axis.html")
    assert "CW viewing the output flange (1-10), on the bench instrument sim-cn2" in html.read_text("utf-8")
    with qtbot.waitSignal(bench.source.sigStopped, timeout=10000):
        bench.start_button.click()
