"""The register on a real PostgreSQL server (the throw-away cluster of tests/support/postgres.py):
the same schema and migrations as the file; a wrong password, a server that went away and a full
disk each one line, and nothing lost or half-written."""

from __future__ import annotations

import sqlite3

import psycopg
import pytest

from fha_studio.cli import main
from fha_studio.logic.register import SCHEMA_VERSION, Register, RegisterError, register_location
from fha_studio.logic.register.guard import ServerAway
from fha_studio.logic.register.identity import uid_hash
from fha_studio.logic.register.schema import MIGRATIONS
from fha_studio.logic.register.server import ServerDatabase, problem, shown_url
from tests.support.postgres import PASSWORD

M = "Line 3 positioner"


def _columns_on_server(url: str) -> dict[str, list[str]]:
    with psycopg.connect(url) as db:
        rows = db.execute(
            "SELECT table_name, column_name FROM information_schema.columns WHERE table_schema = 'public'"
            " AND table_name != 'register_schema' AND column_name != 'rowid'"
            " ORDER BY table_name, ordinal_position"
        ).fetchall()
    out: dict[str, list[str]] = {}
    for table, column in rows:
        out.setdefault(table, []).append(column)
    return out


def _columns_in_file(path) -> dict[str, list[str]]:
    with sqlite3.connect(path) as db:
        query = "SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name"
        tables = [r[0] for r in db.execute(query)]
        return {t: [r[1] for r in db.execute(f"PRAGMA table_info({t})")] for t in tables}


def test_the_server_and_the_file_have_one_schema_at_one_version(postgres_cluster, tmp_path):
    url = postgres_cluster.new_database()
    with Register(url) as on_server, Register(tmp_path / "r.sqlite") as in_file:
        assert on_server.version == in_file.version == SCHEMA_VERSION
        assert on_server.integrity_check() == "ok"
    assert _columns_on_server(url) == _columns_in_file(tmp_path / "r.sqlite")


def test_an_older_register_on_the_server_is_migrated_with_its_facts(postgres_cluster):
    url = postgres_cluster.new_database()
    db = ServerDatabase(url)
    assert db.prepare_register(create=True)
    for statement in MIGRATIONS[0]:  # a register of schema 1, written by an older FHA Studio
        db.execute(statement)
    db.execute("PRAGMA user_version = 1")
    db.execute("INSERT INTO machine (name, created_utc) VALUES (?, ?)", ("Press 7", "2026-01-01T00:00:00Z"))
    db.execute("INSERT INTO axis (machine_id, name, created_utc) VALUES (1, 'feed', '2026-01-01T00:00:00Z')")
    for n in range(3):
        at = f"2026-01-0{n + 2}T00:00:00Z"
        db.execute("INSERT INTO alarm (axis_id, at_utc, code) VALUES (1, ?, 20)", (at,))
    db.close()
    with Register(url, read_only=True) as reg:  # a question brings it up to date first
        assert reg.version == SCHEMA_VERSION
        assert [m.name for m in reg.machines()] == ["Press 7"]
        # schema 5: the facts already there got stable ids; their numbers as this program makes them
        rows = reg._db.execute(
            "SELECT uid, recorded_in, recorded_utc, uid_hash, at_utc FROM alarm").fetchall()
        assert len({r[0] for r in rows}) == 3 and {r[1] for r in rows} == {reg.register_id}
        assert all(r[2] == r[4] and r[3] == uid_hash(r[0]) for r in rows)
    with Register(url) as reg:
        reg.add_axis("Press 7", "ram", "FHA-25C-50-US250", serial_number="S-1")
        assert reg.axis("Press 7/ram").serial_number == "S-1"  # the column of schema 2


def test_a_failing_migration_leaves_the_server_at_its_version(postgres_cluster, monkeypatch):
    """As for a file (test_durability.py): a migration that fails half-way is rolled back whole,
    the register stays at its version with its facts, and a program whose migrations work brings
    it up to date afterwards."""
    from fha_studio.logic.register import store as register_store

    url = postgres_cluster.new_database()
    db = ServerDatabase(url)
    assert db.prepare_register(create=True)
    for statement in MIGRATIONS[0]:  # a register of schema 1
        db.execute(statement)
    db.execute("PRAGMA user_version = 1")
    db.execute("INSERT INTO machine (name, created_utc) VALUES (?, ?)", ("Press 7", "2026-01-01T00:00:00Z"))
    db.execute("INSERT INTO axis (machine_id, name, created_utc) VALUES (1, 'feed', '2026-01-01T00:00:00Z')")
    db.close()
    broken = (MIGRATIONS[0], (*MIGRATIONS[1][:1], "CREATE INDEX oops ON no_such_table (x)"))
    monkeypatch.setattr(register_store, "MIGRATIONS", broken)
    with pytest.raises(RegisterError) as failed:
        Register(url)
    assert "\n" not in str(failed.value) and PASSWORD not in str(failed.value)
    with psycopg.connect(url) as check:
        assert check.execute("SELECT version FROM register_schema").fetchone() == (1,)
        columns = {r[0] for r in check.execute(
            "SELECT column_name FROM information_schema.columns WHERE table_name = 'axis'")}
        assert "serial_number" not in columns  # the first statement of schema 2 was rolled back too
        assert check.execute("SELECT name FROM axis").fetchall() == [("feed",)]
    monkeypatch.undo()
    with Register(url) as reg:
        assert reg.version == SCHEMA_VERSION
        assert [a.name for a in reg.axes("Press 7")] == ["feed"]


def test_a_register_from_a_newer_program_is_refused_unchanged(postgres_cluster):
    url = postgres_cluster.new_database()
    Register(url).close()
    with psycopg.connect(url, autocommit=True) as db:
        db.execute("UPDATE register_schema SET version = %s", (SCHEMA_VERSION + 1,))
    with pytest.raises(RegisterError, match=rf"newer FHA Studio \(schema {SCHEMA_VERSION + 1}"):
        Register(url)
    with psycopg.connect(url) as db:
        assert db.execute("SELECT version FROM register_schema").fetchone() == (SCHEMA_VERSION + 1,)


def test_a_wrong_password_is_one_line_and_changes_nothing(postgres_cluster, capsys):
    url = postgres_cluster.new_database()
    wrong = url.replace(PASSWORD, "not-the-password")
    with pytest.raises(RegisterError) as refused:
        Register(wrong)
    said = str(refused.value)
    assert "refused the user name or password" in said and "\n" not in said
    assert "not-the-password" not in said and PASSWORD not in said  # no password in a message
    assert main(["register", "--register", wrong, "add-machine", "Press 7"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "refused the user name or password" in err
    with psycopg.connect(url) as db:  # nothing made on the server
        assert db.execute("SELECT to_regclass('register_schema')").fetchone() == (None,)


def test_a_server_that_goes_away_mid_run_is_one_line_and_loses_nothing(postgres_cluster):
    url = postgres_cluster.new_database()
    reg = Register(url)
    reg.add_machine(M)
    reg.add_axis(M, "table", "FHA-25C-50-US250", "HA-655-2-200", "/dev/ttyUSB0")
    reg.record_snapshot(f"{M}/table", [("system", 8, "rotary_direction", 1)], "link", who="ana")
    postgres_cluster.stop()
    try:
        with pytest.raises(RegisterError) as gone, reg.batch():  # a session's facts: all or none
            reg.record_alarm(f"{M}/table", 10, "overspeed")
            reg.add_axis_note(f"{M}/table", "after the alarm")
        said = str(gone.value)
        assert "the server went away" in said and "nothing was changed" in said and "\n" not in said
        with pytest.raises(RegisterError, match=r"the server (went away|cannot be reached)"):
            reg.history(f"{M}/table")
        with pytest.raises(RegisterError, match="the server cannot be reached"):
            Register(url)
    finally:
        reg.close()
        postgres_cluster.start()
    with Register(url) as again:
        kinds = [e.kind.value for e in again.history(f"{M}/table")]
        assert kinds == ["axis", "snapshot"]  # what was committed is there, the refused batch is not


def test_a_full_disk_and_the_other_refusals_in_words(postgres_cluster):
    url = postgres_cluster.new_database()
    full = problem(url, psycopg.errors.DiskFull("could not extend file: No space left on device"))
    assert str(full).endswith("the server has no space left on its disk: nothing was changed")
    assert PASSWORD not in str(full) and shown_url(url) in str(full)
    denied = problem(url, psycopg.errors.InsufficientPrivilege("permission denied for table fact"))
    assert "fha may not do that: permission denied for table fact: nothing was changed" in str(denied)
    with pytest.raises(RegisterError, match="there is no register at postgresql://fha@/"):
        Register(url, create=False)
    # a server not reached is away (a window tries again); one that refuses answered
    timeout = problem(url, psycopg.errors.ConnectionTimeout("connection timeout expired"), opening=True)
    assert isinstance(timeout, ServerAway) and "the server cannot be reached" in str(timeout)
    password = problem(url, psycopg.OperationalError('FATAL:  password authentication failed for user "fha"'))
    assert not isinstance(password, ServerAway) and "refused the user name or password" in str(password)


def test_the_register_option_takes_a_url_and_the_old_name_too(postgres_cluster, capsys, monkeypatch):
    url = postgres_cluster.new_database()
    assert main(["register", "--register", url, "add-machine", "Press 7"]) == 0
    assert main(["register", "--db", url, "machines"]) == 0
    out, err = capsys.readouterr()
    assert "Press 7" in out and err == "fha-studio register: note: --db is now called --register\n"
    monkeypatch.setenv("FHA_STUDIO_REGISTER", url)  # the site's choice, as for a file
    assert register_location() == url
    assert main(["register", "check"]) == 2
    assert "is on a server, which keeps its own pages and constraints" in capsys.readouterr().err
