"""Two laptops' registers filled offline by the machine window's facts (facts_from_session), synced
with the plant's register (an SQLite file, or the tests' real PostgreSQL server) both ways, twice;
a sync stopped at twenty random points and run again; a server that goes away in the middle;
conflicts found, shown and settled. Afterwards every fact is in every register exactly once."""

from __future__ import annotations

import json
import random
import select
import signal
import sqlite3
from pathlib import Path

import pytest

from fha_studio.cli import main
from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.absolute import DgrCheckRecord
from fha_studio.logic.procedures import ProcedureSession
from fha_studio.logic.register import Register, RegisterError
from fha_studio.logic.register import facts_from_session as f
from fha_studio.logic.register import sync as sync_module
from fha_studio.logic.register.identity import UID_TABLES
from fha_studio.logic.register.sync import sync_registers
from tests.register.test_roles import logins, plant, server_clock  # noqa: F401 (fixtures)
from tests.support.processes import Child

M = "Line 3 positioner"
SHARED = f"{M}/table"
MODEL = load_parameter_model()


def fill_offline(path, who: str, clock, direction: int, own_axis: str, facts_per_axis: int = 1) -> None:
    """What a technician's machine window records on a laptop without a network: the shared axis
    (its rotary direction read as ``direction``, its origin set) and an axis of their own."""
    with Register(path) as reg:
        for axis, actuator in ((SHARED, "FHA-25C-50-US250"), (f"{M}/{own_axis}", "FHA-32C-100-US250")):
            recorded: list[f.Fact] = [
                f.axis_fact({"actuator_code": actuator, "driver_model": "HA-655-2-200"}, who),
                f.session_fact(ProcedureSession(actuator_code=actuator, operator=who)),
            ]
            for n in range(facts_per_axis):
                recorded += [
                    *f.read_facts(
                        MODEL, {("system", 8): direction, ("tune", 4): 10 + n}, who, "HA-655-2-200"
                    ),
                    f.write_fact(
                        MODEL,
                        {
                            "mode": "tune",
                            "number": 4,
                            "new": 20 + n,
                            "old": 10 + n,
                            "read_back": 20 + n,
                            "verified": True,
                        },
                        who,
                    ),
                    *f.alarm_facts(20, "HA-655", who),
                ]
            at = clock.now_utc().isoformat()
            recorded += f.facts_from_dgr_check(
                DgrCheckRecord("absolute_origin", who, at, {"position_deg": 0.01 * direction}, True, "ok")
            )
            recorded += f.model_check_facts([f"fits, {who}"], "", who)
            for fact in recorded:
                f.record_fact(reg, axis, fact)
                clock.advance(1)


def contents(where) -> dict[str, dict[str, tuple]]:
    """Every fact of the register by table and stable id, as it reads in any register: axes and
    machines by name, a correction by the id of what it corrects, a snapshot with its values."""
    with Register(where) as reg:
        db = reg._db
        axes = {
            r["id"]: f"{r['machine']}/{r['name']}"
            for r in db.execute(
                "SELECT axis.id, axis.name, machine.name AS machine FROM axis"
                " JOIN machine ON machine.id = axis.machine_id"
            )
        }
        machines = {r["id"]: r["name"] for r in db.execute("SELECT id, name FROM machine")}
        out: dict[str, dict[str, tuple]] = {}
        for table in UID_TABLES:
            rows = [dict(r) for r in db.execute(f"SELECT * FROM {table}")]
            uids = {r["id"]: r["uid"] for r in rows}
            facts = {}
            for r in rows:
                r["axis_id"] = axes.get(r.get("axis_id"))
                if "machine_id" in r:
                    r["machine_id"] = machines[r["machine_id"]]
                if r.get("corrects") is not None:
                    r["corrects"] = uids[r["corrects"]]
                if table == "snapshot":
                    r["values"] = sorted(
                        tuple(v)
                        for v in db.execute(
                            "SELECT mode, number, key, value FROM snapshot_value WHERE snapshot_id = ?",
                            (r["id"],),
                        )
                    )
                facts[r["uid"]] = tuple(sorted((k, str(v)) for k, v in r.items() if k not in ("id", "rowid")))
            assert len(facts) == len(rows)  # each stable id once
            out[table] = facts
        for table, key in (
            ("signing_key", "key_id"),
            ("key_revocation", "key_id"),
            ("report_signature", "signature"),
        ):
            out[table] = {r[key]: tuple(r) for r in db.execute(f"SELECT * FROM {table}")}
    return out


def sound(where) -> None:
    """The store's own checks: SQLite's integrity and foreign keys; the server's constraints all
    valid and every fact with a stable id."""
    with Register(where) as reg:
        if isinstance(where, Path):
            assert reg.integrity_check() == "ok"
            assert reg._db.execute("PRAGMA foreign_key_check").fetchall() == []
        else:
            assert (
                reg._db.execute(
                    "SELECT COUNT(*) FROM pg_constraint WHERE NOT convalidated"
                    " AND connamespace = current_schema()::regnamespace"
                ).fetchone()[0]
                == 0
            )
        for table in UID_TABLES:
            assert reg._db.execute(f"SELECT COUNT(*) FROM {table} WHERE uid = ''").fetchone()[0] == 0


@pytest.fixture
def laptops(tmp_path, fixed_clock):
    """Two laptops' registers, filled offline: both changed the shared axis (rotary direction 1
    on Ana's, 0 on Ben's), each commissioned an axis of its own."""
    ana, ben = tmp_path / "ana.sqlite", tmp_path / "ben.sqlite"
    fill_offline(ana, "ana", fixed_clock, 1, "tilt")
    fill_offline(ben, "ben", fixed_clock, 0, "gripper")
    return ana, ben


def test_two_laptops_and_the_plant_register_end_with_every_fact_once(laptops, register_target):
    ana, ben = laptops
    plant_register = register_target
    first = sync_registers(ana, plant_register, who="ana")
    assert (first.received, first.already_there, first.conflicts) == (0, 0, ())  # the plant had nothing
    second = sync_registers(ben, plant_register, who="ben")
    assert second.sent > 0 and second.received == first.sent
    # the shared axis changed on both laptops while apart: its rotary direction and its origin
    # differ, one conflict each, in both registers
    origin, conflict = sorted(second.conflicts, key=lambda c: c.subject)
    assert (origin.subject, conflict.subject) == ("origin", "parameters")
    assert {s.values["origin"].value for s in origin.sides} == {
        "absolute origin set (OWW), read back at +0.00°",
        "absolute origin set (OWW), read back at +0.01°",
    }
    assert conflict.axis.ref == SHARED and conflict.open and conflict.items() == ["rotary_direction"]
    assert {conflict.uid, origin.uid} == second.found_now
    where = sorted(s.values["rotary_direction"].where.rsplit(" ", 1)[-1] for s in conflict.sides)
    assert where == ["ana.sqlite", "ben.sqlite"]  # where each side's fact was recorded
    values = {s.values["rotary_direction"].value for s in conflict.sides}
    assert values == {0, 1} and {s.values["rotary_direction"].who for s in conflict.sides} == {"ana", "ben"}
    third = sync_registers(ana, plant_register)  # Ana's laptop receives Ben's facts and the conflicts
    assert third.sent == 0 and third.received == second.sent + 2
    # twice = once: nothing moves any more, in either direction
    for laptop in (ana, ben):
        again = sync_registers(laptop, plant_register)
        assert (again.sent, again.received, again.found_now) == (0, 0, frozenset())
        assert {c.uid for c in again.conflicts} == {conflict.uid, origin.uid}
    everywhere = [contents(where) for where in (ana, ben, plant_register)]
    assert everywhere[0] == everywhere[1] == everywhere[2]
    facts = everywhere[0]
    assert again.already_there == sum(len(t) for t in facts.values())
    for where in (ana, ben, plant_register):
        sound(where)
    with Register(plant_register) as reg:  # one machine, one shared axis: matched by machine and axis name
        assert sorted(a.ref for a in reg.axes()) == [f"{M}/gripper", SHARED, f"{M}/tilt"]
        kinds = [e.kind.value for e in reg.history(SHARED)]
        assert kinds.count("snapshot") == 2 and kinds.count("conflict") == 2
        recorded_in = {r[0] for r in reg._db.execute("SELECT DISTINCT recorded_in FROM snapshot")}
        assert len(recorded_in) == 2  # each laptop's facts say where they were recorded


def test_a_person_settles_a_conflict_by_a_fact_that_travels(laptops, register_target, capsys):
    ana, ben = laptops
    plant_register = register_target
    sync_registers(ana, plant_register)
    sync_registers(ben, plant_register)
    with Register(plant_register) as reg:
        (conflict,) = [c for c in reg.conflicts() if c.subject == "parameters"]
        assert reg.current_values(SHARED).values["rotary_direction"].source == "link"
    # Ben's laptop does not know it yet; the plant's register says it in the history and `open`
    assert main(["register", "--register", str(plant_register), "history", SHARED]) == 0
    out = capsys.readouterr().out
    assert f"conflict {conflict.short}" in out and "OPEN CONFLICTS: 2" in out and "Rotary direction" in out
    assert main(["register", "--register", str(plant_register), "conflicts", SHARED, "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)
    assert [c["subject"] for c in listed] == ["parameters", "origin"] or len(listed) == 2
    assert all(c["axis"] == SHARED and c["open"] and len(c["sides"]) == 2 for c in listed)
    ana_side = next(n for n, s in enumerate(conflict.sides, 1) if s.values["rotary_direction"].who == "ana")
    assert (
        main(
            [
                "register",
                "--register",
                str(plant_register),
                "resolve",
                conflict.short[:6],
                "--keep",
                str(ana_side),
                "--note",
                "checked on the machine: reversed",
                "--operator",
                "carla",
            ]
        )
        == 0
    )
    assert "settled" in capsys.readouterr().out
    again = ["register", "--register", str(plant_register), "resolve", conflict.short, "--keep", "1"]
    assert main(again) == 2
    assert "was settled by carla" in capsys.readouterr().err
    sync_registers(ben, plant_register)
    with Register(ben) as reg:
        assert [c.subject for c in reg.conflicts()] == ["origin"]  # the other is still open
        (settled,) = [c for c in reg.conflicts(open_only=False) if not c.open]
        assert settled.resolutions[0].who == "carla" and settled.resolutions[0].kept == ana_side
        known = reg.current_values(SHARED).values["rotary_direction"]
        assert (known.value, known.source) == (1, "settled")
        assert SHARED in [found.axis.ref for found in reg.find("rotary_direction", 1)]
        assert SHARED not in [found.axis.ref for found in reg.find("rotary_direction", 0)]
        kinds = [e.kind.value for e in reg.history(SHARED)]
        assert kinds.count("snapshot") == 2 and kinds[-1] == "settled"  # nothing removed, one added


def test_axes_added_apart_with_different_actuators_are_one_axis_in_conflict(tmp_path, fixed_clock):
    a, b = tmp_path / "a.sqlite", tmp_path / "b.sqlite"
    with Register(a) as reg:
        reg.add_machine(M)
        reg.add_axis(M, "table", "FHA-25C-50-US250", who="ana")
        reg.add_axis(M, "old name", "FHA-17C-50-US250", who="ana")
    sync_registers(a, b)
    fixed_clock.advance(60)
    with Register(a) as reg:  # apart: Ana renames an axis, declares a serial number
        reg.update_axis(f"{M}/old name", who="ana", name="feed")
        reg.update_axis(f"{M}/table", who="ana", serial_number="S-25", load_inertia_kgm2=1.5)
    fixed_clock.advance(60)
    with Register(b) as reg:  # Ben declares another actuator on the table
        reg.update_axis(f"{M}/table", who="ben", actuator_code="FHA-32C-100-US250")
        fixed_clock.advance(60)
        reg.update_axis(f"{M}/table", who="ben", load_inertia_kgm2=2.0)
    result = sync_registers(a, b)
    assert result.axes_added == 0  # the renamed axis is the one it was
    (conflict,) = result.conflicts
    assert conflict.subject == "axis" and conflict.items() == ["load_inertia_kgm2"]
    for where in (a, b):
        with Register(where) as reg:
            assert [x.name for x in reg.axes(M)] == ["table", "feed"]
            table = reg.axis(f"{M}/table")
            # each change that only one side made is the axis's in both; the newest of two is shown
            assert (table.actuator_code, table.serial_number, table.load_inertia_kgm2) == (
                "FHA-32C-100-US250",
                "S-25",
                2.0,
            )
    fixed_clock.advance(60)
    with Register(a) as reg:
        reg.resolve_conflict(
            conflict.uid,
            keep=next(
                n for n, s in enumerate(conflict.sides, 1) if s.values["load_inertia_kgm2"].value == 1.5
            ),
            who="ana",
        )
    sync_registers(b, a)
    with Register(b) as reg:
        assert reg.axis(f"{M}/table").load_inertia_kgm2 == 1.5 and reg.conflicts() == []


def test_the_same_answer_recorded_on_two_laptops_is_there_once(tmp_path, fixed_clock):
    record = DgrCheckRecord(
        "absolute_origin", "ana", "2026-11-30T07:00:00Z", {"position_deg": 0.0}, True, "ok"
    )
    a, b = tmp_path / "a.sqlite", tmp_path / "b.sqlite"
    for where in (a, b):  # the same session file imported on both
        with Register(where) as reg:
            for fact in (
                f.axis_fact({"actuator_code": "FHA-25C-50-US250"}, "ana"),
                *f.facts_from_dgr_check(record),
            ):
                f.record_fact(reg, SHARED, fact)
    sync_registers(a, b)
    again = sync_registers(a, b)
    assert (again.sent, again.received) == (0, 0)
    for where in (a, b):
        with Register(where) as reg:
            assert reg.check_counts(SHARED) == (1, 0)
            assert reg._db.execute("SELECT COUNT(*) FROM check_result").fetchone()[0] == 1


def test_a_copy_of_a_register_is_not_synced_with_it(tmp_path, capsys):
    a = tmp_path / "a.sqlite"
    Register(a).close()
    copy = tmp_path / "copy.sqlite"
    copy.write_bytes(a.read_bytes())
    assert main(["register", "sync", "--from", str(a), "--to", str(copy)]) == 3
    assert "are one register" in capsys.readouterr().err


def test_the_sync_command_says_what_it_moved_in_json(laptops, tmp_path, capsys):
    ana, ben = laptops
    assert (
        main(["register", "sync", "--from", str(ana), "--to", str(ben), "--json", "--operator", "ana"]) == 0
    )
    said = json.loads(capsys.readouterr().out)
    assert {"sent", "received", "already_there", "conflicts"} <= set(said)
    assert said["sent"] > 0 and said["received"] > 0 and said["already_there"] == 0
    assert len(said["conflicts"]) == 2
    assert all(c["axis"] == SHARED and c["found_now"] and c["found_by"] == "ana" for c in said["conflicts"])
    assert main(["register", "--register", str(ben), "sync", "--to", str(ana)]) == 0  # --from: --register
    assert "0 fact(s) sent, 0 received" in capsys.readouterr().out
    new = tmp_path / "new" / "fresh.sqlite"  # a new laptop takes the plant's register
    assert main(["register", "sync", "--from", str(ana), "--to", str(new)]) == 0
    assert contents(new) == contents(ana)


class _Stopped(Exception):
    """A fault put into a sync (as if its process had died there)."""


def test_a_sync_stopped_at_twenty_random_points_and_run_again_moves_each_fact_once(
    tmp_path, fixed_clock, register_target, monkeypatch
):
    laptop = tmp_path / "laptop.sqlite"
    fill_offline(laptop, "ana", fixed_clock, 1, "tilt", facts_per_axis=3)
    fill_offline(register_target, "ben", fixed_clock, 0, "gripper", facts_per_axis=3)
    rng = random.Random(26)
    calls = {"n": 0, "stop_at": 0}
    real_insert, real_execute = sync_module._Side.insert, sync_module._Side.execute

    def faulty(real):
        def call(self, *args, **kwargs):
            calls["n"] += 1
            if calls["n"] == calls["stop_at"]:  # inside a transaction: it is rolled back
                raise _Stopped(f"write {calls['n']}")
            return real(self, *args, **kwargs)

        return call

    monkeypatch.setattr(sync_module._Side, "insert", faulty(real_insert))
    monkeypatch.setattr(sync_module._Side, "execute", faulty(real_execute))
    stops = 0
    # both stay open, as in the GUI's worker (a process killed for real: the next test)
    mine, theirs = Register(laptop), Register(register_target)
    for point in range(20):
        calls["n"], boundary = 0, point % 2 == 0
        # a fault after a batch was committed (1 or 2 of this run), or at a write of the run (the
        # registers known, machines, axes, conflicts, a batch's facts, an axis's fields): its
        # transaction is not committed
        calls["stop_at"] = 0 if boundary else rng.randint(1, 5)
        after = rng.randint(1, 2)

        def at_batch(p, after=after, boundary=boundary):
            if boundary and p.stage in ("sending", "receiving") and p.batches == after:
                raise _Stopped(f"after batch {after}")

        try:
            sync_registers(mine, theirs, progress=at_batch, batch_facts=1)
        except _Stopped:
            stops += 1
        assert not mine._db.in_transaction and not theirs._db.in_transaction  # what it began, undone
    calls["stop_at"] = 0
    done = sync_registers(mine, theirs)  # the last run finishes it
    mine.close()
    theirs.close()
    assert stops == 20  # every run was stopped before it was done
    assert done.sent + done.received > 0
    again = sync_registers(laptop, register_target)
    assert (again.sent, again.received) == (0, 0)
    assert contents(laptop) == contents(register_target)
    # found once each, whichever run found them
    assert sorted(c.subject for c in again.conflicts) == ["origin", "parameters"]
    for where in (laptop, register_target):
        sound(where)


def _read_line(child: Child, within_s: float = 60.0) -> str:
    ready, _, _ = select.select([child.stderr], [], [], within_s)
    return child.stderr.readline() if ready else ""


def test_a_sync_killed_for_real_and_run_again_moves_each_fact_once(
    tmp_path, fixed_clock, postgres_cluster, children
):
    laptop = tmp_path / "laptop.sqlite"
    plant_register = postgres_cluster.new_database()
    fill_offline(laptop, "ana", fixed_clock, 1, "tilt", facts_per_axis=4)
    fill_offline(plant_register, "ben", fixed_clock, 0, "gripper", facts_per_axis=4)
    rng = random.Random(2026)
    for _ in range(2):  # (each a new process: 1.5-3 s of the test under load)
        child = children(
            Child.fha,
            "register",
            "sync",
            "--from",
            laptop,
            "--to",
            plant_register,
            "--progress",
            "--batch",
            "2",
            text=True,
        )
        for _ in range(rng.randint(1, 5)):
            if not _read_line(child):
                break
        # SIGKILL: wherever it is, inside a transaction on either side or between them
        assert child.kill() == -signal.SIGKILL
    assert main(["register", "sync", "--from", str(laptop), "--to", plant_register]) == 0
    assert contents(laptop) == contents(plant_register)
    for where in (laptop, plant_register):
        sound(where)
    with sqlite3.connect(laptop) as db:
        assert db.execute("PRAGMA integrity_check").fetchone() == ("ok",)


def test_a_server_that_goes_away_mid_sync_is_one_line_and_a_second_run_finishes(
    tmp_path, fixed_clock, postgres_cluster, monkeypatch, capsys
):
    laptop = tmp_path / "laptop.sqlite"
    plant_register = postgres_cluster.new_database()
    fill_offline(laptop, "ana", fixed_clock, 1, "tilt", facts_per_axis=3)
    real_tell = sync_module._Sync._tell
    stopped = []

    def tell(self, stage):
        real_tell(self, stage)
        if stage == "sending" and self.batches == 2 and not stopped:
            stopped.append(self.done)
            postgres_cluster.stop()

    monkeypatch.setattr(sync_module._Sync, "_tell", tell)
    try:
        assert main(["register", "sync", "--from", str(laptop), "--to", plant_register, "--batch", "4"]) == 3
    finally:
        postgres_cluster.start()
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the server went away" in err and "run it again" in err
    assert "fha-test-password" not in err
    assert stopped == [8]
    monkeypatch.setattr(sync_module._Sync, "_tell", real_tell)
    with Register(plant_register) as reg:  # the two batches before are there, whole
        assert reg._db.execute("SELECT COUNT(*) FROM axis_event").fetchone()[0] >= 1
    assert main(["register", "sync", "--from", str(laptop), "--to", plant_register]) == 0
    assert contents(laptop) == contents(plant_register)
    sound(plant_register)


def test_a_register_that_cannot_be_opened_is_one_line(tmp_path, capsys):
    assert (
        main(
            ["register", "sync", "--from", str(tmp_path / "none.sqlite"), "--to", str(tmp_path / "b.sqlite")]
        )
        == 2
    )
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "there is no register" in err
    assert not (tmp_path / "b.sqlite").exists()
    with pytest.raises(RegisterError, match="there is no register"):
        sync_registers(tmp_path / "none.sqlite", tmp_path / "b.sqlite")


def test_a_technician_syncs_a_laptop_into_a_plant_register_with_roles(
    plant, server_clock, tmp_path, capsys  # noqa: F811 (the roles' fixtures)
):
    """On a server with roles: Ana's login (a technician) syncs the facts her laptop recorded
    offline two days ago; the server says when they came. An axis only her laptop has is an
    administrator's to add: her sync says so in one line and moves nothing, until Cleo adds it."""
    laptop = tmp_path / "ana.sqlite"
    server_clock.advance(-2 * 86400)
    with Register(laptop) as reg:
        for axis in ("Line 3/table", "Line 3/tilt"):
            for fact in (
                f.axis_fact({"actuator_code": "FHA-25C-50-US250"}, "Ana Lima"),
                *f.read_facts(MODEL, {("system", 8): 1}, "Ana Lima", "HA-655-2-200"),
                *f.alarm_facts(20, "HA-655", "Ana Lima"),
            ):
                f.record_fact(reg, axis, fact)
    server_clock.advance(2 * 86400)
    assert main(["register", "sync", "--from", str(laptop), "--to", plant["ana"]]) == 3
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "adds and renames machines and axes" in err
    assert main(["register", "--register", plant["cleo"], "add-axis", "Line 3/tilt",
                 "--actuator", "FHA-25C-50-US250"]) == 0
    capsys.readouterr()
    assert main(["register", "sync", "--from", str(laptop), "--to", plant["ana"], "--json"]) == 0
    said = json.loads(capsys.readouterr().out)
    assert said["sent"] > 0 and said["received"] == 2  # the axes' entries the server made
    assert contents(laptop) == contents(plant["fha"])
    with Register(plant["ana"]) as reg:
        alarm = next(e for e in reg.history("Line 3/tilt") if e.kind.value == "alarm")
        assert "reached the server" in alarm.text and alarm.data["received_by"] == "ana"


def test_the_machine_report_and_open_items_show_an_open_conflict(laptops, tmp_path, capsys):
    from fha_studio.logic.machine import MachineProject
    from fha_studio.logic.machine_report import build_machine_report, render_machine_html

    ana, ben = laptops
    sync_registers(ana, ben)
    with Register(ben) as reg:
        report = build_machine_report(MachineProject.from_register(reg, M), register=reg)
        items = [i for i in reg.open_items(M) if i.kind == "conflict"]
    table = next(s for s in report.summaries if s.axis == "table")
    assert len(table.open_conflicts) == 2 and "Rotary direction" in " ".join(table.open_conflicts)
    assert all(not s.open_conflicts for s in report.summaries if s.axis != "table")
    page = render_machine_html(report)
    assert "Open conflicts" in page and "reversed" in page
    assert len(items) == 2 and {i.axis.ref for i in items} == {SHARED}
    assert main(["register", "--register", str(ben), "open", M]) == 0
    assert capsys.readouterr().out.count(f"{SHARED}: conflict: conflict ") == 2


def test_axes_two_registers_held_differently_before_ids_are_a_conflict_once(tmp_path):
    """Axes of registers older than stable ids (no entry says what set their fields): a field they
    hold differently is a conflict; settled, it stays settled."""
    a, b = tmp_path / "a.sqlite", tmp_path / "b.sqlite"
    for where, actuator in ((a, "FHA-25C-50-US250"), (b, "FHA-32C-100-US250")):
        with Register(where) as reg:
            reg.add_machine(M)
            reg._db.execute(  # as schema 5 and before left it: the field without an entry saying so
                "INSERT INTO axis (machine_id, name, actuator_code, created_utc) VALUES (1, 'table', ?, ?)",
                (actuator, "2025-01-02T03:04:05.000000+00:00"),
            )
    (conflict,) = sync_registers(a, b).conflicts
    assert conflict.subject == "axis" and {s.values["actuator_code"].value for s in conflict.sides} == {
        "FHA-25C-50-US250", "FHA-32C-100-US250"}
    # settled in the register that held the kept value all along: its row does not change
    keep = next(n for n, s in enumerate(conflict.sides, 1) if s.values["actuator_code"].value[4:7] == "25C")
    with Register(a) as reg:
        reg.resolve_conflict(conflict.short, keep, who="carla")
    again = sync_registers(a, b)
    assert again.conflicts == () and again.found_now == frozenset()
    for where in (a, b):
        with Register(where) as reg:
            assert reg.axis(SHARED).actuator_code == "FHA-25C-50-US250"
    assert sync_registers(b, a).conflicts == ()
