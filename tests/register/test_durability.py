"""The register file over time and under stress: a v1 file upgraded with its data, a migration
that fails leaving the file as it was, a process killed mid-write losing nothing it committed,
two processes writing one register at once, and twenty connections writing it at once."""

from __future__ import annotations

import signal
import sqlite3
import textwrap

import pytest

from fha_studio.logic.register import Register, RegisterError
from fha_studio.logic.register import store as register_store
from fha_studio.logic.register.schema import MIGRATIONS
from tests.register.writers import EACH, NOTES, WRITERS, write_at_once
from tests.support.processes import Child


def _write_v1_register(path):
    """A register as the first schema wrote it, with a machine, an axis and some history."""
    db = sqlite3.connect(path, isolation_level=None)
    db.execute("BEGIN")
    for statement in MIGRATIONS[0]:
        db.execute(statement)
    db.execute("PRAGMA user_version = 1")
    t = "2025-01-02T03:04:05.000000+00:00"
    db.execute("INSERT INTO machine (name, site, created_utc) VALUES ('Press 7', 'Plant B', ?)", (t,))
    db.execute(
        "INSERT INTO axis (machine_id, name, actuator_code, driver_model, port_url, load_inertia_kgm2,"
        " created_utc) VALUES (1, 'feed', 'FHA-17C-50-US250', 'HA-655-1-200', 'COM3', 0.2, ?)",
        (t,),
    )
    db.execute(
        "INSERT INTO snapshot (axis_id, at_utc, who, source) VALUES (1, ?, 'ana', 'link')",
        ("2025-01-02T04:00:00.000000+00:00",),
    )
    db.execute("INSERT INTO snapshot_value VALUES (1, 'system', 8, 'rotary_direction', 1)")
    db.execute(
        "INSERT INTO parameter_write (axis_id, at_utc, who, mode, number, key, old, new, read_back, verified)"
        " VALUES (1, ?, 'ana', 'tune', 2, 'position_loop_gain', 40, 50, 50, 1)",
        ("2025-01-02T05:00:00.000000+00:00",),
    )
    # where the procedures stood: one row each, replaced as they moved on (wiring last written)
    for procedure, status in (("wiring", "running"), ("installation", "paused"), ("wiring", "completed")):
        db.execute(
            "INSERT OR REPLACE INTO procedure_run (axis_id, procedure_id, title, status, updated_utc)"
            " VALUES (1, ?, ?, ?, ?)",
            (procedure, procedure.title(), status, "2025-01-02T06:00:00.000000+00:00"))
    db.execute("COMMIT")
    db.close()


def test_a_v1_register_is_upgraded_with_its_data(tmp_path):
    path = tmp_path / "v1.sqlite"
    _write_v1_register(path)
    with Register(path) as reg:
        assert reg.version == 6
        feed = reg.axis("Press 7/feed")
        assert (feed.actuator_code, feed.port_url, feed.serial_number) == ("FHA-17C-50-US250", "COM3", "")
        assert [f.axis.name for f in reg.find("rotary_direction", 1)] == ["feed"]
        assert reg.current_values(feed).values["position_loop_gain"].value == 50
        assert [e.kind for e in reg.history(feed)] == ["snapshot", "write"]
        # what v2 added works on the old data
        reg.update_axis(feed, who="ben", serial_number="S/N 0012345")
        assert reg.axis(feed.id).serial_number == "S/N 0012345"
        assert reg.history(feed)[-1].text == "serial number: not given → S/N 0012345"
        plan = reg._db.execute(
            "EXPLAIN QUERY PLAN SELECT * FROM snapshot_value WHERE key = 'rotary_direction' AND value = 1"
        ).fetchall()
        assert "snapshot_value_by_key" in " ".join(str(tuple(r)) for r in plan)
        assert reg.integrity_check() == "ok"
        # v5: the procedures' states kept in the order they were last written, each now a row of its own
        assert [(r["procedure_id"], r["status"]) for r in reg.procedure_status(feed)] == [
            ("installation", "paused"), ("wiring", "completed")]
        # v6: the facts already there have stable ids, recorded in this register at their own time
        ids = _fact_ids(reg)
        assert len(ids) == 5 and len({uid for uid, *_ in ids}) == 5  # snapshot, write, procedures, serial
        assert {recorded_in for _, recorded_in, _ in ids} == {reg.register_id}
        assert "2025-01-02T04:00:00.000000+00:00" in {recorded for *_, recorded in ids}
        reg.record_procedure_status(feed, "installation", "Installation", "completed")
        assert [r["status"] for r in reg.procedure_status(feed)] == ["completed", "completed"]
    # and the history is append-only from now on: the file's own triggers refuse any program
    with sqlite3.connect(path) as raw, pytest.raises(
            sqlite3.IntegrityError, match="append-only: parameter snapshots are never changed"):
        raw.execute("UPDATE snapshot SET who = 'eve'")
    with Register(path) as again:  # opening an up-to-date file changes nothing
        assert again.version == 6 and len(again.snapshots("Press 7/feed")) == 1
        assert set(ids) < set(_fact_ids(again)) and again.register_id == reg.register_id


def _fact_ids(reg):
    from fha_studio.logic.register.identity import UID_TABLES

    return sorted(
        tuple(r)
        for t in UID_TABLES
        for r in reg._db.execute(f"SELECT uid, recorded_in, recorded_utc FROM {t}")
    )


def test_a_failing_migration_leaves_the_file_at_its_version(tmp_path, monkeypatch):
    path = tmp_path / "v1.sqlite"
    _write_v1_register(path)
    broken = (MIGRATIONS[0], (*MIGRATIONS[1][:1], "CREATE INDEX oops ON no_such_table (x)"))
    monkeypatch.setattr(register_store, "MIGRATIONS", broken)
    with pytest.raises(RegisterError, match="not a usable register file"):
        Register(path)
    db = sqlite3.connect(path)
    assert db.execute("PRAGMA user_version").fetchone()[0] == 1
    columns = [r[1] for r in db.execute("PRAGMA table_info(axis)")]
    assert "serial_number" not in columns  # the first statement of v2 was rolled back too
    assert db.execute("SELECT COUNT(*) FROM snapshot_value").fetchone()[0] == 1
    db.close()
    monkeypatch.undo()
    with Register(path) as reg:
        assert reg.version == 6


_WRITER = textwrap.dedent(
    """
    import sys
    from fha_studio.logic.register import Register

    path, axis, tag, count = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
    reg = Register(path)
    reg.ensure_axis("Cell 1", axis, actuator_code="FHA-25C-50-US250")
    n = 0
    while count < 0 or n < count:
        # one snapshot of 400 values per transaction: most of the loop's time is inside a write
        values = [("tune", k, f"item_{k}", n) for k in range(400)]
        number = reg.record_snapshot(axis if "/" in axis else "Cell 1/" + axis, values, "link", who=tag)
        reg.record_write("Cell 1/" + axis, "tune", 0, "item_0", n, n - 1, n, True, who=tag)
        print(number, flush=True)
        n += 1
    reg.close()
    """
)


def _writer(path, axis, tag, count) -> Child:
    return Child.python("-c", _WRITER, path, axis, tag, str(count), text=True)


def test_a_process_killed_mid_write_loses_nothing_committed(tmp_path, children):
    path = tmp_path / "crash.sqlite"
    writer = children(_writer, path, "rotary", "writer", -1)
    committed = []
    while len(committed) < 40:
        line = writer.stdout.readline()
        assert line, f"the writer ended early: {writer.stderr.read()}"
        committed.append(int(line))
    writer.kill()  # while it is in the middle of its next snapshot
    assert writer.returncode == -signal.SIGKILL
    assert (tmp_path / "crash.sqlite-wal").exists()  # the log the next opener recovers from
    with Register(path) as reg:
        assert reg.integrity_check() == "ok"
        snapshots = {s["id"]: s["count"] for s in reg.snapshots("Cell 1/rotary")}
        assert set(committed) <= set(snapshots)  # every snapshot it reported is there
        assert set(snapshots.values()) == {400}  # and none is there in part
        writes = [e for e in reg.history("Cell 1/rotary") if e.kind == "write"]
        assert len(writes) >= len(committed)


def test_two_processes_writing_one_register_do_not_corrupt_it(tmp_path, children):
    path = tmp_path / "shared.sqlite"
    # both add the same machine and the axis "shared" at the start: one of each results
    writers = [children(_writer, path, "shared", tag, 60) for tag in ("window A", "window B")]
    outputs = []
    for writer in writers:
        out, err = writer.communicate(240)
        assert writer.returncode == 0, err
        outputs.append([int(n) for n in out.split()])
    assert all(len(numbers) == 60 for numbers in outputs)
    assert not set(outputs[0]) & set(outputs[1])
    with Register(path) as reg:
        assert reg.integrity_check() == "ok"
        assert [a.ref for a in reg.axes()] == ["Cell 1/shared"]
        snapshots = reg.snapshots("Cell 1/shared")
        assert len(snapshots) == 120 and {s["count"] for s in snapshots} == {400}
        by_who = {who: sum(1 for s in snapshots if s["who"] == who) for who in ("window A", "window B")}
        assert by_who == {"window A": 60, "window B": 60}
        assert sum(1 for e in reg.history("Cell 1/shared") if e.kind == "write") == 120


def test_twenty_writers_at_once_on_a_register_file_leave_every_fact_once(tmp_path):
    """The server's twenty writers (test_roles.py) on a register file: twenty
    connections of their own write at once; every fact is there once, the check all of them
    answered once, and SQLite's own check holds."""
    path = tmp_path / "shared.sqlite"
    with Register(path) as reg:
        reg.add_machine("Cell 1")
        reg.add_axis("Cell 1", "rotary", "FHA-25C-50-US250", "HA-655-2-200", "/dev/ttyUSB0")
    write_at_once(lambda: Register(path), "Cell 1/rotary")
    with Register(path) as reg:
        assert reg.integrity_check() == "ok"
        db = reg._db
        assert sorted(r[0] for r in db.execute("SELECT note FROM snapshot")) == NOTES
        assert sorted(r[0] for r in db.execute("SELECT note FROM alarm")) == NOTES
        assert db.execute("SELECT count(*) FROM check_result").fetchone()[0] == 1
        values = db.execute("SELECT count(*), count(DISTINCT snapshot_id) FROM snapshot_value").fetchone()
        assert tuple(values) == (WRITERS * EACH * 20, WRITERS * EACH)
        for table in ("snapshot", "alarm", "check_result"):
            uids = [r[0] for r in db.execute(f"SELECT uid FROM {table}")]
            assert len(uids) == len(set(uids)), f"{table}: a fact twice"
        assert db.execute("PRAGMA foreign_key_check").fetchall() == []

