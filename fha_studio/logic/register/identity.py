"""A fact's identity, the same in every register it travels to (no Qt).

Every fact (a line of an axis's history: a snapshot, a write, a check, an alarm, a report, a
recording, a model check, an axis event, a conflict and its resolution) gets a stable id where it
is first recorded, a UUID (``uid``), kept forever: a sync between two registers (a laptop's file
and the plant's server) tells the facts one has and the other lacks by it. Beside it a fact keeps
where it was recorded (``recorded_in``: the id of the register, each file and each server has its
own, made when the register is made) and when (``recorded_utc``, by that register's clock; ``at_utc``
stays when it happened, which may be earlier, e.g. an answer taken from a session file).

``uid_hash`` is a 31-bit number from the uid: a sync compares the facts of an axis in two registers
by their count and the sum of these numbers before it compares them one by one.
"""

from __future__ import annotations

import socket
import sqlite3
import uuid
from pathlib import Path
from typing import Any

#: The tables whose rows are facts with a stable id (each with the columns of
#: :data:`FACT_ID_COLUMNS`), in the order a sync moves them (a resolution after its conflict). The
#: other facts are known by ids of their own: a snapshot's values by their snapshot, a signing key
#: by its fingerprint, its revocation by the key, a signature by itself.
UID_TABLES = (
    "axis_event",
    "snapshot",
    "parameter_write",
    "procedure_run",
    "check_result",
    "alarm",
    "report",
    "recording",
    "model_check",
    "conflict",
    "conflict_resolution",
)
#: The tables of schema 5 and before whose rows schema 6 gave ids, each with the column that says
#: when it happened.
OLDER_UID_TABLES = {
    table: "updated_utc" if table == "procedure_run" else "at_utc" for table in UID_TABLES[:9]
}
#: Facts a sync moves in one transaction (with their snapshots' values): about a MB, a fraction of a
#: second on either store (a sync stopped in the middle has that much to do again). Here, not in
#: :mod:`.sync`, so that the command line's help says it without loading the register.
BATCH_FACTS = 1000
#: The columns every fact has for its identity, in this order (:meth:`fact_ids` gives the values).
FACT_ID_COLUMNS = ("uid", "recorded_in", "recorded_utc", "uid_hash")


def new_uid() -> str:
    """A new fact's stable id (a random UUID, text)."""
    return str(uuid.uuid4())


def uid_hash(uid: str) -> int:
    """The 31-bit number of a uid (its first 8 hex digits): what a sync sums over an axis's facts."""
    try:
        return int(uid[:8], 16) & 0x7FFFFFFF
    except ValueError:
        return 0


def fact_ids(register_id: str, recorded_utc: str) -> tuple[str, str, str, int]:
    """The identity columns' values for a new fact recorded now in the register ``register_id``."""
    uid = new_uid()
    return uid, register_id, recorded_utc, uid_hash(uid)


def _register_name(db: Any) -> str:
    """What people call a register: the computer and the file (``ana-laptop register.sqlite``),
    or the server's database (``server plant_register``)."""
    if isinstance(db, sqlite3.Connection):
        file = next((str(r[2]) for r in db.execute("PRAGMA database_list") if r[1] == "main"), "")
        return f"{socket.gethostname()} {Path(file).name}".strip()
    row = db.execute("SELECT current_database()").fetchone()
    return f"server {row[0]}" if row else "server"


def give_ids(db: Any) -> None:
    """Schema 6's migration step: the register gets its own id (and name), and every fact already
    in it its stable id, recorded here, at the time it happened (the time it was recorded was not
    kept before). ``db`` is an ``sqlite3.Connection`` or the server's connection."""
    from fha_studio.logic.register.records import utc_stamp

    register_id = new_uid()
    db.execute(
        "INSERT INTO known_register (register_id, name, created_utc) VALUES (?, ?, ?)",
        (register_id, _register_name(db), utc_stamp()),
    )
    db.execute("INSERT INTO this_register (register_id) VALUES (?)", (register_id,))
    if isinstance(db, sqlite3.Connection):
        db.create_function("fha_new_uid", 0, new_uid, deterministic=False)
        db.create_function("fha_uid_hash", 1, uid_hash, deterministic=True)
        new, number = "fha_new_uid()", "fha_uid_hash(uid)"
    else:
        new, number = "gen_random_uuid()::text", "(('x' || substr(uid, 1, 8))::bit(32)::bigint & 2147483647)"
    for table, at in OLDER_UID_TABLES.items():
        db.execute(f"UPDATE {table} SET uid = {new}, recorded_in = ?, recorded_utc = {at}", (register_id,))
        db.execute(f"UPDATE {table} SET uid_hash = {number}")
