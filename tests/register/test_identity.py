"""Every fact has a stable id made where it is first recorded, and keeps where and when it was
recorded (schema 6), on both stores: what a sync between registers tells facts apart by."""

from __future__ import annotations

import json

from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.absolute import DgrCheckRecord
from fha_studio.logic.register import facts_from_session as f
from fha_studio.logic.register.identity import UID_TABLES, uid_hash

AXIS = "Line 3 positioner/table"
AT = "2026-12-04T01:02:03+01:00"


def test_every_fact_recorded_has_its_own_stable_id_and_says_where_it_was_recorded(line3, tmp_path):
    model = load_parameter_model()
    recording = tmp_path / "move.fha-recording"
    recording.write_text("{}")
    facts = [
        *f.read_facts(model, {("system", 8): 1, ("tune", 4): 10}, "ana", "HA-655-2-200"),
        f.write_fact(model, {"mode": "tune", "number": 4, "new": 25, "old": 10, "read_back": 25,
                             "verified": True}, "ana"),
        *f.alarm_facts(20, "HA-655", "ana"),
        *f.facts_from_dgr_check(
            DgrCheckRecord("absolute_origin", "ana", AT, {"position_deg": 0.0}, True, "ok")
        ),
        f.RecordingFact(recording, "a move", "ana"),
        *f.model_check_facts(["fits"], str(recording), "ana"),
        f.DriverFact("HA-655-2-200", "ana"),
    ]
    for fact in facts:
        f.record_fact(line3, AXIS, fact)
    rows = [
        (table, *r)
        for table in UID_TABLES
        for r in line3._db.execute(f"SELECT uid, recorded_in, recorded_utc, uid_hash FROM {table}")
    ]
    tables = {r[0] for r in rows}
    assert {"axis_event", "snapshot", "parameter_write", "check_result", "alarm", "recording",
            "model_check"} <= tables
    uids = [r[1] for r in rows]
    assert len(set(uids)) == len(uids) and all(len(u) == 36 for u in uids)
    assert {r[2] for r in rows} == {line3.register_id}
    assert all(r[3] and r[4] == uid_hash(r[1]) for r in rows)
    # the register knows its own id and name
    (name,) = line3._db.execute("SELECT name FROM known_register WHERE register_id = ?",
                                (line3.register_id,)).fetchone()
    assert name


def test_an_axis_event_says_what_it_set(line3):
    line3.update_axis(AXIS, who="ben", serial_number="S-1", load_inertia_kgm2=2.0)
    line3.record_origin(AXIS, "origin sensor at +1.25°", who="ben")
    line3.add_axis_note(AXIS, "cable tied", who="ben")
    axis_id = line3.axis(AXIS).id
    data = [json.loads(r[0]) if r[0] else None for r in line3._db.execute(
        "SELECT data FROM axis_event WHERE axis_id = ? ORDER BY id", (axis_id,))]
    assert data[0] == {"axis_added": {"actuator_code": "FHA-25C-50-US250", "driver_model": "HA-655-2-200",
                                      "port_url": "/dev/ttyUSB0", "load_inertia_kgm2": 1.5, "notes": "",
                                      "serial_number": ""}}
    assert {"field": "serial_number", "old": "", "new": "S-1"} in data
    assert {"field": "load_inertia_kgm2", "old": 1.5, "new": 2.0} in data
    assert data[-2:] == [{"origin": "origin sensor at +1.25°"}, None]
