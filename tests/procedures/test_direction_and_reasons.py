"""A rotary-direction check confirmed on its own page is the 1-10 procedure done in the report;
a procedure that does not apply says why."""

from __future__ import annotations

import pytest

from fha_studio.logic.procedures import ProcedureSession, load_procedure
from fha_studio.logic.procedures.context import build_context
from fha_studio.logic.procedures.direction_check import DirectionCheck, record_direction_check
from fha_studio.logic.procedures.report import build_report, render_html
from fha_studio.logic.procedures.session import SessionError

CODE = "FHA-25C-50-US250"


def result(report, procedure_id):
    return next(r for r in report.procedures if r.id == procedure_id)


def test_a_direction_check_confirmed_on_its_page_is_the_procedure_done():
    session = ProcedureSession(actuator_code=CODE, operator="T. Tech")
    assert result(build_report(session), "rotary-direction").status == "not_started"
    check = DirectionCheck(0, "CW", "CW", "T. Tech", "2026-11-30T05:00:00+00:00")
    assert record_direction_check(session, check)
    done = result(build_report(session), "rotary-direction")
    assert done.status == "completed" and all(r.passed for r in done.records)
    walked = load_procedure("rotary-direction", build_context(CODE)).step_ids()
    assert [r.step_id for r in done.records] == walked
    assert "Rotary direction page" in render_html(build_report(session))


def test_a_mismatch_stops_the_procedure_with_the_manuals_remedy():
    session = ProcedureSession(actuator_code=CODE)
    record_direction_check(session, DirectionCheck(0, "CW", "CCW", "T. Tech"))
    run = session.runs["rotary-direction"]
    assert run.status == "stopped" and "Change parameter 8" in run.stop_warning


def test_a_procedure_that_does_not_apply_says_why():
    procedure = load_procedure("sensor-adjustment", build_context(CODE))
    assert not procedure.applies
    assert procedure.not_applicable_reason == (
        "needs an actuator with the rotary position sensor set (option L, 4-7); this one is FHA-25C-50-US250"
    )
    html = render_html(build_report(ProcedureSession(actuator_code=CODE)))
    assert "Does not apply to this actuator: needs an actuator with the rotary position sensor set" in html


def test_a_session_with_front_panel_values_reads_back_and_a_wrong_entry_is_named(tmp_path):
    # the Procedures page writes the values entered from the front panel beside the drive's
    session = ProcedureSession(actuator_code=CODE, operator="T. Tech")
    session.parameters = {
        "file": "axis1.params",
        "values": {"rotary_direction": 1},
        "front_panel": {"rotary_direction": {"who": "T. Tech", "time": "2026-11-30T05:00:00+00:00"}},
    }
    session.save(tmp_path / "s.json")
    assert ProcedureSession.load(tmp_path / "s.json").parameters == session.parameters

    text = (tmp_path / "s.json").read_text(encoding="utf-8").replace('"who": "T. Tech"', '"who": 5')
    (tmp_path / "bad.json").write_text(text, encoding="utf-8")
    wrong = r"field parameters\.front_panel\.rotary_direction\.who: must be text"
    with pytest.raises(SessionError, match=wrong):
        ProcedureSession.load(tmp_path / "bad.json")
