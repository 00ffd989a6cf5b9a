"""The commissioning report: built from the session file alone, HTML with what was checked."""

from __future__ import annotations

import pytest

from fha_studio.logic.procedures import ProcedureRun, ProcedureSession, load_procedure
from fha_studio.logic.procedures.report import SignError, build_report, render_html, report_title, sign
from tests.procedures.walk import walk

ALL = ["receiving-inspection", "installation", "wiring", "sensor-adjustment", "rotary-direction"]


def _finished_session(context, path):
    session = ProcedureSession(actuator_code=context["actuator"]["model_code"], operator="T. Trainee",
                               site="Line 3")
    session.driver = {"model": "HA-655-2-200", "adjusted_for": "FHA-25C-50-US250-B-L", "version": "sim 1"}
    session.save(path)
    for procedure_id in ALL:
        walk(ProcedureRun(session, load_procedure(procedure_id, context)))
    return session


def test_report_of_a_finished_session_signs_and_reproduces(context, tmp_path):
    path = tmp_path / "axis1.json"
    session = _finished_session(context, path)
    session.parameters = {"file": "axis1.params", "values": {"rotary_direction": 1, "position_loop_gain": 50}}
    plot = tmp_path / "step.png"
    plot.write_bytes(b"\x89PNG\r\n\x1a\n")
    session.add_plot("Step response", plot)
    session.save()
    report = build_report(session, context)
    assert report.warnings == ()
    sign(session, "T. Trainee", context)
    html = render_html(build_report(ProcedureSession.load(path), context))
    assert html == render_html(build_report(ProcedureSession.load(path), context))  # reproducible
    for text in (
        "FHA-25C-50-US250-B-L",
        "HA-655-2-200",
        "Receiving inspection",
        "8-M6 depth: 10",  # the tightening torques that were checked
        "the Blue lead goes to Brake",
        "limit switch 2 (CW end)",
        "+120.00°",
        "Signed by T. Trainee",
        "rotary direction",
        str(plot),
        "No open warnings.",
    ):
        assert text.lower() in html.lower(), text
    changed = {p.key for p in build_report(session, context).changed_parameters}
    assert "rotary_direction" in changed


def test_open_warnings_block_the_signature(context, tmp_path):
    session = ProcedureSession(actuator_code=context["actuator"]["model_code"], operator="T. Trainee")
    run = ProcedureRun(session, load_procedure("receiving-inspection", context), autosave=False)
    run.submit(True)
    run.submit("FHA-25C-50-US250")  # the label lacks -B-L: not what was ordered
    report = build_report(session, context)
    # the step in the checklist's words, not its file id
    assert any("stopped at 'A label is attached on the right side" in w for w in report.warnings)
    assert not any("actuator-type-label" in w for w in report.warnings)
    assert any("Location and installation (3-3): not done" in w for w in report.warnings)
    with pytest.raises(SignError, match="cannot sign while these are open"):
        sign(session, "T. Trainee", context)
    html = render_html(report)
    assert "FAIL" in html and "immediately contact the dealer" in html and "Not signed" in html


def test_a_failure_put_right_stays_in_the_history(context):
    session = ProcedureSession(actuator_code="x")
    run = ProcedureRun(session, load_procedure("installation", context), autosave=False)
    run.submit(45)
    run.retry(note="air conditioning repaired")
    run.submit(25)
    report = build_report(session, context)
    installation = next(p for p in report.procedures if p.id == "installation")
    assert [r.value for r in installation.records] == [45.0, 25.0] and installation.failed == 1
    assert not any("failed and was not checked again" in w for w in report.warnings)
    assert "air conditioning repaired" in render_html(report)


def test_options_that_do_not_apply_say_so(make_context):
    context = make_context(brake=False, sensor_set=False)
    report = build_report(ProcedureSession(actuator_code="x"), context)
    sensor = next(p for p in report.procedures if p.id == "sensor-adjustment")
    assert sensor.status == "not applicable"
    assert not any("Rotary position sensor" in w for w in report.warnings)
    assert "Does not apply to this actuator" in render_html(report)


@pytest.mark.parametrize(("axis", "code", "title"), [
    ("table", "FHA-25C-50-US250", "Commissioning report — table — FHA-25C-50-US250"),
    # an axis nobody named is called by its actuator's code: the title says it once
    ("FHA-25C-50-US250 (simulated)", "FHA-25C-50-US250",
     "Commissioning report — FHA-25C-50-US250 (simulated)"),
    ("fha-17c-100 on line 3", "FHA-17C-100", "Commissioning report — fha-17c-100 on line 3"),
    ("axis 1", "", "Commissioning report — axis 1"),
])
def test_the_title_names_the_actuator_once(axis, code, title):
    assert report_title(axis, code) == title
