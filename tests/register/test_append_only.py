"""History that nobody rewrites, on both stores: the database refuses to change or remove a fact,
whoever asks (on the server its owner too; the roles of people are tests/register/test_roles.py);
a mistake is corrected by a new fact that points at the one it corrects."""

from __future__ import annotations

import contextlib
import datetime
import json
import sqlite3

import psycopg
import pytest

from fha_studio import clock
from fha_studio.logic.register import Register, RegisterError
from fha_studio.logic.register.schema import ENTITY_TABLES, FACT_TABLES, REGISTER_TABLES
from fha_studio.logic.register.server import is_server_url, problem

TABLE = "Line 3 positioner/table"


@contextlib.contextmanager
def _raw(target):
    """The register's database opened by another program (no FHA Studio in between)."""
    if is_server_url(target):
        with psycopg.connect(target, autocommit=True) as db:
            yield db
    else:
        db = sqlite3.connect(target, isolation_level=None)
        try:
            yield db
        finally:
            db.close()


def _refused(db, sql):
    """The database's own refusal of ``sql`` (its first line)."""
    with pytest.raises((sqlite3.IntegrityError, psycopg.Error)) as refused:
        db.execute(sql)
    return str(refused.value).splitlines()[0]


def test_every_table_is_a_fact_or_what_facts_are_about(tmp_path):
    with Register(tmp_path / "r.sqlite") as reg:
        tables = {r[0] for r in reg._db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
    # a new table is classified: a fact is protected, and on a server with roles a technician adds it
    assert tables == set(FACT_TABLES) | set(ENTITY_TABLES) | set(REGISTER_TABLES)


def test_no_program_changes_or_removes_a_fact(line3, register_target):
    line3.record_snapshot(TABLE, [("system", 8, "rotary_direction", 1)], "link", who="ana")
    line3.record_write(TABLE, "system", 8, "rotary_direction", 0, 1, 0, True, who="ana")
    line3.record_alarm(TABLE, 10, "overspeed")
    line3.record_procedure_status(TABLE, "wiring", "Wiring", "running")
    with _raw(register_target) as db:
        said = _refused(db, "UPDATE parameter_write SET new = 5")
        assert said.startswith("append-only: parameter writes are never changed or removed")
        assert _refused(db, "DELETE FROM snapshot_value").startswith("append-only: snapshot values")
        assert _refused(db, "UPDATE snapshot SET at_utc = '2020-01-01T00:00:00.000000+00:00'").startswith(
            "append-only: parameter snapshots")  # back-dated: refused as any change is
        assert _refused(db, "DELETE FROM alarm").startswith("append-only: alarms")
        assert _refused(db, "UPDATE procedure_run SET status = 'completed'").startswith(
            "append-only: procedure states")
        assert _refused(db, "DELETE FROM axis_event").startswith("append-only: axis history entries")
        assert "never removed" in _refused(db, "DELETE FROM axis WHERE name = 'tilt'")
        if is_server_url(register_target):
            assert _refused(db, "TRUNCATE alarm").startswith("append-only: alarms")
    history = [e.kind.value for e in line3.history(TABLE)]
    assert history == ["axis", "snapshot", "write", "alarm"]  # all there, as recorded
    line3.update_axis(TABLE, who="ben", serial_number="S-1")  # an axis is changed, in its history
    assert line3.history(TABLE)[-1].text == "serial number: not given → S-1"


def test_the_refusal_is_one_line_naming_the_register(register_target):
    with Register(register_target) as reg, _raw(register_target) as db:
        reg.add_machine("Press 7")
        reg.add_axis("Press 7", "ram")
        with pytest.raises((sqlite3.IntegrityError, psycopg.Error)) as refused:
            db.execute("DELETE FROM axis_event")
        said = str(reg._problem(refused.value))  # the database's refusal as the register tells it
    assert said.startswith("the register ") and "\n" not in said
    assert said.endswith("its history is append-only: axis history entries are never changed or removed "
                         "(a mistake is corrected by a new fact that points at it): nothing was changed")
    server = problem("postgresql://x@h/db", psycopg.errors.RaiseException(
        "append-only: alarms are never changed or removed (...)\nCONTEXT: PL/pgSQL function"))
    assert "its history is append-only: alarms" in str(server) and "\n" not in str(server)


def test_a_correction_is_a_new_fact_pointing_at_the_one_it_corrects(line3):
    # read from the panel an hour ago and corrected 5 min later; the notes below are stamped now
    wrong = line3.record_snapshot(TABLE, [("tune", 4, "in_position_range", 100)], "front_panel", who="ana",
                                  at_utc=_ago(minutes=60))
    right = line3.record_snapshot(TABLE, [("tune", 4, "in_position_range", 10)], "front_panel", who="ana",
                                  note="read 100 for 10", corrects=wrong, at_utc=_ago(minutes=55))
    lines = {e.ref: e for e in line3.history(TABLE) if e.kind == "snapshot"}
    assert lines[wrong].text.endswith(f"— corrected by snapshot {right}")
    assert lines[wrong].data["corrected_by"] == [right]
    assert lines[right].text.endswith(f"— corrects snapshot {wrong}")
    assert lines[right].data["corrects"] == wrong
    assert line3.current_values(TABLE).values["in_position_range"].value == 10  # the newest counts
    assert line3.snapshot(wrong).values["in_position_range"].value == 100  # the wrong one stays, as it was
    note = line3.add_axis_note(TABLE, "brake wired to CN1-5", who="ana")
    line3.add_axis_note(TABLE, "brake wired to CN1-6", who="ana", corrects=note)
    assert line3.history(TABLE)[-1].text == f"note: brake wired to CN1-6 — corrects axis entry {note}"
    other = line3.record_alarm("Line 3 positioner/tilt", 10, "overspeed")
    with pytest.raises(RegisterError, match=r"alarm \d+ is not one of 'Line 3 positioner/table''s"):
        line3.record_alarm(TABLE, 11, "overload", corrects=other)
    with pytest.raises(RegisterError, match="there is no write number 999 in the register to correct"):
        line3.record_write(TABLE, "system", 8, "rotary_direction", 0, corrects=999)
    with pytest.raises(RegisterError, match="a correction names the number of the check"):
        line3.record_checks(TABLE, [_Check(corrects="12")])


def _ago(minutes: float) -> str:
    """A moment before now by the one clock the register stamps with (never a calendar date: a
    fixed date is in the future when the suite runs with the calendar moved back)."""
    return (clock.now_utc() - datetime.timedelta(minutes=minutes)).isoformat()


class _Check:
    procedure_id, step_id, kind, section, text = "wiring", "w1", "confirm", "1-14", "Motor wired"
    value, expected, unit, passed, who, detail = True, "", "", True, "ana", ""

    def __init__(self, corrects=None):
        self.corrects = corrects
        self.at_utc = _ago(minutes=30)  # checked before it is corrected


def test_where_a_procedure_stands_is_a_row_each_time_it_moves_on(line3, register_target):
    for status in ("running", "running", "paused", "completed"):
        line3.record_procedure_status(TABLE, "wiring", "Wiring", status, "1-14")
    line3.record_procedure_status(TABLE, "installation", "Installation", "running", "3-3")
    assert [(r["procedure_id"], r["status"]) for r in line3.procedure_status(TABLE)] == [
        ("wiring", "completed"), ("installation", "running")]
    with _raw(register_target) as db:
        rows = db.execute(
            "SELECT status FROM procedure_run WHERE procedure_id = 'wiring' ORDER BY id").fetchall()
    assert [r[0] for r in rows] == ["running", "paused", "completed"]  # the same state twice is one row


def _cli(capsys, target, *args):
    from fha_studio.cli import main

    code = main(["register", "--register", str(target), *args])
    out, err = capsys.readouterr()
    return code, out, err


def test_a_person_corrects_a_mistake_on_the_command_line(line3, register_target, capsys):
    read = [("tune", 4, "in_position_range", 100), ("system", 8, "rotary_direction", 1)]
    wrong = line3.record_snapshot(TABLE, read, "front_panel", who="ana")
    check = _Check()
    line3.record_checks(TABLE, [check])
    note = line3.add_axis_note(TABLE, "brake wired to CN1-5", who="ana")
    code, out, _ = _cli(capsys, register_target, "correct", "snapshot", str(wrong), "--set",
                        "in_position_range=10", "--reason", "read 100 for 10", "--operator", "ana")
    assert code == 0 and out.startswith(f"{TABLE}: snapshot ") and f"corrects snapshot {wrong}" in out
    assert "(in_position_range: 100 → 10)" in out
    values = line3.current_values(TABLE).values
    assert (values["in_position_range"].value, values["rotary_direction"].value) == (10, 1)
    check_ref = next(e.ref for e in line3.history(TABLE) if e.kind == "check")
    code, out, _ = _cli(capsys, register_target, "correct", "check", str(check_ref), "--passed", "no",
                        "--reason", "the motor was wired to U and W swapped", "--json")
    assert code == 0 and json.loads(out)["what"] == "pass → FAIL"
    assert [i.text for i in line3.open_items() if i.axis.ref == TABLE and "Motor wired" in i.text]
    code, _, _ = _cli(capsys, register_target, "correct", "note", str(note), "--text", "brake wired to CN1-6")
    assert code == 0
    code, out, _ = _cli(capsys, register_target, "history", TABLE, "--numbers")
    assert code == 0 and f"{note:>6}  axis" in out and f"— corrected by axis entry {note + 1}" in out
    assert "— corrects check" in out and f"corrected by snapshot {wrong + 1}" in out
    for args, said in (
        (("snapshot", str(wrong), "--set", "no_such=1", "--reason", "x"), "holds no no_such"),
        (("snapshot", str(wrong), "--set", "in_position_range=10"), "a correction says why (--reason)"),
        (("snapshot", str(wrong), "--set", "in_position_range=ten", "--reason", "x"), "KEY=VALUE expected"),
        (("check", str(check_ref), "--reason", "x"), "a corrected check needs its right answer"),
        (("note", "999", "--text", "x"), "there is no note number 999 in the register"),
        (("note", str(note), "--set", "in_position_range=1"), "--set corrects a snapshot's values"),
    ):
        code, _, err = _cli(capsys, register_target, "correct", *args)
        assert code == 2 and err.count("\n") == 1 and said in err, (args, err)
    assert len(line3.snapshots(TABLE)) == 2  # nothing half-done by the refusals
