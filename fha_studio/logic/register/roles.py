"""Roles on the server: who may add what to a plant's register, enforced by PostgreSQL itself.

The register's three roles are group roles of the server (NOLOGIN), named after the database
(``plant_register_technician``, ``..._reviewer``, ``..._administrator``: a role of one register
is no role of another on the same server). A person logs in with a login of their own (made with
PostgreSQL's ``createuser``) that is a member of one or more of them:

- **technician**: adds the facts of axes (snapshots, writes, checks, alarms, where procedures
  stand, recordings, model checks, notes, reports not signed) and changes an axis's actuator,
  driver, port, load inertia, serial number and notes (each change a line of its history);
- **reviewer**: signs reports (a report signed by name, a report's signature), adds notes;
- **administrator**: adds and renames machines and axes, says which person each login is.

Every role reads the whole register. Each person adds their own signing key and may revoke it
(an administrator may revoke anyone's: a lost laptop). The register's **owner** (the role that
made its tables, and runs ``register roles setup``) keeps the rest: migrations, roles, grants.
The owner is no role of FHA Studio's people: once the roles are set up the server refuses any
fact, machine or axis the owner would add (nobody works as the owner).

What the server enforces (the triggers and grants :func:`protection` makes, on top of the
append-only triggers every register has, :mod:`.append_only`):

- nobody changes or removes a fact (the owner neither: it could only drop the triggers);
- a role adds only what its grants allow; a refused write is one line naming the rule;
- **signing as someone else is refused**: a report signature must be made with a key of the
  person the connecting login is, and name that person; a report signed by name must name them;
  a key is added only by its own person;
- **when a fact reached the server is the server's to say**: each fact added gets a receipt
  (``register_receipt``: the table, the fact's id, the server's clock, the login; written by the
  server, readable by all, never changed), so a fact cannot be made to look as if it had been
  recorded earlier than it was; a fact dated or recorded later than the server's clock by more
  than :data:`FUTURE_TOLERANCE_S` is refused (a laptop's clock that is ahead), and so is one said
  to be recorded in the server's own register (``recorded_in``) earlier than that (back-dated).
  A fact dated earlier is taken (an alarm seen yesterday; a laptop that worked offline syncs days
  later, its facts recorded in its own register) and its receipt says when it came;
- a snapshot's values are added with the snapshot, in its transaction, never to it later;
- who each login is (``register_person``) is a row per change, stamped by the server.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from fha_studio.logic.register.append_only import PREFIX as APPEND_ONLY_PREFIX
from fha_studio.logic.register.append_only import refusal_text
from fha_studio.logic.register.guard import RegisterError
from fha_studio.logic.register.schema import ENTITY_TABLES, FACT_TABLES, REGISTER_TABLES

#: The register's roles, in words for people and in the group role's name.
ROLES = ("technician", "reviewer", "administrator")
#: What each role does, as a refusal and ``roles list`` say it.
ROLE_WORDS = {
    "technician": "adds the facts of axes",
    "reviewer": "signs reports",
    "administrator": "adds machines and axes, says who each login is",
}
#: A fact dated later than the server's clock by more than this is refused.
FUTURE_TOLERANCE_S = 300
#: The server's SQLSTATE for a write a rule of the roles refuses.
SQLSTATE = "FH002"
#: How such a refusal's message begins.
REFUSED = "refused:"
#: Every trigger made here begins with this.
TRIGGER_PREFIX = "register_role_"
#: The axis's fields a technician may change (each change goes into the axis's history).
TECHNICIAN_AXIS_FIELDS = (
    "actuator_code", "driver_model", "port_url", "load_inertia_kgm2", "notes", "serial_number",
)
#: The facts a reviewer adds.
REVIEWER_TABLES = ("report", "report_signature", "signing_key", "key_revocation", "axis_event")
#: The facts only a reviewer adds.
REVIEWER_ONLY = ("report_signature",)
#: What only the owner writes: the register's own id, made with it.
OWNER_ONLY = ("this_register",)
#: What an administrator adds (and changes: machines and axes).
ADMINISTRATOR_TABLES = ("machine", "axis", "axis_event", "signing_key", "key_revocation", "register_person")
#: The column that says when a fact happened, by table (the first of these it has).
TIME_COLUMNS = ("at_utc", "updated_utc", "signed_utc", "created_utc")
#: The tables the roles add beside the register's own (server only).
ROLE_TABLES = ("register_person", "register_receipt")


class RolesError(RegisterError):
    """The roles cannot be set up or given: one line saying what and who can."""


def group_role(database: str, role: str) -> str:
    """The server's group role of ``role`` in the register ``database``."""
    if role not in ROLES:
        raise RolesError(f"{role!r} is not a role of the register (roles: {', '.join(ROLES)})")
    name = f"{database}_{role}"
    if len(name.encode("utf-8")) > 63:
        raise RolesError(f"database {database!r}: its name is too long for the roles' names "
                         "(at most 63 bytes with '_administrator')")
    return name


def ident(name: str) -> str:
    """``name`` as an SQL identifier."""
    return '"' + name.replace('"', '""') + '"'


def literal(text: str) -> str:
    """``text`` as an SQL string."""
    return "'" + text.replace("'", "''") + "'"


@dataclass(frozen=True)
class Catalog:
    """What protection needs to know of the database: its name and schema, its tables with their
    columns, each table's key column for a receipt."""

    database: str
    schema: str
    owner: str  # the role that owns the register's tables
    columns: dict[str, list[str]]
    keys: dict[str, str]

    @classmethod
    def read(cls, db: Any) -> Catalog:
        """From an open connection (psycopg's or the register's :class:`~.server.ServerDatabase`)."""
        database, schema, owner = db.execute(
            "SELECT current_database(), current_schema(), (SELECT tableowner FROM pg_tables"
            " WHERE tablename = 'register_schema' AND schemaname = current_schema())").fetchone()
        columns: dict[str, list[str]] = {}
        for table, column in db.execute(
            "SELECT table_name, column_name FROM information_schema.columns"
            " WHERE table_schema = current_schema() ORDER BY table_name, ordinal_position"
        ).fetchall():
            columns.setdefault(str(table), []).append(str(column))
        primary: dict[str, list[str]] = {}
        for table, column in db.execute(
            "SELECT c.relname, a.attname FROM pg_index i JOIN pg_class c ON c.oid = i.indrelid"
            " JOIN pg_attribute a ON a.attrelid = c.oid AND a.attnum = ANY(i.indkey)"
            " WHERE i.indisprimary AND c.relnamespace = current_schema()::regnamespace"
        ).fetchall():
            primary.setdefault(str(table), []).append(str(column))
        keys = {}
        for table, names in columns.items():
            # a fact's number (its history line's), else its own key
            if "id" in names:
                keys[table] = "id"
            elif len(primary.get(table, [])) == 1:
                keys[table] = primary[table][0]
        return cls(str(database), str(schema), str(owner or ""), columns, keys)


def has_receipts(db: Any) -> bool:
    """Whether the register on the server keeps receipts (its roles are set up)."""
    row = db.execute("SELECT to_regclass('register_receipt') IS NOT NULL").fetchone()
    return bool(row and row[0])


def receipts(db: Any, table: str, axis_id: int) -> dict[int, tuple[str, str]]:
    """{fact number: (when the server received it, ISO UTC; the login)} of an axis's facts of
    ``table`` (a table of :data:`~.schema.FACT_TABLES` with ``id`` and ``axis_id``)."""
    rows = db.execute(
        f"SELECT t.id, to_char(r.received_utc AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI:SS.US\"+00:00\"'),"
        f" r.received_by FROM {table} t JOIN register_receipt r ON r.fact_table = '{table}'"
        " AND r.fact_key = t.id::text WHERE t.axis_id = ?", (axis_id,)).fetchall()
    return {int(r[0]): (str(r[1]), str(r[2])) for r in rows}


def is_set_up(db: Any) -> bool:
    """Whether ``register roles setup`` has been run on the register (its tables are there)."""
    row = db.execute("SELECT to_regclass('register_person') IS NOT NULL").fetchone()
    return bool(row and row[0])


def role_tables(catalog: Catalog) -> list[str]:
    """The statements making the roles' own tables (server only; never changed once written)."""
    return [
        """CREATE TABLE IF NOT EXISTS register_person (
            id BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
            login TEXT COLLATE "C" NOT NULL,
            person TEXT COLLATE "C" NOT NULL,
            at_utc TIMESTAMPTZ NOT NULL DEFAULT clock_timestamp(),
            by_login TEXT COLLATE "C" NOT NULL DEFAULT session_user
        )""",
        "CREATE INDEX IF NOT EXISTS register_person_by_login ON register_person (login, id)",
        """CREATE TABLE IF NOT EXISTS register_receipt (
            fact_table TEXT COLLATE "C" NOT NULL,
            fact_key TEXT COLLATE "C" NOT NULL,
            received_utc TIMESTAMPTZ NOT NULL,
            received_by TEXT COLLATE "C" NOT NULL,
            in_transaction XID8 NOT NULL,
            PRIMARY KEY (fact_table, fact_key)
        )""",
    ]


def _functions(catalog: Catalog) -> list[str]:
    """The trigger functions (one register's: they name its roles)."""
    path = f"SET search_path = {ident(catalog.schema)}, pg_temp"
    reviewer = literal(group_role(catalog.database, "reviewer"))
    administrator = literal(group_role(catalog.database, "administrator"))
    later = f"interval '{FUTURE_TOLERANCE_S} seconds'"
    # the refusal's words: "refused: <why>"; a login's person, and this login in words
    return [
        f"""CREATE OR REPLACE FUNCTION register_refuse(reason TEXT) RETURNS void LANGUAGE plpgsql AS $fn$
        BEGIN
            RAISE EXCEPTION USING ERRCODE = '{SQLSTATE}', MESSAGE = '{REFUSED} ' || reason;
        END $fn$""",
        f"""CREATE OR REPLACE FUNCTION register_person_of(login_name TEXT) RETURNS TEXT
        LANGUAGE sql STABLE {path} AS $fn$
            SELECT NULLIF(person, '') FROM register_person WHERE login = login_name ORDER BY id DESC LIMIT 1
        $fn$""",
        f"""CREATE OR REPLACE FUNCTION register_me() RETURNS TEXT LANGUAGE plpgsql STABLE {path} AS $fn$
        DECLARE
            me TEXT := register_person_of(session_user::text);
        BEGIN
            IF me IS NULL THEN
                PERFORM register_refuse('the login ' || session_user || ' is no person of this register '
                    || '(its owner says who: fha-studio register roles grant LOGIN ROLE --person NAME)');
            END IF;
            RETURN me;
        END $fn$""",
        f"""CREATE OR REPLACE FUNCTION register_check_signer() RETURNS trigger LANGUAGE plpgsql {path} AS $fn$
        DECLARE
            me TEXT := register_me();
            owner TEXT;
        BEGIN
            SELECT person INTO owner FROM signing_key WHERE key_id = NEW.key_id;
            IF NEW.signer IS DISTINCT FROM me OR owner IS DISTINCT FROM me THEN
                PERFORM register_refuse('signing as someone else: the login ' || session_user || ' is '
                    || me || '; the signature is ' || NEW.signer || '''s, with key ' || NEW.key_id
                    || ' of ' || coalesce(owner, 'nobody in the register'));
            END IF;
            RETURN NEW;
        END $fn$""",
        f"""CREATE OR REPLACE FUNCTION register_check_report() RETURNS trigger LANGUAGE plpgsql {path} AS $fn$
        DECLARE
            me TEXT;
        BEGIN
            IF NEW.signed_by <> '' THEN
                me := register_me();
                IF NOT pg_has_role(session_user, {reviewer}, 'MEMBER') THEN
                    PERFORM register_refuse('only a reviewer signs reports: the login ' || session_user
                        || ' (' || me || ') is none');
                END IF;
                IF NEW.signed_by IS DISTINCT FROM me THEN
                    PERFORM register_refuse('signing as someone else: the login ' || session_user || ' is '
                        || me || '; the report says signed by ' || NEW.signed_by);
                END IF;
            END IF;
            RETURN NEW;
        END $fn$""",
        f"""CREATE OR REPLACE FUNCTION register_check_key() RETURNS trigger LANGUAGE plpgsql {path} AS $fn$
        DECLARE
            me TEXT := register_me();
        BEGIN
            IF NEW.person IS DISTINCT FROM me THEN
                PERFORM register_refuse('a key in someone else''s name: the login ' || session_user || ' is '
                    || me || ', the key says ' || NEW.person || ' (each person adds their own key)');
            END IF;
            RETURN NEW;
        END $fn$""",
        f"""CREATE OR REPLACE FUNCTION register_check_revocation() RETURNS trigger LANGUAGE plpgsql {path}
        AS $fn$
        DECLARE
            me TEXT := register_me();
            owner TEXT;
        BEGIN
            SELECT person INTO owner FROM signing_key WHERE key_id = NEW.key_id;
            IF owner IS DISTINCT FROM me AND NOT pg_has_role(session_user, {administrator}, 'MEMBER') THEN
                PERFORM register_refuse('key ' || NEW.key_id || ' is ' || coalesce(owner, 'nobody') || '''s: '
                    || 'the login ' || session_user || ' (' || me || ') revokes only its own keys '
                    || '(an administrator revokes anyone''s)');
            END IF;
            RETURN NEW;
        END $fn$""",
        """CREATE OR REPLACE FUNCTION register_time(said TEXT) RETURNS TIMESTAMPTZ LANGUAGE plpgsql
        STABLE AS $fn$
        BEGIN
            RETURN said::timestamptz;
        EXCEPTION WHEN others THEN
            RETURN NULL;
        END $fn$""",
        """CREATE OR REPLACE FUNCTION register_utc(moment TIMESTAMPTZ) RETURNS TEXT LANGUAGE sql
        IMMUTABLE AS $fn$
            SELECT to_char(moment AT TIME ZONE 'UTC', 'YYYY-MM-DD HH24:MI:SS') || ' UTC'
        $fn$""",
        f"""CREATE OR REPLACE FUNCTION register_check_time() RETURNS trigger LANGUAGE plpgsql {path} AS $fn$
        DECLARE
            fact JSONB := to_jsonb(NEW);
            moment TIMESTAMPTZ := register_time(fact ->> TG_ARGV[0]);
            recorded TIMESTAMPTZ;
            server TIMESTAMPTZ := clock_timestamp();
        BEGIN
            IF moment IS NULL THEN
                PERFORM register_refuse(coalesce(quote_literal(fact ->> TG_ARGV[0]), 'no time')
                    || ' is not a time');
            END IF;
            IF moment > server + {later} THEN
                PERFORM register_refuse('dated ' || register_utc(moment) || ', later than the '
                    || 'server''s clock (' || register_utc(server) || ') by more than '
                    || '{FUTURE_TOLERANCE_S // 60} minutes: is this computer''s clock right?');
            END IF;
            -- when it was recorded, and where: recorded here, it was recorded now (never back-dated)
            IF TG_NARGS > 1 AND coalesce(fact ->> 'recorded_utc', '') <> '' THEN
                recorded := register_time(fact ->> 'recorded_utc');
                IF recorded IS NULL THEN
                    PERFORM register_refuse(quote_literal(fact ->> 'recorded_utc') || ' is not a time');
                END IF;
                IF recorded > server + {later} THEN
                    PERFORM register_refuse('recorded ' || register_utc(recorded) || ', later than the '
                        || 'server''s clock (' || register_utc(server) || ') by more than '
                        || '{FUTURE_TOLERANCE_S // 60} minutes: is this computer''s clock right?');
                END IF;
                IF recorded < server - {later}
                        AND fact ->> 'recorded_in' = (SELECT register_id FROM this_register LIMIT 1) THEN
                    PERFORM register_refuse('back-dated: said to be recorded in this register at '
                        || register_utc(recorded) || ', but the server''s clock says '
                        || register_utc(server) || ' (a fact is recorded when it is; '
                        || 'is this computer''s clock right?)');
                END IF;
            END IF;
            RETURN NEW;
        END $fn$""",
        f"""CREATE OR REPLACE FUNCTION register_not_owner() RETURNS trigger LANGUAGE plpgsql AS $fn$
        BEGIN
            IF session_user = {literal(catalog.owner)} THEN
                PERFORM register_refuse('the register''s owner, ' || session_user || ', records nothing: '
                    || 'people work with their own logins (fha-studio register roles grant LOGIN ROLE '
                    || '--person NAME)');
            END IF;
            RETURN NEW;
        END $fn$""",
        f"""CREATE OR REPLACE FUNCTION register_receive() RETURNS trigger LANGUAGE plpgsql
        SECURITY DEFINER {path} AS $fn$
        BEGIN
            INSERT INTO register_receipt (fact_table, fact_key, received_utc, received_by, in_transaction)
            VALUES (TG_TABLE_NAME, to_jsonb(NEW) ->> TG_ARGV[0], clock_timestamp(), session_user,
                    pg_current_xact_id());
            RETURN NULL;
        END $fn$""",
        f"""CREATE OR REPLACE FUNCTION register_check_values() RETURNS trigger LANGUAGE plpgsql {path} AS $fn$
        BEGIN
            IF NOT EXISTS (SELECT 1 FROM register_receipt WHERE fact_table = 'snapshot'
                    AND fact_key = NEW.snapshot_id::text AND in_transaction = pg_current_xact_id()) THEN
                PERFORM register_refuse('snapshot ' || NEW.snapshot_id || ' was recorded before: '
                    || 'values are added with their snapshot, never to it later');
            END IF;
            RETURN NEW;
        END $fn$""",
        f"""CREATE OR REPLACE FUNCTION register_stamp_person() RETURNS trigger LANGUAGE plpgsql {path} AS $fn$
        BEGIN
            NEW.at_utc := clock_timestamp();
            NEW.by_login := session_user;
            RETURN NEW;
        END $fn$""",
    ]


def protection(catalog: Catalog) -> list[str]:
    """The statements giving the register's roles their rights and making the triggers that hold
    them to them (every one can be run again: after a migration, the owner runs them anew)."""
    groups = {role: ident(group_role(catalog.database, role)) for role in ROLES}
    everyone = ", ".join(groups.values())
    tables = set(catalog.columns)
    out = [*_functions(catalog)]
    out += [
        f"REVOKE ALL ON DATABASE {ident(catalog.database)} FROM PUBLIC",
        # (temporary tables: a sync brings many facts in through one, COPY then INSERT)
        f"GRANT CONNECT, TEMPORARY ON DATABASE {ident(catalog.database)} TO {everyone}",
        f"GRANT USAGE ON SCHEMA {ident(catalog.schema)} TO {everyone}",
        f"GRANT SELECT ON ALL TABLES IN SCHEMA {ident(catalog.schema)} TO {everyone}",
    ]
    technician = [t for t in (*FACT_TABLES, *REGISTER_TABLES)
                  if t in tables and t not in REVIEWER_ONLY and t not in OWNER_ONLY]
    out.append(f"GRANT INSERT ON {', '.join(technician)} TO {groups['technician']}")
    fields = [c for c in TECHNICIAN_AXIS_FIELDS if c in catalog.columns.get("axis", [])]
    out.append(f"GRANT UPDATE ({', '.join(fields)}) ON axis TO {groups['technician']}")
    out.append(f"GRANT INSERT ON {', '.join(t for t in REVIEWER_TABLES if t in tables)}"
               f" TO {groups['reviewer']}")
    out.append(f"GRANT INSERT ON {', '.join(t for t in ADMINISTRATOR_TABLES if t in tables)}"
               f" TO {groups['administrator']}")
    out.append(f"GRANT UPDATE ON machine, axis TO {groups['administrator']}")

    def trigger(name: str, table: str, when: str, function: str, *args: str) -> str:
        given = ", ".join(literal(a) for a in args)
        return (f"CREATE OR REPLACE TRIGGER {TRIGGER_PREFIX}{name}_{table} {when} ON {table}"
                f" FOR EACH ROW EXECUTE FUNCTION {function}({given})")

    for table in (*ENTITY_TABLES, *FACT_TABLES, *REGISTER_TABLES):
        if table in tables and table not in OWNER_ONLY:
            out.append(trigger("owner", table, "BEFORE INSERT", "register_not_owner"))
    for table in (*FACT_TABLES, *REGISTER_TABLES):
        if table not in tables:
            continue
        columns = catalog.columns[table]
        time = next((c for c in TIME_COLUMNS if c in columns), None)
        if time is not None:
            recorded = ("recorded",) if {"recorded_in", "recorded_utc"} <= set(columns) else ()
            out.append(trigger("time", table, "BEFORE INSERT", "register_check_time", time, *recorded))
        if table in catalog.keys and table != "snapshot_value":  # a snapshot's receipt is its values'
            out.append(trigger("receipt", table, "AFTER INSERT", "register_receive", catalog.keys[table]))
    checks = {
        "report_signature": "register_check_signer",
        "report": "register_check_report",
        "signing_key": "register_check_key",
        "key_revocation": "register_check_revocation",
    }
    for table, function in checks.items():
        if table in tables:
            out.append(trigger("who", table, "BEFORE INSERT", function))
    if "snapshot_value" in tables:
        out.append(trigger("values", "snapshot_value", "BEFORE INSERT", "register_check_values"))
    out.append(trigger("stamp", "register_person", "BEFORE INSERT", "register_stamp_person"))
    for table, words in (("register_person", "who each login is"), ("register_receipt", "receipts")):
        said = literal(f"append-only: {words} are never changed or removed")
        out.append(f"CREATE OR REPLACE TRIGGER {APPEND_ONLY_PREFIX}change_{table} BEFORE UPDATE OR DELETE"
                   f" ON {table} FOR EACH ROW EXECUTE FUNCTION {APPEND_ONLY_PREFIX}refuse({said})")
        out.append(f"CREATE OR REPLACE TRIGGER {APPEND_ONLY_PREFIX}truncate_{table} BEFORE TRUNCATE"
                   f" ON {table} FOR EACH STATEMENT EXECUTE FUNCTION {APPEND_ONLY_PREFIX}refuse({said})")
    return out


@dataclass(frozen=True)
class Member:
    """A login of the server with the register's roles it has, and the person it is."""

    login: str
    person: str
    roles: tuple[str, ...]


def members(db: Any, database: str) -> list[Member]:
    """Every login with a role of the register ``database``, and every login it knows the person of."""
    groups = {group_role(database, r): r for r in ROLES}
    found: dict[str, set[str]] = {}
    for login, group in db.execute(
        "SELECT m.rolname, g.rolname FROM pg_auth_members am JOIN pg_roles m ON m.oid = am.member"
        " JOIN pg_roles g ON g.oid = am.roleid WHERE g.rolname = ANY(%s)", (list(groups),)
    ).fetchall():
        found.setdefault(str(login), set()).add(groups[str(group)])
    persons = {str(login): str(person) for login, person in db.execute(
        "SELECT DISTINCT ON (login) login, person FROM register_person ORDER BY login, id DESC"
    ).fetchall()}
    logins = sorted(set(found) | {k for k, v in persons.items() if v})
    return [Member(login, persons.get(login, ""), tuple(r for r in ROLES if r in found.get(login, set())))
            for login in logins]


def refused_words(message: str) -> str:
    """A refusal of the roles' triggers without its prefix (its first line)."""
    first = message.strip().splitlines()[0] if message.strip() else ""
    return first[len(REFUSED):].strip() if first.startswith(REFUSED) else first


#: Who may write each table, for a refusal of the server's grants.
_WHO_WRITES = {
    "machine": "an administrator of the register adds and renames machines and axes",
    "axis": "an administrator of the register adds and renames machines and axes",
    "report_signature": "a reviewer signs reports",
    "register_person": "an administrator says who each login is",
    "register_schema": "the register's owner brings it up to date (fha-studio register roles setup)",
    "register_receipt": "the server writes the receipts itself",
    "this_register": "the register's own id is made with it, by its owner",
}


def who_writes(table: str) -> str:
    """The rule that gives the right to write ``table``, in words ("" for a table the register
    does not know)."""
    if table in _WHO_WRITES:
        return _WHO_WRITES[table]
    if table in FACT_TABLES:
        what = refusal_text(table).split(" are ")[0]
        return f"a technician adds {what}, and nobody changes or removes them"
    return ""


def names_listed(items: Iterable[str]) -> str:
    return ", ".join(items) or "none"

