"""The Procedures page in the real window against the embedded simulated drive: a trainee walks the
procedures, a check fails and is put right, the app is restarted and resumes, the report prints."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from fha_studio.gui.link import SetInputs
from fha_studio.hardware.protocol import IoBit
from fha_studio.logic.procedures import ProcedureSession
from tests.gui.procedure_answers import answer_by_hand

CODE = "FHA-25C-50-US250-B-L"
SIM_URL = f"sim://{CODE}?paced=0&ls1_deg=-30&ls2_deg=30&origin_deg=0"


@pytest.fixture
def window(make_window, qtbot):
    w = make_window(connect=SIM_URL)
    qtbot.waitUntil(lambda: len(w.state.drive_values) >= 14, timeout=10000)
    return w


def _answer_by_hand(page):
    """What a trainee types or clicks for the step on the screen (live steps: the button)."""
    step = page.current_step()
    if not answer_by_hand(page, step):
        raise AssertionError(step.kind)


def _walk(page, qtbot, procedure_id, before=None, limit=80):
    page.select_procedure(procedure_id)
    for _ in range(limit):
        step = page.current_step()
        if step is None or page.run.stopped:
            return
        if before:
            before(step)
        if step.kind == "live":
            with qtbot.waitSignal(page.sigLiveDone, timeout=20000):
                page.live_button.click()
        else:
            _answer_by_hand(page)
    raise AssertionError("procedure did not end")


def test_trainee_walks_inspection_and_wiring_with_a_failed_check_and_a_resume(window, qtbot, tmp_path):
    page = window.show_page("procedures")
    page.operator_edit.setText("T. Trainee")
    path = tmp_path / "axis1.json"
    page.new_session(path, CODE)
    assert page.procedure_list.count() == 5
    assert page.session.driver["adjusted_for"] == CODE
    # receiving inspection: the trainee misreads the driver label; the manual's warning stops it
    page.select_procedure("receiving-inspection")
    page.yes_button.click()
    page.value_edit.setText(CODE)
    page.value_button.click()
    page.value_edit.setText("FHA-32C-50-US250")
    page.value_button.click()
    assert page.run.stopped and page.stop_box.isVisibleTo(page)
    assert "Only connect the actuator specified on the driver label" in page.warning_label.text()
    assert not page.step_box.isEnabled()
    page.note_edit.setText("read the label again: 25C")
    page.retry_button.click()
    assert not page.run.stopped
    _walk(page, qtbot, "receiving-inspection")
    assert page.session.runs["receiving-inspection"].status == "completed"
    records = page.session.runs["receiving-inspection"].records
    assert records[-1].step_id == "drive-identity" and records[-1].value == CODE and records[-1].passed

    # wiring: half way, the app is closed
    page.select_procedure("wiring")
    for _ in range(4):
        _answer_by_hand(page)
    here = page.current_step().id
    page.pause_button.click()
    assert ProcedureSession.load(path).runs["wiring"].status == "paused"

    page.open_session(path)  # as after a restart
    page.select_procedure("wiring")
    assert page.current_step().id == here

    def trainee(step):  # switches the brake's 24 V as the step asks (on the simulated drive: INP)
        if step.id in ("brake-releases", "brake-holds"):
            want = step.id == "brake-releases"
            window.link.send(SetInputs({"brake_released": want}))
            qtbot.waitUntil(lambda: window.link.status.bit(IoBit.BRAKE_RELEASED) is want, timeout=15000)

    _walk(page, qtbot, "wiring", before=trainee)
    wiring = ProcedureSession.load(path).runs["wiring"]
    assert wiring.status == "completed", page.warning_label.text()
    assert {r.who for r in wiring.records} == {"T. Trainee"}
    assert "done" in page.procedure_list.item(2).text()


@pytest.mark.slow
def test_sensor_dogs_set_on_the_simulated_drive_and_the_report_prints(window, qtbot, tmp_path):
    page = window.show_page("procedures")
    page.new_session(tmp_path / "axis1.json", CODE, operator="T. Trainee")
    page.select_procedure("sensor-adjustment")
    page.yes_button.click()
    page.yes_button.click()
    panel = page.dog_panel
    assert page.inputs.currentWidget() is panel and panel.sim_box.isVisibleTo(panel)
    qtbot.waitUntil(lambda: panel.wizard.angle_deg is not None, timeout=15000)
    # moves past the movable range are refused before anything is sent
    assert not panel.move_to(179.0)
    assert "movable range" in page.message_label.text()

    def go_to(angle):
        assert panel.move_to(angle)
        qtbot.waitUntil(
            lambda: abs(panel.wizard.angle_deg - angle) < 0.3 and not window.link.moving, timeout=15000
        )

    for sensor, angle in (("limit_switch_2", 25.0), ("limit_switch_1", -20.0), ("origin_sensor", 2.0)):
        assert page.current_step().sensor == sensor
        go_to(angle)
        panel.set_dog_button.click()  # the trainee turns the dog until its switch actuates here
        qtbot.waitUntil(lambda s=sensor: panel.wizard.states[s], timeout=15000)
        panel.record_button.click()
        assert page.session.sensor_angles_deg[sensor] == pytest.approx(angle, abs=0.6)
    page.yes_button.click()  # screws tightened
    progress = []
    with qtbot.waitSignal(page.sigLiveDone, timeout=60000) as done:
        page.live_button.click()
        # the test run takes a while: the page says where the output is while it runs
        qtbot.waitUntil(lambda: page.live_label.text().startswith("Running on the drive"), timeout=30000)
        progress.append(page.live_label.text())
    assert done.args[0].passed, done.args[0].detail
    assert "the output is at" in progress[0] and "°" in progress[0]
    assert page.session.runs["sensor-adjustment"].status == "completed"

    html, pdf = page.write_report(tmp_path / "report.html", tmp_path / "report.pdf")
    text = html.read_text()
    assert "limit switch 2 (CW end)" in text and "HA-655-2-200" in text and "Not signed" in text
    assert "Changed from the defaults" in text or "items differ from the defaults" in text
    assert pdf.read_bytes().startswith(b"%PDF")
    if shutil.which("pdftotext"):
        pdf_text = subprocess.run(
            ["pdftotext", str(pdf), "-"], capture_output=True, text=True, check=True
        ).stdout
        assert "Rotary position sensor set adjustment" in pdf_text and CODE in pdf_text
    assert not page.sign()  # the other procedures are still open
    said = page.message_label.text()  # a sentence, the open procedures one after another
    assert said.startswith("Cannot sign while these are open: ") and " | " not in said
    assert "; Rotary direction (1-10): not done" in said


@pytest.mark.slow
def test_from_boxed_actuator_to_signed_report(make_window, qtbot, tmp_path):
    """Every procedure that applies, in the app only, then the signed report (brake, no sensor set)."""
    code = "FHA-25C-50-US250-B"
    window = make_window(connect=f"sim://{code}?paced=0")
    qtbot.waitUntil(lambda: len(window.state.drive_values) >= 14, timeout=10000)
    window.connection_page.actuator_combo.setCurrentText(code)  # the label's code, typed once
    window.connection_page.check_pairing()
    page = window.show_page("procedures")
    assert code in page.actuator_label.text()  # not asked again
    page.operator_edit.setText("T. Trainee")
    page.new_session(tmp_path / "axis1.json")
    assert "does not apply" in page.procedure_list.item(3).text()

    def trainee(step):  # the brake supply switch, on the page (simulated drive)
        if step.id in ("brake-releases", "brake-holds"):
            assert page.sim_brake_check.isVisibleTo(page)
            want = step.id == "brake-releases"
            page.sim_brake_check.setChecked(want)
            qtbot.waitUntil(lambda: window.link.status.bit(IoBit.BRAKE_RELEASED) is want, timeout=15000)

    for procedure_id in ("receiving-inspection", "installation", "wiring", "rotary-direction"):
        _walk(page, qtbot, procedure_id, before=trainee)
        assert page.session.runs[procedure_id].status == "completed", (
            procedure_id,
            page.warning_label.text(),
        )
    jog = page.session.runs["rotary-direction"].records[2]
    assert jog.step_id == "jog-fwd" and jog.value == pytest.approx(5.0, abs=0.3) and "CW" in jog.detail
    plot = page.capture_scope_plot("Scope after the direction check")
    assert plot is not None and plot.is_file()
    assert page.sign(), page.message_label.text()
    html, pdf = page.write_report(tmp_path / "report.html", tmp_path / "report.pdf")
    text = html.read_text()
    for wanted in (
        "Signed by T. Trainee",
        "No open warnings.",
        "HA-655-2-200",
        "Scope after the direction check",
        "rotary direction",
        "21.6",
        "8-M6 depth: 10",
    ):
        assert wanted in text, wanted
    assert pdf.stat().st_size > 5000
    assert ProcedureSession.load(tmp_path / "axis1.json").signature["who"] == "T. Trainee"


def test_a_restarted_app_reopens_the_session_where_it_was_left(make_window, tmp_path):
    first = make_window()
    page = first.show_page("procedures")
    page.operator_edit.setText("T. Trainee")
    page.new_session(tmp_path / "axis1.json", "FHA-17C-100-US250")
    page.select_procedure("installation")
    page.value_edit.setText("23.5")
    page.value_button.click()
    here = page.current_step().id
    first.save_layout()  # what closing the window does
    second = make_window()  # the app started again
    again = second.procedures_page
    assert again.session is not None and again.session.path == tmp_path / "axis1.json"
    assert again.operator_edit.text() == "T. Trainee"
    again.select_procedure("installation")
    assert again.current_step().id == here
    assert again.run.state.records[0].value == 23.5
