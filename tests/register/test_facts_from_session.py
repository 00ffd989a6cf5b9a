"""Which event of a commissioning session becomes which register fact, without Qt: each kind of
DGR check, a parameter read and write, an alarm, front-panel entries, a report, a model check,
written into a real register file."""

from __future__ import annotations

import typing
from dataclasses import dataclass

import pytest

from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.absolute import DgrCheckRecord
from fha_studio.logic.procedures import ProcedureSession
from fha_studio.logic.register import facts_from_session as f

AXIS = "Line 3 positioner/table"
AT = "2026-12-04T01:02:03+01:00"


def _record(register, facts):
    for fact in facts:
        f.record_fact(register, AXIS, fact)


def _dgr(check, values, passed=True, by_hand=False, detail="ok"):
    return DgrCheckRecord(check, "ana", AT, values, passed, detail, by_hand)


def test_every_kind_of_fact_has_its_writer():
    assert set(typing.get_args(f.Fact)) == set(f.WRITERS)


def test_an_absolute_origin_is_a_check_and_the_axis_origin(line3):
    facts = f.facts_from_dgr_check(_dgr("absolute_origin", {"position_deg": 0.01}))
    assert [type(x) for x in facts] == [f.CheckFact, f.OriginFact]
    check = facts[0].record
    assert (check.procedure_id, check.step_id, check.text, check.passed) == (
        "dgr-checks", "absolute_origin", "Absolute origin (OWW)", True
    )
    _record(line3, facts)
    origin = line3.latest_origin(AXIS)
    assert origin["text"] == "absolute origin set (OWW), read back at +0.01°" and origin["who"] == "ana"
    assert origin["at_utc"].startswith("2026-12-04T00:02:03")
    assert line3.check_counts(AXIS) == (1, 0)


def test_a_failed_origin_is_a_failed_check_and_no_origin(line3):
    facts = f.facts_from_dgr_check(_dgr("absolute_origin", {}, passed=False, detail="OWW refused"))
    assert [type(x) for x in facts] == [f.CheckFact]
    _record(line3, facts)
    assert line3.latest_origin(AXIS) is None and line3.check_counts(AXIS) == (0, 1)


def test_the_origin_sensor_angle_is_the_origin_another_sensor_is_not():
    origin = f.facts_from_dgr_check(_dgr("sensor_dog", {"sensor": "origin_sensor", "angle_deg": 1.25}))
    assert origin[-1] == f.OriginFact("origin sensor at +1.25° (4-7-2)", "ana", AT)
    limit = f.facts_from_dgr_check(_dgr("sensor_dog", {"sensor": "limit_switch_1", "angle_deg": 1.25}))
    assert [type(x) for x in limit] == [f.CheckFact]


def test_a_rotary_direction_check_enters_parameter_8_from_the_front_panel(line3):
    facts = f.facts_from_dgr_check(_dgr("rotary_direction", {"rotary_direction": 1}, by_hand=True))
    check, panel = facts
    assert check.record.text == "Rotary direction (1-10) (given by hand)"
    assert panel.rows == (("system", 8, "rotary_direction", 1),) and panel.what == "front-panel value"
    _record(line3, facts)
    (snapshot,) = line3.snapshots(AXIS)
    assert (snapshot["source"], snapshot["who"]) == ("front_panel", "ana")
    assert line3.current_values(AXIS).values["rotary_direction"].value == 1
    # a direction not given (a bool is no parameter value) enters nothing
    not_given = f.facts_from_dgr_check(_dgr("rotary_direction", {"rotary_direction": True}))
    assert [type(x) for x in not_given] == [f.CheckFact]


def test_a_check_without_a_verdict_is_a_note(line3):
    facts = f.facts_from_dgr_check(_dgr("encoder", {}, passed=None, detail="turned 90°, read 89.9°"))
    assert facts == [f.NoteFact("Encoder check (turned by hand): turned 90°, read 89.9°", "ana", AT, "check")]
    _record(line3, facts)
    assert any("turned 90°, read 89.9°" in e.text for e in line3.history(AXIS))
    assert line3.check_counts(AXIS) == (0, 0)


def test_reads_and_writes_name_their_items_and_keep_an_unknown_one():
    model = load_parameter_model()
    (read,) = f.read_facts(model, {("system", 8): 1, ("system", 99): 5}, "ana", "HA-655-2-200")
    assert read.rows == (("system", 8, "rotary_direction", 1), ("system", 99, "system_99", 5))
    assert (read.source, read.what, read.driver_model) == ("link", "parameter read", "HA-655-2-200")
    assert f.read_facts(model, {}, "ana") == []
    write = f.write_fact(model, {"mode": "tune", "number": 4, "new": 25, "old": 10, "read_back": 25,
                                 "verified": True}, "ana")
    assert (write.key, write.new, write.old, write.verified) == ("in_position_range", 25, 10, True)
    assert write.error == "" and write.what == "parameter write"


def test_an_alarm_is_named_by_the_drivers_table_and_no_alarm_is_no_fact(line3):
    assert f.alarm_facts(0, "HA-655", "ana") == []
    (alarm,) = f.alarm_facts(20, "HA-655", "ana")
    assert alarm.name and alarm.name != "unknown code"
    assert f.alarm_facts(4321, "HA-655", "ana")[0].name == "unknown code"
    _record(line3, [alarm])
    assert any(e.kind == "alarm" for e in line3.history(AXIS))


@dataclass(frozen=True)
class _Entry:
    mode: str
    number: int
    value: int
    who: str
    time: str


def test_front_panel_entries_are_one_snapshot_per_person_and_time_each_once():
    model = load_parameter_model()
    seen: set = set()
    entries = [
        _Entry("system", 8, 0, "ana", AT), _Entry("tune", 4, 10, "ana", AT), _Entry("system", 8, 1, "ben", AT)
    ]
    facts = f.front_panel_facts(model, entries, seen)
    assert [(x.who, len(x.rows)) for x in facts] == [("ana", 2), ("ben", 1)]
    assert all(x.source == "front_panel" and x.at_utc == AT for x in facts)
    assert f.front_panel_facts(model, entries, seen) == []  # recorded once


def test_a_report_is_its_pdf_with_signature_and_open_warnings(line3, tmp_path):
    session = ProcedureSession(actuator_code="FHA-25C-50-US250", operator="ana")
    html, pdf = tmp_path / "r.html", tmp_path / "r.pdf"
    html.write_text("<html></html>")
    pdf.write_bytes(b"%PDF-1.4\n")
    (report,) = f.report_facts(session, None, html, pdf, "ben")
    assert report.path == pdf and report.signed_by == "" and report.open_warnings > 0  # nothing done yet
    assert f.report_facts(session, None, html, None, "ben")[0].path == html
    _record(line3, [report])
    latest = line3.latest_report(AXIS)
    assert latest["file"] == str(pdf.resolve()) and latest["open_warnings"] == report.open_warnings


def test_a_model_check_is_its_first_three_summary_lines(line3):
    (fact,) = f.model_check_facts(["a", "b", "c", "d"], "/x/move.csv", "ana")
    assert (fact.summary, fact.recording_file) == ("a; b; c", "/x/move.csv")
    assert f.model_check_facts([], "", "ana")[0].summary == "model check run"
    _record(line3, [fact])
    assert any(e.kind == "model_check" for e in line3.history(AXIS))


def test_a_windows_axis_is_added_once_with_its_actuator_and_a_session_as_it_stood(register_file):
    """The single-axis window's facts: its axis (machine too) added before them and found after,
    the actuator declared later in its record, a session recorded as it was when handed over."""
    bench = "laptop-07 bench/FHA-25C-50-US250"
    axis = f.axis_fact({"actuator_code": "", "load_inertia_kgm2": None}, "ana")
    assert axis == f.AxisFact((), "ana")
    session = ProcedureSession(actuator_code="FHA-25C-50-US250", operator="ana")
    handed_over = f.session_fact(session)
    session.run("receiving-inspection").status = "completed"  # the page goes on with its own
    for fact in (axis, axis, f.ActuatorFact("FHA-25C-50-US250", "ben"), handed_over):
        f.record_fact(register_file, bench, fact)
    assert [a.name for a in register_file.axes("laptop-07 bench")] == ["FHA-25C-50-US250"]
    texts = [e.text for e in register_file.history(bench) if e.kind == "axis"]
    assert texts == ["axis added", "actuator: not given → FHA-25C-50-US250"]
    status = {r["procedure_id"]: r["status"] for r in register_file.procedure_status(bench)}
    assert status["receiving-inspection"] == "not_started"


def test_a_fact_the_register_cannot_take_raises_its_error(line3):
    from fha_studio.logic.register import RegisterError

    with pytest.raises(RegisterError):
        f.record_fact(line3, "Line 3 positioner/none", f.OriginFact("x", "ana"))


def test_every_kind_of_history_entry_has_its_word_and_its_place():
    """A new kind of register fact is told in the register dialog and ``fha-studio register
    history`` by its word, and facts of one moment in a fixed order: neither may be missing."""
    from fha_studio.logic.register.history import HISTORY_ORDER
    from fha_studio.logic.register.records import EventKind
    from fha_studio.logic.register.words import KIND_WORDS

    assert set(KIND_WORDS) == set(EventKind)
    assert sorted(HISTORY_ORDER) == sorted(EventKind)
