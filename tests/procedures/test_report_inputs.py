"""What the other pages give a report, brought into the session without Qt: the drive's identity,
the known parameter values and their file, the Rotary direction page's check, the DGR checks."""

from __future__ import annotations

from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.absolute import DgrCheckRecord
from fha_studio.logic.commissioning import FrontPanelEntry
from fha_studio.logic.procedures import ProcedureSession
from fha_studio.logic.procedures.direction_check import PROCEDURE_ID, DirectionCheck
from fha_studio.logic.procedures.report_inputs import ReportInputs, collect_for_report, dgr_check_notes

CODE = "FHA-25C-50-US250"
AT = "2026-12-04T01:02:03+01:00"


def _session(tmp_path, name="axis1.fha-session.json"):
    session = ProcedureSession(actuator_code=CODE, operator="ana")
    session.save(tmp_path / name)
    return session


def test_identity_values_their_file_and_who_entered_them_go_into_the_session(tmp_path):
    session = _session(tmp_path)
    panel = FrontPanelEntry("tune", 4, 10, "ben", AT)
    read_too = FrontPanelEntry("system", 8, 0, "ben", AT)
    inputs = ReportInputs(
        who="ana",
        parameter_model=load_parameter_model(),
        driver={"model": "HA-655-2-200", "url": "sim://x"},
        values={("system", 8): 1, ("tune", 4): 10, ("system", 99): 3},
        read={("system", 8)},
        front_panel={("tune", 4): panel, ("system", 8): read_too},
        parameter_file_text="# fha-parameters/1\n",
    )
    assert collect_for_report(session, inputs) is False  # no direction check: the procedures stay
    assert session.driver == {"model": "HA-655-2-200", "url": "sim://x"}
    params = session.parameters
    assert params["values"] == {"rotary_direction": 1, "in_position_range": 10}  # 99: no such item
    assert params["front_panel"] == {"in_position_range": {"who": "ben", "time": AT}}  # read wins
    written = tmp_path / "axis1.fha-session.params"
    assert params["file"] == str(written) and written.read_text() == "# fha-parameters/1\n"
    assert ProcedureSession.load(session.path).parameters == params  # saved


def test_nothing_known_leaves_the_session_as_it_was(tmp_path):
    session = _session(tmp_path)
    before = (dict(session.driver), dict(session.parameters), list(session.notes))
    collect_for_report(session, ReportInputs(who="ana", parameter_model=load_parameter_model()))
    assert (session.driver, session.parameters, session.notes) == before


def test_a_parameter_file_that_cannot_be_written_is_said_missing(tmp_path):
    session = _session(tmp_path)
    (tmp_path / "axis1.fha-session.params").mkdir()  # a directory where the file goes
    inputs = ReportInputs(who="ana", parameter_model=load_parameter_model(), values={("system", 8): 1},
                          parameter_file_text="x\n")
    collect_for_report(session, inputs)
    assert session.parameters["file"] == "" and session.parameters["values"] == {"rotary_direction": 1}


def test_the_direction_page_check_is_the_procedure_done_by_the_operator(tmp_path):
    session = _session(tmp_path)
    check = DirectionCheck(0, "CW", "CW", "", "2026-12-04T00:00:00+00:00")
    inputs = ReportInputs(who="ana", parameter_model=load_parameter_model(), direction_check=check)
    assert collect_for_report(session, inputs) is True
    run = session.runs[PROCEDURE_ID]
    assert run.status == "completed" and {r.who for r in run.records} == {"ana"}


def test_dgr_checks_are_notes_each_once(tmp_path):
    session = _session(tmp_path)
    records = [
        DgrCheckRecord("encoder", "ben", AT, {}, True, "turned 90°, read 89.9°"),
        DgrCheckRecord("rotary_direction", "ben", AT, {"rotary_direction": 0}, None, "entered", by_hand=True),
    ]
    assert dgr_check_notes(records) == [
        (f"Encoder check (turned by hand) ({AT}, with DGR): pass: turned 90°, read 89.9°", "ben"),
        (f"Rotary direction (1-10) ({AT}, entered by hand): recorded: entered", "ben"),
    ]
    inputs = ReportInputs(who="ana", parameter_model=load_parameter_model(), dgr_checks=records)
    collect_for_report(session, inputs)
    collect_for_report(session, inputs)
    assert [(n["text"].split(" (")[0], n["who"]) for n in session.notes] == [
        ("Encoder check", "ben"), ("Rotary direction", "ben")
    ]
