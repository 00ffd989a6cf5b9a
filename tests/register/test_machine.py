"""A machine project (axes, each with its own commissioning state; file and register) and the
machine report (summary of every axis, then each axis's report)."""

from __future__ import annotations

import json

import pytest

from fha_studio.catalog import ModelCodeError
from fha_studio.logic.machine import MachineError, MachineProject
from fha_studio.logic.machine_report import build_machine_report, direction_text, render_machine_html
from fha_studio.logic.procedures import ProcedureRun, ProcedureSession, load_procedure
from fha_studio.logic.procedures.context import build_context
from fha_studio.logic.procedures.report import sign
from tests.procedures.walk import walk


def _positioner() -> MachineProject:
    project = MachineProject("Line 3 positioner", site="Plant A, hall 2")
    project.add_axis("table", "FHA-25C-50-US250-L", "HA-655-2-200", "sim://FHA-25C-50-US250-L", 1.5)
    project.add_axis("table twin", "FHA-25C-50-US250-L", "HA-655-2-200", "sim://FHA-25C-50-US250-L?x=2", 1.5)
    project.add_axis("tilt", "FHA-32C-100-S248-B", "HA-655-2-200", "/dev/ttyUSB2", 4.0, notes="brake")
    return project


def test_each_axis_has_its_own_commissioning_state():
    project = _positioner()
    table, twin = project.axis("table"), project.axis("table twin")
    assert table.state is not twin.state
    twin.state.set_actuator("FHA-25C-100-US250")
    twin.state.set_load_inertia(2.0)
    assert (table.actuator_code, table.load_inertia_kgm2) == ("FHA-25C-50-US250-L", 1.5)
    assert (twin.actuator_code, twin.load_inertia_kgm2, twin.state.ratio) == ("FHA-25C-100-US250", 2.0, 100)
    assert project.axis("tilt").state.actuator.brake is not None
    with pytest.raises(MachineError, match="already has an axis called 'tilt'"):
        project.add_axis("tilt")
    with pytest.raises(ModelCodeError):
        project.add_axis("roll", "FHA-26C-50-US250")
    with pytest.raises(MachineError, match="axis 'roll': port /dev/ttyUSB2 is already axis 'tilt''s"):
        project.add_axis("roll", "FHA-17C-50-US250", port_url="/dev/ttyUSB2")
    assert [a.name for a in project] == ["table", "table twin", "tilt"]  # nothing half-added
    with pytest.raises(MachineError, match=r"has no axis 'roll' \(axes: table, table twin, tilt\)"):
        project.axis("roll")
    project.add_axis("roll", "FHA-17C-50-US250", port_url="sim://FHA-25C-50-US250-L")  # a sim each time


def test_the_project_file_round_trips_and_a_wrong_one_is_refused(tmp_path):
    project = _positioner()
    path = project.save(tmp_path / "positioner.fha-machine.json")
    again = MachineProject.load(path)
    assert again.to_json() == project.to_json()
    assert again.axis("tilt").state.actuator_code == "FHA-32C-100-S248-B"
    data = json.loads(path.read_text())
    data["axes"][1]["actuator_code"] = "FHA-99"
    path.write_text(json.dumps(data))
    with pytest.raises(MachineError, match=r"positioner\.fha-machine\.json: axis 2: model code 'FHA-99'"):
        MachineProject.load(path)
    path.write_text("{")
    with pytest.raises(MachineError, match="not a readable machine file"):
        MachineProject.load(path)


def test_the_project_goes_into_the_register_and_comes_back(register):
    project = _positioner()
    project.save_to(register, who="ana")
    assert [a.ref for a in register.axes()] == [
        "Line 3 positioner/table",
        "Line 3 positioner/table twin",
        "Line 3 positioner/tilt",
    ]
    project.axis("tilt").state.set_load_inertia(4.5)
    project.save_to(register, who="ben")
    tilt_history = register.history("Line 3 positioner/tilt")
    assert tilt_history[-1].text == "load inertia: 4 kg·m² → 4.5 kg·m²" and tilt_history[-1].who == "ben"
    back = MachineProject.from_register(register, "Line 3 positioner")
    assert back.to_json() == project.to_json()
    # an axis added on the command line, without a load inertia: opening and saving changes nothing
    register.add_axis("Line 3 positioner", "roll", "FHA-17C-50-US250")
    before = len(register.history("Line 3 positioner/roll"))
    MachineProject.from_register(register, "Line 3 positioner").save_to(register)
    assert len(register.history("Line 3 positioner/roll")) == before


def _finished_session(code: str, axis: str, path, who="T. Trainee") -> ProcedureSession:
    session = ProcedureSession(actuator_code=code, axis=axis, operator=who, site="Plant A")
    session.driver = {"model": "HA-655-2-200", "adjusted_for": code, "version": "sim"}
    session.save(path)
    context = build_context(code)
    for procedure_id in (
        "receiving-inspection",
        "installation",
        "wiring",
        "sensor-adjustment",
        "rotary-direction",
    ):
        procedure = load_procedure(procedure_id, context)
        if procedure.applies:
            walk(ProcedureRun(session, procedure), who=who)
    return session


def test_machine_report_summarises_every_axis_then_each_report(register, tmp_path):
    project = _positioner()
    project.save_to(register)
    table = _finished_session("FHA-25C-50-US250-L", "table", tmp_path / "table.json")
    sign(table, "T. Trainee")
    twin = ProcedureSession(actuator_code="FHA-25C-50-US250-L", axis="table twin", operator="ben")
    run = ProcedureRun(
        twin, load_procedure("receiving-inspection", build_context(twin.actuator_code)), autosave=False
    )
    run.submit(True, who="ben")
    run.submit("FHA-17C-50-US250", who="ben")  # the wrong label: fails
    twin.save(tmp_path / "twin.json")
    project.axis("table twin").session_file = tmp_path / "twin.json"
    project.axis("table").state.record_read({("system", 8): 1})
    register.record_origin("Line 3 positioner/tilt", "multi-turn data cleared (OWW) at +0.00°", who="ana")
    report = build_machine_report(project, {"table": table}, register=register)
    rows = {s.axis: s for s in report.summaries}
    assert rows["table"].direction == "1: FWD command → REV rotation"
    assert rows["table"].origin == "origin sensor at +0.00° (4-7-2)"
    assert rows["table"].checks_failed == 0 and rows["table"].checks_passed > 20
    assert rows["table"].is_signed and rows["table"].signed.startswith("signed by T. Trainee")
    assert (rows["table twin"].checks_passed, rows["table twin"].checks_failed) == (1, 1)
    assert rows["table twin"].signed == "not signed" and rows["table twin"].direction == "not known"
    assert rows["tilt"].origin.startswith("multi-turn data cleared (OWW) at +0.00° (")
    assert (rows["tilt"].checks_passed, rows["tilt"].actuator) == (0, "FHA-32C-100-S248-B")
    assert report.axis_reports[2] is None
    assert direction_text(0) == "0: FWD command → FWD rotation (default)"
    html = render_machine_html(report)
    summary = html[: html.index("Axis table</h1>")]
    for text in ("Machine report — Line 3 positioner", "Plant A, hall 2", "FHA-32C-100-S248-B", "not signed"):
        assert text in summary
    # then each axis's own report, in order
    assert html.index("Axis table</h1>") < html.index("Axis table twin</h1>") < html.index("Axis tilt</h1>")
    assert "Commissioning report — table — FHA-25C-50-US250-L" in html
    assert "Signed by T. Trainee" in html
    assert "No procedure session for this axis yet" in html[html.index("Axis tilt</h1>") :]
    assert html.count("<html>") == 1 and html.count("</body>") == 1
