"""The register's schema and its migrations, versioned with SQLite's ``PRAGMA user_version``.

A file's ``user_version`` is the number of migrations applied to it. Opening a file applies the
missing ones in order, each in its own ``BEGIN IMMEDIATE`` transaction that also sets the
version, so that a crash mid-migration leaves the file at the previous version, whole, and two
processes opening one old file migrate it once. A file newer than this program is refused, never
"downgraded".

Times are UTC, ISO 8601 to the microsecond (``2026-11-30T04:05:06.000000+00:00``), so that text
order is time order. Parameter values are the drive's wire integers (the parameter model's
``scale`` converts), named by the manual's key (``rotary_direction``) beside mode and number.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from fha_studio.logic.register.identity import OLDER_UID_TABLES, give_ids

#: A migration's step: a statement, or a function of the connection for what SQL alone does not
#: say the same way on both stores (the new ids of the facts already there).
Statement = str | Callable[[Any], None]

# Each migration is a list of statements (run one by one: sqlite3's executescript would commit
# the transaction the migration runs in).
_V1 = [
    """CREATE TABLE machine (
        id INTEGER PRIMARY KEY,
        name TEXT NOT NULL UNIQUE,
        site TEXT NOT NULL DEFAULT '',
        notes TEXT NOT NULL DEFAULT '',
        created_utc TEXT NOT NULL
    )""",
    """CREATE TABLE axis (
        id INTEGER PRIMARY KEY,
        machine_id INTEGER NOT NULL REFERENCES machine(id),
        name TEXT NOT NULL,
        actuator_code TEXT NOT NULL DEFAULT '',
        driver_model TEXT NOT NULL DEFAULT '',
        port_url TEXT NOT NULL DEFAULT '',
        load_inertia_kgm2 REAL,
        notes TEXT NOT NULL DEFAULT '',
        created_utc TEXT NOT NULL,
        UNIQUE (machine_id, name)
    )""",
    # what happened to the axis itself: created, actuator or driver changed, a note
    """CREATE TABLE axis_event (
        id INTEGER PRIMARY KEY,
        axis_id INTEGER NOT NULL REFERENCES axis(id),
        at_utc TEXT NOT NULL,
        who TEXT NOT NULL DEFAULT '',
        text TEXT NOT NULL
    )""",
    """CREATE TABLE snapshot (
        id INTEGER PRIMARY KEY,
        axis_id INTEGER NOT NULL REFERENCES axis(id),
        at_utc TEXT NOT NULL,
        who TEXT NOT NULL DEFAULT '',
        source TEXT NOT NULL CHECK (source IN ('link', 'front_panel', 'file')),
        driver_model TEXT NOT NULL DEFAULT '',
        file TEXT NOT NULL DEFAULT '',
        note TEXT NOT NULL DEFAULT ''
    )""",
    """CREATE TABLE snapshot_value (
        snapshot_id INTEGER NOT NULL REFERENCES snapshot(id) ON DELETE CASCADE,
        mode TEXT NOT NULL,
        number INTEGER NOT NULL,
        key TEXT NOT NULL,
        value INTEGER NOT NULL,
        PRIMARY KEY (snapshot_id, mode, number)
    )""",
    """CREATE TABLE parameter_write (
        id INTEGER PRIMARY KEY,
        axis_id INTEGER NOT NULL REFERENCES axis(id),
        at_utc TEXT NOT NULL,
        who TEXT NOT NULL DEFAULT '',
        mode TEXT NOT NULL,
        number INTEGER NOT NULL,
        key TEXT NOT NULL,
        old INTEGER,
        new INTEGER NOT NULL,
        read_back INTEGER,
        verified INTEGER NOT NULL,
        error TEXT NOT NULL DEFAULT ''
    )""",
    # where each procedure of an axis stands (one row per procedure, replaced as it moves on)
    """CREATE TABLE procedure_run (
        axis_id INTEGER NOT NULL REFERENCES axis(id),
        procedure_id TEXT NOT NULL,
        title TEXT NOT NULL,
        section TEXT NOT NULL DEFAULT '',
        status TEXT NOT NULL,
        updated_utc TEXT NOT NULL,
        session_file TEXT NOT NULL DEFAULT '',
        PRIMARY KEY (axis_id, procedure_id)
    )""",
    # every answer to every check; the same answer recorded twice (live, then from the session
    # file) is one row
    """CREATE TABLE check_result (
        id INTEGER PRIMARY KEY,
        axis_id INTEGER NOT NULL REFERENCES axis(id),
        procedure_id TEXT NOT NULL,
        step_id TEXT NOT NULL,
        kind TEXT NOT NULL,
        section TEXT NOT NULL DEFAULT '',
        text TEXT NOT NULL DEFAULT '',
        value_json TEXT NOT NULL,
        expected TEXT NOT NULL DEFAULT '',
        unit TEXT NOT NULL DEFAULT '',
        passed INTEGER NOT NULL,
        who TEXT NOT NULL DEFAULT '',
        at_utc TEXT NOT NULL,
        detail TEXT NOT NULL DEFAULT '',
        session_file TEXT NOT NULL DEFAULT '',
        UNIQUE (axis_id, procedure_id, step_id, at_utc)
    )""",
    """CREATE TABLE alarm (
        id INTEGER PRIMARY KEY,
        axis_id INTEGER NOT NULL REFERENCES axis(id),
        at_utc TEXT NOT NULL,
        who TEXT NOT NULL DEFAULT '',
        code INTEGER NOT NULL,
        name TEXT NOT NULL DEFAULT '',
        note TEXT NOT NULL DEFAULT ''
    )""",
    # a report of one axis (axis_id set) or of a whole machine (axis_id NULL)
    """CREATE TABLE report (
        id INTEGER PRIMARY KEY,
        machine_id INTEGER NOT NULL REFERENCES machine(id),
        axis_id INTEGER REFERENCES axis(id),
        at_utc TEXT NOT NULL,
        who TEXT NOT NULL DEFAULT '',
        file TEXT NOT NULL,
        sha256 TEXT NOT NULL,
        signed_by TEXT NOT NULL DEFAULT '',
        signed_utc TEXT NOT NULL DEFAULT '',
        open_warnings INTEGER NOT NULL DEFAULT 0
    )""",
    """CREATE TABLE recording (
        id INTEGER PRIMARY KEY,
        axis_id INTEGER NOT NULL REFERENCES axis(id),
        at_utc TEXT NOT NULL,
        who TEXT NOT NULL DEFAULT '',
        file TEXT NOT NULL,
        sha256 TEXT NOT NULL DEFAULT '',
        summary TEXT NOT NULL DEFAULT ''
    )""",
    """CREATE TABLE model_check (
        id INTEGER PRIMARY KEY,
        axis_id INTEGER NOT NULL REFERENCES axis(id),
        at_utc TEXT NOT NULL,
        who TEXT NOT NULL DEFAULT '',
        file TEXT NOT NULL DEFAULT '',
        recording_file TEXT NOT NULL DEFAULT '',
        summary TEXT NOT NULL DEFAULT ''
    )""",
    "CREATE INDEX axis_event_by_axis ON axis_event (axis_id, at_utc)",
    "CREATE INDEX snapshot_by_axis ON snapshot (axis_id, at_utc)",
    "CREATE INDEX parameter_write_by_axis ON parameter_write (axis_id, at_utc)",
    "CREATE INDEX check_result_by_axis ON check_result (axis_id, at_utc)",
    "CREATE INDEX alarm_by_axis ON alarm (axis_id, at_utc)",
    "CREATE INDEX report_by_machine ON report (machine_id, axis_id, at_utc)",
    "CREATE INDEX recording_by_axis ON recording (axis_id, at_utc)",
    "CREATE INDEX model_check_by_axis ON model_check (axis_id, at_utc)",
]

# v2: the serial number from the actuator's label (a replaced actuator on the same axis shows in
# its history, the model code alone does not tell two FHA-25C-50 apart), and an index for "which
# axes have this parameter value" that does not scan every snapshot.
_V2 = [
    "ALTER TABLE axis ADD COLUMN serial_number TEXT NOT NULL DEFAULT ''",
    "CREATE INDEX snapshot_value_by_key ON snapshot_value (key, value)",
    "CREATE INDEX parameter_write_by_key ON parameter_write (key, axis_id)",
]

# v3: the people's public signing keys (Ed25519) and the signatures made with them. Append-only:
# a key is never replaced (a new key is a new row, a revoked key a row of key_revocation), a
# signature is a row of its own; ids are the key's fingerprint and the signature itself, the same
# in every register a fact travels to.
_V3 = [
    """CREATE TABLE signing_key (
        key_id TEXT PRIMARY KEY,
        person TEXT NOT NULL,
        public_key TEXT NOT NULL UNIQUE,
        created_utc TEXT NOT NULL,
        who TEXT NOT NULL DEFAULT ''
    )""",
    """CREATE TABLE key_revocation (
        key_id TEXT PRIMARY KEY REFERENCES signing_key(key_id),
        at_utc TEXT NOT NULL,
        who TEXT NOT NULL DEFAULT '',
        reason TEXT NOT NULL DEFAULT ''
    )""",
    """CREATE TABLE report_signature (
        signature TEXT PRIMARY KEY,
        key_id TEXT NOT NULL REFERENCES signing_key(key_id),
        signer TEXT NOT NULL,
        signed_utc TEXT NOT NULL,
        sha256 TEXT NOT NULL,
        file TEXT NOT NULL DEFAULT ''
    )""",
    "CREATE INDEX signing_key_by_person ON signing_key (person, created_utc)",
    "CREATE INDEX report_signature_by_sha256 ON report_signature (sha256)",
]

# v4: "which axes have this parameter value" over a plant's register (a thousand axes, ten years of
# writes each) looks up each axis's latest write of the parameter in this index, not every write.
_V4 = [
    "CREATE INDEX parameter_write_latest ON parameter_write (axis_id, key, at_utc, id)",
    "CREATE INDEX snapshot_latest ON snapshot (axis_id, at_utc, id)",
]

#: The tables a person may correct a fact of: the correction is a new row of the same table whose
#: ``corrects`` names the row it corrects (never a change of that row).
CORRECTABLE_TABLES = (
    "axis_event", "snapshot", "parameter_write", "check_result", "alarm", "report", "recording",
    "model_check",
)

# v5: history that nobody rewrites. Where a procedure stands is a row of its own each time it moves
# on (it was one row per procedure, replaced: the table is made anew, its rows kept in the order
# they were last written); a fact recorded wrong is corrected by a new fact that points at it.
_V5 = [
    """CREATE TABLE procedure_run_v5 (
        id INTEGER PRIMARY KEY,
        axis_id INTEGER NOT NULL REFERENCES axis(id),
        procedure_id TEXT NOT NULL,
        title TEXT NOT NULL,
        section TEXT NOT NULL DEFAULT '',
        status TEXT NOT NULL,
        updated_utc TEXT NOT NULL,
        session_file TEXT NOT NULL DEFAULT ''
    )""",
    "INSERT INTO procedure_run_v5 (axis_id, procedure_id, title, section, status, updated_utc, session_file)"
    " SELECT axis_id, procedure_id, title, section, status, updated_utc, session_file FROM procedure_run"
    " ORDER BY rowid",
    "DROP TABLE procedure_run",
    "ALTER TABLE procedure_run_v5 RENAME TO procedure_run",
    "CREATE INDEX procedure_run_latest ON procedure_run (axis_id, procedure_id, updated_utc, id)",
    *(f"ALTER TABLE {table} ADD COLUMN corrects INTEGER REFERENCES {table}(id)"
      for table in CORRECTABLE_TABLES),
]

# v6: facts that travel between registers (a laptop's file and the plant's server, `register
# sync`). Every fact gets a stable id where it is first recorded, the same in every register it is
# synced to, and keeps where (the register's id) and when it was recorded (identity.py); the facts
# already there get theirs now. A register knows its own id and the names of the registers its
# facts came from. An axis event says what it set (``data``: the fields of an axis added, a field
# changed, an origin), so that a register an event is synced to sets the same. A conflict: an axis
# changed in two registers while they were apart, the two sides' values kept for a person to settle
# by a resolution (a fact of its own that names the conflict); nothing is picked silently.
_FACT_ID_COLUMNS_SQL = """uid TEXT NOT NULL UNIQUE,
        recorded_in TEXT NOT NULL DEFAULT '',
        recorded_utc TEXT NOT NULL DEFAULT '',
        uid_hash INTEGER NOT NULL DEFAULT 0"""
_V6: list[Statement] = [
    """CREATE TABLE known_register (
        register_id TEXT PRIMARY KEY,
        name TEXT NOT NULL DEFAULT '',
        created_utc TEXT NOT NULL
    )""",
    """CREATE TABLE this_register (
        register_id TEXT PRIMARY KEY REFERENCES known_register(register_id)
    )""",
    *(
        f"ALTER TABLE {table} ADD COLUMN {column}"
        for table in OLDER_UID_TABLES
        for column in (
            "uid TEXT NOT NULL DEFAULT ''",
            "recorded_in TEXT NOT NULL DEFAULT ''",
            "recorded_utc TEXT NOT NULL DEFAULT ''",
            "uid_hash INTEGER NOT NULL DEFAULT 0",
        )
    ),
    "ALTER TABLE axis_event ADD COLUMN data TEXT NOT NULL DEFAULT ''",
    give_ids,
    *(f"CREATE UNIQUE INDEX {table}_by_uid ON {table} (uid)" for table in OLDER_UID_TABLES),
    f"""CREATE TABLE conflict (
        id INTEGER PRIMARY KEY,
        axis_id INTEGER NOT NULL REFERENCES axis(id),
        at_utc TEXT NOT NULL,
        who TEXT NOT NULL DEFAULT '',
        subject TEXT NOT NULL,
        sides_json TEXT NOT NULL,
        {_FACT_ID_COLUMNS_SQL}
    )""",
    f"""CREATE TABLE conflict_resolution (
        id INTEGER PRIMARY KEY,
        conflict_uid TEXT NOT NULL REFERENCES conflict(uid),
        axis_id INTEGER NOT NULL REFERENCES axis(id),
        at_utc TEXT NOT NULL,
        who TEXT NOT NULL DEFAULT '',
        kept INTEGER NOT NULL,
        settled_json TEXT NOT NULL,
        note TEXT NOT NULL DEFAULT '',
        {_FACT_ID_COLUMNS_SQL}
    )""",
    "CREATE INDEX conflict_by_axis ON conflict (axis_id, at_utc)",
    "CREATE INDEX conflict_resolution_by_conflict ON conflict_resolution (conflict_uid)",
    "CREATE INDEX conflict_resolution_by_axis ON conflict_resolution (axis_id, at_utc)",
]

#: MIGRATIONS[n] takes a file from user_version n to n + 1.
MIGRATIONS: tuple[tuple[Statement, ...], ...] = (
    tuple(_V1), tuple(_V2), tuple(_V3), tuple(_V4), tuple(_V5), tuple(_V6)
)

#: The version this program writes.
SCHEMA_VERSION = len(MIGRATIONS)

#: The tables of facts: rows are added, never changed or removed (on both stores the database
#: refuses it: :mod:`.append_only`). A new table of facts goes here.
FACT_TABLES = (
    "axis_event", "snapshot", "snapshot_value", "parameter_write", "procedure_run", "check_result", "alarm",
    "report", "recording", "model_check", "signing_key", "key_revocation", "report_signature",
    "conflict", "conflict_resolution", "known_register", "this_register",
)
#: The tables of things facts are about: changed (each change a fact of the axis's history), never
#: removed.
ENTITY_TABLES = ("machine", "axis")
#: The register's own bookkeeping, neither facts nor what they are about (a technician's program
#: may add to them on a server with roles, :mod:`.roles`).
REGISTER_TABLES: tuple[str, ...] = ()
