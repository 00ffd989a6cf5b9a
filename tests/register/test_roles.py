"""The register's roles on a real PostgreSQL server (the tests' throw-away cluster): a technician
adds facts, a reviewer signs, an administrator adds machines and axes; the server refuses a
technician's change, removal or back-dating of a fact and anyone's signing as someone else, each
one line; twenty writers at once leave every fact once and the server's constraints whole. A
register file has no roles (it has no users): the command says so."""

from __future__ import annotations

import datetime as _dt
import json
from pathlib import Path
from urllib.parse import urlsplit

import psycopg
import pytest

from fha_studio import clock
from fha_studio.cli import main
from fha_studio.logic.register import Register, RegisterError
from fha_studio.logic.register.report_signing import sign_other_file
from fha_studio.logic.register.signing import key_id_of, new_key, public_raw, write_private_key
from tests.register.writers import EACH, NOTES, WRITERS, write_at_once
from tests.support.clock import FakeClock
from tests.support.postgres import PASSWORD, ROLE, SUPER_PASSWORD

M = "Line 3"
TABLE = f"{M}/table"
#: The people of the tests' plant: login, role, person.
PEOPLE = (
    ("ana", "technician", "Ana Lima"),
    ("bob", "reviewer", "Bob Reviewer"),
    ("cleo", "administrator", "Cleo Admin"),
    ("dave", "reviewer", "Dave Other"),
)
#: A login of the server with no role of the register.
STRANGER = "eve"
LOGIN_PASSWORD = "login-test-password"


@pytest.fixture(scope="session")
def logins(postgres_cluster):
    """The people's logins on the tests' server (made once), and the register's role allowed to
    make roles (its owner sets the roles up)."""
    with psycopg.connect(postgres_cluster.url("postgres", "postgres", SUPER_PASSWORD), autocommit=True) as db:
        db.execute(f"ALTER ROLE {ROLE} CREATEROLE")
        for login in (*(p[0] for p in PEOPLE), STRANGER):
            if db.execute("SELECT 1 FROM pg_roles WHERE rolname = %s", (login,)).fetchone() is None:
                db.execute(f"CREATE ROLE {login} LOGIN PASSWORD '{LOGIN_PASSWORD}'")
    return [login for login, _, _ in PEOPLE]


@pytest.fixture
def server_clock(postgres_cluster):
    """FHA Studio's clock at the server's (a run with the calendar moved, FHA_TEST_TRAVEL_DAYS,
    would otherwise date every fact far from the server's clock)."""
    with psycopg.connect(postgres_cluster.url("postgres", "postgres", SUPER_PASSWORD)) as db:
        now = db.execute("SELECT now()").fetchone()[0]
    with clock.use(FakeClock(now)) as fixed:
        yield fixed


def _database(url: str) -> str:
    return urlsplit(url).path.lstrip("/")


def _as(url: str, login: str) -> str:
    return url.replace(f"{ROLE}:{PASSWORD}@", f"{login}:{LOGIN_PASSWORD}@")


@pytest.fixture
def plant(postgres_cluster, logins, server_clock, capsys):
    """A register on the server with machine Line 3 and its table axis, its roles set up by the
    owner and given to the people; {login: URL} ("fha": the owner)."""
    url = postgres_cluster.new_database()
    with Register(url) as reg:
        reg.add_machine(M, site="Plant A")
        reg.add_axis(M, "table", "FHA-25C-50-US250", "HA-655-2-200", "/dev/ttyUSB0")
    assert main(["register", "--register", url, "roles", "setup"]) == 0
    for login, role, person in PEOPLE:
        assert main(["register", "--register", url, "roles", "grant", login, role, "--person", person]) == 0
    capsys.readouterr()
    return {ROLE: url, **{login: _as(url, login) for login in logins}}


def _cli(capsys, url, *args):
    code = main(["register", "--register", url, *args])
    out, err = capsys.readouterr()
    return code, out, err


def _one_line(err: str) -> str:
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err.strip()


def test_the_owner_sets_the_roles_up_and_gives_them(postgres_cluster, logins, server_clock, capsys):
    url = postgres_cluster.new_database()
    code, out, _ = _cli(capsys, url, "roles", "setup")  # an empty database: the register, its roles
    database = _database(url)
    assert code == 0 and f"technician    {database}_technician: adds the facts of axes" in out
    assert _cli(capsys, url, "roles", "setup")[0] == 0  # again: nothing new, nothing lost
    code, _, err = _cli(capsys, url, "roles", "grant", "ana", "technician")
    assert code == 2 and "say who ana is: --person NAME" in _one_line(err)
    code, _, err = _cli(capsys, url, "roles", "grant", "nobody", "technician", "--person", "N. Body")
    assert code == 2 and "there is no login 'nobody' on the server" in _one_line(err)
    assert _cli(capsys, url, "roles", "grant", "ana", "technician", "--person", "Ana Lima")[0] == 0
    code, out, _ = _cli(capsys, url, "roles", "grant", "ana", "reviewer", "--json")
    assert code == 0 and json.loads(out) == {"login": "ana", "person": "Ana Lima",
                                             "roles": ["technician", "reviewer"]}
    assert _cli(capsys, url, "roles", "revoke", "ana", "reviewer")[1] == "ana (Ana Lima): technician\n"
    code, out, _ = _cli(capsys, _as(url, "ana"), "roles", "list")  # anyone with a role may ask
    assert code == 0 and out == "ana (Ana Lima): technician\n"
    code, _, err = _cli(capsys, _as(url, STRANGER), "machines")  # a login without a role of it
    assert code == 2 and _one_line(err).endswith(
        "eve may not use this register: a login works with it when its owner gives the login a role "
        "(fha-studio register roles grant LOGIN ROLE --person NAME): nothing was changed")
    code, _, err = _cli(capsys, _as(url, "ana"), "roles", "setup")  # not the owner
    said = _one_line(err)
    assert code == 2 and f"the roles are set up by the register's owner, {ROLE}; this is ana" in said
    code, _, err = _cli(capsys, url, "add-machine", "Press 7")  # nobody works as the owner
    assert code == 2 and _one_line(err).endswith(
        f"the server refused it: the register's owner, {ROLE}, records nothing: people work with their "
        "own logins (fha-studio register roles grant LOGIN ROLE --person NAME): nothing was changed")
    with psycopg.connect(url) as db:  # who each login is: a row per change, stamped by the server
        rows = db.execute("SELECT login, person, by_login FROM register_person").fetchall()
    assert rows == [("ana", "Ana Lima", ROLE)]


def test_a_register_file_has_no_roles(tmp_path, capsys):
    code, _, err = _cli(capsys, str(tmp_path / "r.sqlite"), "roles", "setup")
    assert code == 2 and "is a file: roles are a server's (a file has no users" in _one_line(err)


def test_each_role_adds_what_it_may_and_nothing_else(plant, capsys):
    code, _, err = _cli(capsys, plant["ana"], "add-axis", f"{M}/tilt")
    assert code == 2 and _one_line(err).endswith(
        "ana may not do that: an administrator of the register adds and renames machines and axes: "
        "nothing was changed")
    assert _cli(capsys, plant["cleo"], "add-axis", f"{M}/tilt", "--actuator", "FHA-32C-100-S248")[0] == 0
    with Register(plant["ana"]) as reg:
        reg.record_snapshot(TABLE, [("system", 8, "rotary_direction", 1)], "link", who="Ana Lima")
        reg.record_alarm(TABLE, 10, "overspeed", who="Ana Lima")
        reg.update_axis(TABLE, who="Ana Lima", serial_number="S-1")  # a technician may: in its history
        with pytest.raises(RegisterError, match="ana may not do that: an administrator of the register"):
            reg.update_axis(TABLE, who="Ana Lima", name="rotary table")
    with Register(plant["bob"]) as reg, pytest.raises(RegisterError, match=(
            "bob may not do that: a technician adds parameter snapshots, and nobody changes or removes")):
        reg.record_snapshot(TABLE, [("system", 8, "rotary_direction", 0)], "link")
    with psycopg.connect(plant["ana"]) as db:  # a temporary table of her own (a sync brings facts so)
        db.execute("CREATE TEMPORARY TABLE incoming (uid TEXT)")
    with psycopg.connect(plant[ROLE]) as db:  # each fact's receipt: the server's clock, the login
        receipts = db.execute("SELECT fact_table, received_by FROM register_receipt ORDER BY received_utc")
        assert [tuple(r) for r in receipts] == [
            ("axis_event", "cleo"), ("snapshot", "ana"), ("alarm", "ana"), ("axis_event", "ana")]


def test_a_technician_cannot_change_remove_or_back_date_a_fact(plant, capsys, server_clock):
    with Register(plant["ana"]) as reg:
        reg.record_alarm(TABLE, 10, "overspeed", who="Ana Lima")
        # dated later than the server's clock: refused, one line (a laptop whose clock is ahead)
        with pytest.raises(RegisterError) as ahead:
            reg.record_alarm(TABLE, 11, "overload", at_utc=server_clock.now_utc() + _dt.timedelta(hours=1))
        said = str(ahead.value)
        assert "\n" not in said and "the server refused it: dated " in said
        assert "later than the server's clock" in said and said.endswith("nothing was changed")
        # dated earlier (a laptop that worked offline): taken, and its receipt says when it came
        reg.record_alarm(TABLE, 12, "encoder", at_utc=server_clock.now_utc() - _dt.timedelta(days=3))
        # but said to be recorded in this register earlier than now: back-dated, refused
        server_clock.advance(-3600)  # the laptop's clock set back an hour
        with pytest.raises(RegisterError) as back:
            reg.record_alarm(TABLE, 13, "overload")
        said = str(back.value)
        assert "\n" not in said and "the server refused it: back-dated: said to be recorded in this " \
            "register at " in said and said.endswith("is this computer's clock right?): nothing was changed")
        server_clock.advance(3600)
    with psycopg.connect(plant["ana"], autocommit=True) as db:
        for sql in ("UPDATE alarm SET code = 13",
                    "UPDATE alarm SET at_utc = '2020-01-01T00:00:00.000000+00:00'",  # back-dated
                    "DELETE FROM alarm", "TRUNCATE alarm",
                    "UPDATE register_receipt SET received_utc = received_utc - interval '3 days'",
                    "INSERT INTO register_receipt VALUES ('alarm', '99', now(), 'ana', pg_current_xact_id())",
                    "DELETE FROM register_receipt",
                    "INSERT INTO this_register VALUES ((SELECT register_id FROM known_register LIMIT 1))"):
            with pytest.raises(psycopg.errors.InsufficientPrivilege):
                db.execute(sql)
        with pytest.raises(psycopg.Error, match="values are added with their snapshot, never to it later"):
            db.execute(
                "INSERT INTO snapshot_value VALUES ((SELECT min(id) FROM snapshot), 'tune', 99, 'x', 1)")
    with psycopg.connect(plant[ROLE], autocommit=True) as db:  # nor can the register's owner
        with pytest.raises(psycopg.Error, match="append-only: alarms are never changed or removed"):
            db.execute("UPDATE alarm SET at_utc = '2020-01-01T00:00:00.000000+00:00'")
        with pytest.raises(psycopg.Error, match="append-only: receipts are never changed or removed"):
            db.execute("UPDATE register_receipt SET received_utc = received_utc - interval '3 days'")
        alarms = db.execute("SELECT code, at_utc FROM alarm ORDER BY id").fetchall()
        receipts = db.execute("SELECT received_utc FROM register_receipt WHERE fact_table = 'alarm'"
                              " ORDER BY received_utc").fetchall()
    assert [a[0] for a in alarms] == [10, 12]
    assert alarms[1][1] < alarms[0][1]  # the offline one claims three days ago ...
    assert receipts[1][0] - receipts[0][0] < _dt.timedelta(minutes=5)  # ... and came now
    code, out, _ = _cli(capsys, plant["ana"], "history", TABLE)
    lines = out.splitlines()
    assert code == 0 and next(line for line in lines if "alarm 10: overspeed" in line).endswith("[Ana Lima]")
    offline = next(line for line in lines if "alarm 12: encoder" in line)
    came = receipts[1][0].astimezone(_dt.UTC)
    assert f"— reached the server {came:%Y-%m-%d %H:%M:%S} UTC from ana" in offline


def _bob_signs(plant, tmp_path):
    """Bob's key in the register (added by Bob) and its private key file."""
    key = new_key()
    path = write_private_key(key, tmp_path / "bob.pem")
    with Register(plant["bob"]) as reg:
        reg.add_key("Bob Reviewer", public_raw(key).hex(), key_id_of(public_raw(key)))
    return key, path


def test_signing_as_someone_else_is_refused_by_the_server(plant, tmp_path, capsys, monkeypatch):
    bob_key, bob_file = _bob_signs(plant, tmp_path)
    report = tmp_path / "axis1.pdf"
    report.write_bytes(b"%PDF-1.4 commissioning report of Line 3/table\n")
    # Dave, a reviewer, signs with Bob's key (a copy of Bob's key file): refused by the server
    with Register(plant["dave"]) as reg, pytest.raises(RegisterError) as refused:
        sign_other_file(reg, bob_key, "Bob Reviewer", report)
    said = str(refused.value)
    assert "\n" not in said and said.endswith(
        "the server refused it: signing as someone else: the login dave is Dave Other; the signature is "
        f"Bob Reviewer's, with key {key_id_of(public_raw(bob_key))} of Bob Reviewer: nothing was changed")
    # Ana, a technician, signs nothing: a reviewer signs reports
    with Register(plant["ana"]) as reg, pytest.raises(RegisterError, match="ana may not do that: a reviewer "
                                                      "signs reports: nothing was changed"):
        sign_other_file(reg, bob_key, "Bob Reviewer", report)
    # nor does she add a key in Bob's name (the command: one line, and no key file left behind)
    monkeypatch.setenv("FHA_STUDIO_KEY_PASSPHRASE", "")
    code, _, err = _cli(capsys, plant["ana"], "keys", "add", "--name", "Bob Reviewer",
                        "--key-file", str(tmp_path / "forged.pem"))
    assert code == 2 and "a key in someone else's name: the login ana is Ana Lima, the key says Bob " \
        "Reviewer (each person adds their own key)" in _one_line(err)
    assert not (tmp_path / "forged.pem").exists()
    # Bob signs with his own key: recorded, and the file verifies
    with Register(plant["bob"]) as reg:
        sign_other_file(reg, bob_key, "Bob Reviewer", report)
    assert _cli(capsys, plant["ana"], "verify", str(report))[0] == 0
    with psycopg.connect(plant[ROLE]) as db:
        assert db.execute("SELECT signer FROM report_signature").fetchall() == [("Bob Reviewer",)]
    assert Path(bob_file).exists()
    # a key is revoked by its own person, or by an administrator (a lost laptop), by nobody else
    bob_id = key_id_of(public_raw(bob_key))
    code, _, err = _cli(capsys, plant["dave"], "keys", "revoke", bob_id)
    assert code == 2 and f"key {bob_id} is Bob Reviewer's: the login dave (Dave Other) revokes only its " \
        "own keys (an administrator revokes anyone's)" in _one_line(err)
    assert _cli(capsys, plant["cleo"], "keys", "revoke", bob_id, "--reason", "laptop lost")[0] == 0


def test_twenty_writers_at_once_leave_every_fact_once(plant, postgres_cluster):
    write_at_once(lambda: Register(plant["ana"]), TABLE)
    super_url = postgres_cluster.url(_database(plant[ROLE]), "postgres", SUPER_PASSWORD)
    with psycopg.connect(super_url, autocommit=True) as db:
        notes = [r[0] for r in db.execute("SELECT note FROM snapshot")]
        assert sorted(notes) == NOTES  # every snapshot once
        assert sorted(r[0] for r in db.execute("SELECT note FROM alarm")) == NOTES
        assert db.execute("SELECT count(*) FROM check_result").fetchone() == (1,)
        assert db.execute("SELECT count(*), count(DISTINCT snapshot_id) FROM snapshot_value").fetchone() == (
            WRITERS * EACH * 20, WRITERS * EACH)
        receipts = db.execute("SELECT fact_table, count(*) FROM register_receipt WHERE received_by = 'ana'"
                              " GROUP BY fact_table ORDER BY fact_table").fetchall()
        assert receipts == [("alarm", WRITERS * EACH), ("check_result", 1), ("snapshot", WRITERS * EACH)]
        # the server's own checks: every constraint valid, every index's b-tree and its rows whole
        assert db.execute("SELECT count(*) FROM pg_constraint WHERE NOT convalidated").fetchone() == (0,)
        db.execute("CREATE EXTENSION IF NOT EXISTS amcheck")
        indexes = db.execute(
            "SELECT c.oid::regclass::text FROM pg_index i JOIN pg_class c ON c.oid = i.indexrelid"
            " JOIN pg_am a ON a.oid = c.relam WHERE a.amname = 'btree'"
            " AND c.relnamespace = 'public'::regnamespace").fetchall()
        for (index,) in indexes:
            db.execute("SELECT bt_index_parent_check(%s::regclass, true)", (index,))
        assert len(indexes) > 20



def test_an_upgrade_is_the_owners_and_gives_new_facts_their_rights(plant, monkeypatch, capsys):
    from fha_studio.logic.register import append_only, roles, schema
    from fha_studio.logic.register import store as register_store

    newer = (*schema.MIGRATIONS, ("CREATE TABLE brake_test (id INTEGER PRIMARY KEY, axis_id INTEGER NOT NULL"
                                  " REFERENCES axis(id), at_utc TEXT NOT NULL, holding_torque_nm REAL)",))
    monkeypatch.setattr(register_store, "MIGRATIONS", newer)
    monkeypatch.setattr(register_store, "SCHEMA_VERSION", len(newer))
    for module in (append_only, roles):
        monkeypatch.setattr(module, "FACT_TABLES", (*schema.FACT_TABLES, "brake_test"))
    with pytest.raises(RegisterError) as refused:  # a technician's newer FHA Studio: the owner upgrades
        Register(plant["ana"])
    assert str(refused.value).endswith(
        "ana may not do that: the register was written by an older FHA Studio: its owner brings it up to "
        "date (fha-studio register roles setup, run as the owner): nothing was changed")
    Register(plant[ROLE]).close()  # the owner's FHA Studio upgrades it, and gives the new table its rights
    with Register(plant["ana"]) as reg, reg.batch():
        reg._db.execute("INSERT INTO brake_test (axis_id, at_utc, holding_torque_nm) VALUES (?, ?, ?)",
                        (reg.axis(TABLE).id, clock.utc_iso(), 12.5))
    with psycopg.connect(plant["ana"], autocommit=True) as db:
        with pytest.raises(psycopg.errors.InsufficientPrivilege):
            db.execute("DELETE FROM brake_test")
        assert db.execute("SELECT received_by FROM register_receipt WHERE fact_table = 'brake_test'"
                          ).fetchall() == [("ana",)]
    with psycopg.connect(plant[ROLE], autocommit=True) as db, pytest.raises(
            psycopg.Error, match="append-only: brake_test are never changed"):
        db.execute("UPDATE brake_test SET holding_torque_nm = 0")
