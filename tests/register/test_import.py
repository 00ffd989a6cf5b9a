"""Session files (fha-session/1) and parameter files (fha-parameters/1) into the register: what
they hold arrives once, however often they are imported; a wrong file is refused whole."""

from __future__ import annotations

import datetime as dt

import pytest

from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.paramfile import dump_parameter_file
from fha_studio.logic.procedures import ProcedureRun, ProcedureSession, load_procedure
from fha_studio.logic.procedures.context import build_context
from fha_studio.logic.register import RegisterError, import_parameter_file, import_session_file
from tests.procedures.walk import walk

CODE = "FHA-25C-50-US250"


def _session(path, operator="T. Trainee"):
    session = ProcedureSession(actuator_code=CODE, axis="table", operator=operator, site="Plant A")
    session.driver = {"model": "HA-655-2-200", "adjusted_for": CODE, "version": "sim 1"}
    session.parameters = {
        "values": {"rotary_direction": 1, "in_position_range": 20},
        "read_utc": "2026-11-29T10:00:00+00:00",
    }
    session.save(path)
    context = build_context(CODE)
    walk(ProcedureRun(session, load_procedure("receiving-inspection", context)), who=operator)
    return session


def test_a_session_file_arrives_once(register, tmp_path):
    path = tmp_path / "table.fha-session.json"
    session = _session(path)
    n_records = len(session.runs["receiving-inspection"].records)
    first = import_session_file(register, path, "Line 3")
    assert first.axis.ref == "Line 3/table"
    assert (first.axis.actuator_code, first.axis.driver_model) == (CODE, "HA-655-2-200")
    assert first.checks_added == n_records > 3
    assert first.snapshot is not None
    status = {r["procedure_id"]: r["status"] for r in register.procedure_status("Line 3/table")}
    assert status["receiving-inspection"] == "completed"
    assert status["installation"] == "not_started"
    assert status["sensor-adjustment"] == "not applicable"  # no option L on this actuator
    values = register.current_values("Line 3/table").values
    assert (values["rotary_direction"].value, values["in_position_range"].value) == (1, 20)
    assert values["rotary_direction"].at_utc == "2026-11-29T10:00:00.000000+00:00"
    checks = [e for e in register.history("Line 3/table") if e.kind == "check"]
    assert len(checks) == n_records and all(e.who == "T. Trainee" for e in checks)
    again = import_session_file(register, path, "Line 3")  # nothing new
    assert (again.checks_added, again.snapshot) == (0, None)
    assert len(register.snapshots("Line 3/table")) == 1
    assert "Location and installation (3-3): not started" in {i.text for i in register.open_items("Line 3")}


def test_a_session_for_another_actuator_is_refused(register, tmp_path):
    path = tmp_path / "s.json"
    _session(path)
    register.add_machine("Line 3")
    register.add_axis("Line 3", "table", "FHA-32C-100-US250")
    with pytest.raises(
        RegisterError, match="a session for FHA-25C-50-US250, but axis Line 3/table has FHA-32C-100"
    ):
        import_session_file(register, path, "Line 3")
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "something-else"}')
    with pytest.raises(RegisterError, match="not an fha-session/1 session file"):
        import_session_file(register, bad, "Line 3")
    assert register.history("Line 3/table")[-1].kind == "axis"  # nothing recorded


def test_a_parameter_file_becomes_a_snapshot_at_its_saved_time(register, tmp_path):
    model = load_parameter_model("HA-655")
    item = model.by_key("rotary_direction")
    gain = model.by_key("position_loop_gain")
    saved = dt.datetime(2026, 11, 28, 15, 30, tzinfo=dt.UTC)
    text = dump_parameter_file(
        model, {(item.mode, item.number): 1, (gain.mode, gain.number): 55}, CODE, "HA-655-2-200", saved
    )
    text += "\n[tune]\n" if "[tune]" not in text else ""
    path = tmp_path / "tilt.toml"
    path.write_text(text.replace("[system]", "[system]\nno_such_item = 3"), encoding="utf-8")
    result = import_parameter_file(register, path, "Line 3", "tilt", who="ana")
    assert result.axis.ref == "Line 3/tilt" and result.snapshot is not None
    assert any("no_such_item" in line for line in result.not_taken)
    snapshot = register.snapshot(result.snapshot)
    assert {k: v.value for k, v in snapshot.values.items()} == {
        "rotary_direction": 1,
        "position_loop_gain": 55,
    }
    assert snapshot.values["rotary_direction"].at_utc == "2026-11-28T15:30:00.000000+00:00"
    assert [f.axis.name for f in register.find("rotary_direction", 1)] == ["tilt"]
    assert import_parameter_file(register, path, "Line 3", "tilt").snapshot is None  # once
    broken = tmp_path / "broken.toml"
    broken.write_text('format = "fha-parameters/1"\n[system]\nrotary_direction = "one"\n')
    with pytest.raises(RegisterError, match=r"broken\.toml: line 3: system\.rotary_direction"):
        import_parameter_file(register, broken, "Line 3", "tilt")
    assert len(register.snapshots("Line 3/tilt")) == 1


def test_a_refused_import_leaves_no_machine_or_axis_behind(register, tmp_path):
    path = tmp_path / "empty.toml"
    path.write_text(
        'format = "fha-parameters/1"\nactuator = "FHA-25C-50-US250"\n[system]\nno_such_item = 1\n'
    )
    with pytest.raises(RegisterError, match="no value in it fits HA-655"):
        import_parameter_file(register, path, "Line 9", "roll")
    assert register.machines() == []


def test_a_batch_is_committed_whole_or_not_at_all(register):
    register.add_machine("m")
    register.add_axis("m", "a")
    with pytest.raises(RuntimeError), register.batch():
        register.record_alarm("m/a", 20, "Deviation counter overflow")
        register.record_snapshot("m/a", [("system", 8, "rotary_direction", 1)], "link")
        raise RuntimeError("the power went")
    assert [e.kind for e in register.history("m/a")] == ["axis"]
    with register.batch():
        register.record_alarm("m/a", 20)
        register.record_alarm("m/a", 60)
    assert [e.kind for e in register.history("m/a")] == ["axis", "alarm", "alarm"]
