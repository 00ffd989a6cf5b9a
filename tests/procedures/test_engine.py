"""The procedure engine walks every procedure headless, stops on a failed check, resumes from a file."""

from __future__ import annotations

import json

import pytest

from fha_studio.logic.procedures import (
    Observation,
    ProcedureError,
    ProcedureRun,
    ProcedureSession,
    SessionError,
    StepInputError,
    load_all,
    load_procedure,
)
from fha_studio.logic.procedures.definitions import procedure_files
from tests.procedures.walk import good_answer, walk

PROCEDURES = ["receiving-inspection", "installation", "wiring", "sensor-adjustment", "rotary-direction"]


def test_every_procedure_file_loads(context):
    loaded = load_all(context)
    assert [p.id for p in loaded] == PROCEDURES
    assert len(procedure_files()) == len(PROCEDURES)
    for procedure in loaded:
        assert procedure.section and procedure.steps
        for step in procedure.steps:
            assert step.raw["section"], (procedure.id, step.id)


@pytest.mark.parametrize("procedure_id", PROCEDURES)
def test_walk_each_procedure_to_the_end(context, tmp_path, procedure_id):
    session = ProcedureSession(actuator_code=context["actuator"]["model_code"], operator="T. Trainee")
    session.save(tmp_path / "axis1.json")
    run = ProcedureRun(session, load_procedure(procedure_id, context))
    answered = walk(run)
    assert run.completed and run.current() is None
    saved = json.loads((tmp_path / "axis1.json").read_text())
    records = saved["runs"][procedure_id]["records"]
    assert [r["step_id"] for r in records] == answered
    assert all(r["who"] == "T. Trainee" and r["passed"] and r["at_utc"].endswith("+00:00") for r in records)


def test_values_come_from_the_actuator(context):
    procedure = load_procedure("installation", context)
    step = procedure.step("output-flange-torque").resolve(context, {})
    assert (step.minimum, step.maximum, step.unit) == (10.8, 13.2, "N·m")
    assert "8-M6 depth: 10" in step.text and "12 N·m (120 kgf·cm)" in step.warning
    wiring = load_procedure("wiring", context)
    leads = [s for s in wiring.steps if s.id.startswith("motor-lead.")]
    assert len(leads) == 7
    assert "the Blue lead goes to Brake" in leads[4].resolve(context, {}).text
    supply = wiring.step("brake-supply-voltage").resolve(context, {})
    assert (supply.minimum, supply.maximum) == (21.6, 26.4)


def test_options_choose_the_steps(make_context):
    plain = make_context(brake=False, absolute=False, sensor_set=False)
    wiring = load_procedure("wiring", plain)
    assert not any(s.id.startswith("brake") for s in wiring.steps)
    assert not any(s.id.startswith("encoder-lead-abs") for s in wiring.steps)
    assert not load_procedure("sensor-adjustment", plain).applies
    with pytest.raises(ProcedureError, match="does not apply"):
        ProcedureRun(ProcedureSession(actuator_code="FHA-25C-50-US250"),
                     load_procedure("sensor-adjustment", plain))
    absolute = make_context(brake=False, absolute=True, sensor_set=False)
    ids = load_procedure("wiring", absolute).step_ids()
    assert "encoder-lead-abs.1" in ids and "absolute-battery" in ids and "encoder-leads" not in ids


def test_an_answer_chooses_the_encoder_table(context):
    run = ProcedureRun(ProcedureSession(actuator_code="x"), load_procedure("wiring", context), autosave=False)
    seen = []
    while (step := run.current()) is not None:
        seen.append(step.id)
        run.submit("4" if step.id == "encoder-leads" else good_answer(step))
    assert "encoder-lead-4.1" in seen and not any(s.startswith("encoder-lead-14") for s in seen)


def test_a_mismatch_stops_with_the_manuals_warning_and_retry_goes_on(context, tmp_path):
    session = ProcedureSession(actuator_code=context["actuator"]["model_code"], operator="T. Trainee")
    session.save(tmp_path / "s.json")
    run = ProcedureRun(session, load_procedure("receiving-inspection", context))
    run.submit(True)
    run.submit("fha 25c-50-us250-b-l")  # case, spaces and dashes do not matter
    record = run.submit("FHA-32C-50-US250")  # the driver was adjusted for another actuator
    assert not record.passed and run.stopped
    assert run.state.stop_step_id == "driver-adjusted-for"
    assert "Only connect the actuator specified on the driver label" in run.state.stop_warning
    with pytest.raises(StepInputError, match="stopped"):
        run.submit("FHA-25C-50-US250-B-L")
    # nothing goes on until someone says the cause was put right
    run.retry(who="Supervisor", note="driver swapped for the right one")
    assert run.submit("FHA-25C-50-US250-B-L").passed
    assert run.submit("HA-655-4-200").passed is False  # not in the combination table for 25C at 200 V
    assert "1-3" in run.state.stop_warning
    run.retry()
    run.submit("HA-655-2-200")
    assert run.submit("100").passed is False  # site supplies 100 V to a 200 V driver
    assert "Do not connect a supply voltage other than" in run.state.stop_warning
    saved = ProcedureSession.load(tmp_path / "s.json")
    failed = [r for r in saved.runs["receiving-inspection"].records if not r.passed]
    assert [r.step_id for r in failed] == ["driver-adjusted-for", "driver-type-label", "site-supply-voltage"]
    assert any("retried" in n["text"] and n["who"] == "Supervisor" for n in saved.notes)


def test_a_measured_value_outside_its_limits_fails(context):
    run = ProcedureRun(ProcedureSession(actuator_code="x"), load_procedure("installation", context),
                       autosave=False)
    record = run.submit("41,5")  # comma decimal accepted
    assert record.value == 41.5 and not record.passed and record.unit == "°C"
    assert "less than 40 °C" in run.state.stop_warning


def test_bad_input_records_nothing(context):
    run = ProcedureRun(ProcedureSession(actuator_code="x"), load_procedure("installation", context),
                       autosave=False)
    for bad in ("warm", "nan", True, ""):
        with pytest.raises(StepInputError):
            run.submit(bad)
    assert run.state.records == []
    for value in (20, 50, 10, 100):
        assert run.submit(value).passed
    assert run.current().kind == "confirm"
    with pytest.raises(StepInputError, match="yes or no"):
        run.submit("yes")


def test_pause_and_resume_after_a_restart(context, tmp_path):
    path = tmp_path / "axis1.json"
    session = ProcedureSession(actuator_code=context["actuator"]["model_code"], operator="A")
    session.save(path)
    run = ProcedureRun(session, load_procedure("wiring", context))
    for _ in range(5):
        run.submit(good_answer(run.current()), who="A")
    here = run.current().id
    run.pause()
    assert ProcedureSession.load(path).runs["wiring"].status == "paused"
    del run, session  # "restart"
    resumed = ProcedureRun(ProcedureSession.load(path), load_procedure("wiring", context))
    assert resumed.current().id == here and resumed.state.status == "running"
    walk(resumed, who="B")
    final = ProcedureSession.load(path).runs["wiring"]
    assert final.status == "completed"
    assert {r.who for r in final.records} == {"A", "B"}


def test_resume_refuses_a_changed_procedure(context, tmp_path, make_context):
    session = ProcedureSession(actuator_code="x")
    run = ProcedureRun(session, load_procedure("wiring", context), autosave=False)
    run.submit(True)
    other = load_procedure("wiring", make_context(brake=False))
    with pytest.raises(ProcedureError, match="changed since"):
        ProcedureRun(session, other)


def test_sensor_angles_are_checked_against_the_movable_range(context):
    session = ProcedureSession(actuator_code="x")
    run = ProcedureRun(session, load_procedure("sensor-adjustment", context), autosave=False)
    run.submit(True)
    run.submit(True)
    record = run.submit(179.0)  # limit switch 2 beyond the movable range
    assert not record.passed and "movable range" in record.detail
    run.retry()
    assert run.submit(140.0).passed
    assert not run.submit(150.0).passed  # limit switch 1 must be CCW of limit switch 2
    run.retry()
    assert run.submit(-140.0).passed
    assert not run.submit(Observation(160.0, True)).passed  # origin outside the stroke
    run.retry()
    assert run.submit(Observation(2.5, True, "origin seen")).passed
    assert session.sensor_angles_deg == {
        "limit_switch_2": 140.0,
        "limit_switch_1": -140.0,
        "origin_sensor": 2.5,
    }


def test_bad_procedure_data_is_named(tmp_path, context):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        '[procedure]\nid="b"\ntitle="B"\n[[step]]\nid="s"\nkind="measure"\nsection="1"\n'
        'text="x"\nminimum="{tightening.nowhere.torque_nm}"\n'
    )
    with pytest.raises(ProcedureError, match=r"bad.toml: step 's': '\{tightening.nowhere.torque_nm\}'"):
        load_procedure(bad, context)
    bad.write_text('[procedure]\nid="b"\ntitle="B"\n[[step]]\nid="s"\nkind="guess"\nsection="1"\ntext="x"\n')
    with pytest.raises(ProcedureError, match="kind 'guess'"):
        load_procedure(bad, context)
    bad.write_text("not toml [")
    with pytest.raises(ProcedureError, match="not valid TOML"):
        load_procedure(bad, context)
    with pytest.raises(ProcedureError, match="no procedure 'nope'; known: "):
        load_procedure("nope", context)


def test_session_file_errors_name_the_file(tmp_path):
    path = tmp_path / "x.json"
    path.write_text("{}")
    with pytest.raises(SessionError, match=r"x\.json: not an fha-session/1"):
        ProcedureSession.load(path)
    with pytest.raises(SessionError, match="no such session"):
        ProcedureSession.load(tmp_path / "none.json")


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"runs": [1]}, 'field runs: must be a table of procedure runs by procedure id, got a list'),
        ({"notes": "x"}, "field notes: must be a list of tables (who, at_utc, text), got the text 'x'"),
        ({"signature": "me"}, "field signature: must be a table of texts (who, at_utc), got the text 'me'"),
        ({"driver": [1]}, "field driver: must be a table of texts, got a list"),
        ({"actuator_code": 5}, "field actuator_code: must be text, got the number 5"),
        ({"actuator_code": "FHA-99C-50-US250"}, "field actuator_code: "),
        ({"runs": {"p": {"procedure_id": "p", "records": [{"passed": "yes"}]}}}, "field runs.p.records[0]."),
        ({"runs": {"p": {"procedure_id": "p", "status": "flying"}}}, "field runs.p.status: is the text"),
        ({"runs": {"p": {"procedure_id": "p", "position": 7}}}, "field runs.p.position: must be a whole"),
        ({"sensor_angles_deg": {"origin_sensor": 1e308}}, "outside -360 ... 360 deg"),
        ({"colour": "red"}, "field colour: unknown; allowed:"),
        # a line break or escape sequence in the file stays escaped: the refusal is one line
        ({"notes": "a\nb\x1b[2J"}, "got the text 'a\\nb\\x1b[2J'"),
    ],
)
def test_a_session_file_of_the_wrong_shape_is_refused_naming_the_field(tmp_path, change, words):
    import json

    good = ProcedureSession(actuator_code="FHA-25C-50-US250", operator="me")
    path = good.save(tmp_path / "s.json")
    assert ProcedureSession.load(path).actuator_code == "FHA-25C-50-US250"
    data = json.loads(path.read_text())
    data.update(change)
    path.write_text(json.dumps(data))
    with pytest.raises(SessionError) as err:
        ProcedureSession.load(path)
    message = str(err.value)
    assert message.startswith(f"{path}: ") and words in message and "\n" not in message


def test_only_regular_files_are_read_as_sessions(tmp_path):
    import os

    os.mkfifo(tmp_path / "fifo.json")
    for path, words in ((tmp_path / "fifo.json", "FIFO"), ("/dev/full", "character device"),
                        ("/dev/zero", "character device"), (tmp_path / ("x" * 300), "too long")):
        with pytest.raises(SessionError, match=words):
            ProcedureSession.load(path)


def test_a_session_that_cannot_be_written_leaves_the_old_file_whole(tmp_path):
    import os

    from fha_studio.fileio import FileProblem

    session = ProcedureSession(actuator_code="FHA-25C-50-US250")
    path = session.save(tmp_path / "s.json")
    before = path.read_text()
    session.operator = "someone else"
    (tmp_path / "afile").write_text("")
    os.mkfifo(tmp_path / "device")  # stands for /dev/full: a rename over it would harm nothing
    for target, words in ((tmp_path / "device", "not a regular file"),
                          (tmp_path / "afile" / "s.json", "not a directory")):
        with pytest.raises(FileProblem, match=words):
            session.save(target)
    assert path.read_text() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "device", "s.json"]
