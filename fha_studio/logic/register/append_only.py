"""History that nobody rewrites: the database itself refuses to change or remove a fact.

On both stores every table of :data:`~.schema.FACT_TABLES` has triggers that refuse an UPDATE or
a DELETE (and on the server a TRUNCATE), whoever asks: FHA Studio, another program on the file,
the server's roles, its owner included. A machine or an axis is changed (each change a line of
the axis's history) but never removed. A mistake is corrected by a new fact that points at the
one it corrects (``corrects``, :data:`~.schema.CORRECTABLE_TABLES`).

The triggers are made by the migrations (:meth:`Register._migrate`): each migration removes them
first (a migration may rebuild a table) and the last one makes them again for every fact table,
so a register at this program's schema version always has them.

What this does not stop: SQLite has no users, so whoever can write the file can drop a trigger
(the application never does; the file's protection is its permissions). On the server only the
register's owner can drop one (its tables are the owner's; the roles FHA Studio's people connect
as cannot: :mod:`.roles`).

The refusal's words start with :data:`REFUSAL`, so that both stores' errors are told alike.
"""

from __future__ import annotations

from fha_studio.logic.register.guard import APPEND_ONLY, TABLE_WORDS
from fha_studio.logic.register.schema import ENTITY_TABLES, FACT_TABLES

#: How the database's refusal begins (SQLite's RAISE message, the server's exception message).
REFUSAL = APPEND_ONLY
#: Every protecting trigger's name begins with this.
PREFIX = "append_only_"
#: The server's SQLSTATE for the refusal (a class of our own: no server error has it).
SQLSTATE = "FH001"

_CORRECT = "a mistake is corrected by a new fact that points at it"


def refusal_text(table: str, removed_only: bool = False) -> str:
    """The refusal for ``table`` (without the prefix)."""
    what = TABLE_WORDS.get(table, table)
    if removed_only:
        return f"{what} are never removed"
    return f"{what} are never changed or removed ({_CORRECT})"


def _sql_text(text: str) -> str:
    return "'" + text.replace("'", "''") + "'"


def sqlite_drop(existing: list[str]) -> list[str]:
    """Statements removing the protecting triggers named in ``existing``."""
    return [f'DROP TRIGGER IF EXISTS "{name}"' for name in existing if name.startswith(PREFIX)]


def sqlite_create(tables: set[str]) -> list[str]:
    """Statements making the protecting triggers of the register's tables present in ``tables``."""
    out = []
    for table in FACT_TABLES:
        if table in tables:
            said = _sql_text(f"{REFUSAL} {refusal_text(table)}")
            for event in ("UPDATE", "DELETE"):
                out.append(f"CREATE TRIGGER {PREFIX}{event.lower()}_{table} BEFORE {event} ON {table}"
                           f" BEGIN SELECT RAISE(ABORT, {said}); END")
    for table in ENTITY_TABLES:
        if table in tables:
            said = _sql_text(f"{REFUSAL} {refusal_text(table, removed_only=True)}")
            out.append(f"CREATE TRIGGER {PREFIX}delete_{table} BEFORE DELETE ON {table}"
                       f" BEGIN SELECT RAISE(ABORT, {said}); END")
    return out


#: The server's one trigger function: its argument is the refusal's text.
_SERVER_FUNCTION = f"""CREATE OR REPLACE FUNCTION {PREFIX}refuse() RETURNS trigger LANGUAGE plpgsql AS $body$
BEGIN
    RAISE EXCEPTION USING ERRCODE = '{SQLSTATE}', MESSAGE = TG_ARGV[0];
END
$body$"""


def server_drop(existing: list[tuple[str, str]], prefixes: tuple[str, ...] = (PREFIX,)) -> list[str]:
    """Statements removing the protecting triggers in ``existing`` ((table, trigger) pairs), those
    whose names begin with one of ``prefixes`` (the roles' too: :mod:`.roles`, made again after
    the migrations)."""
    return [f'DROP TRIGGER IF EXISTS "{name}" ON "{table}"'
            for table, name in existing if name.startswith(prefixes)]


def server_create(tables: set[str]) -> list[str]:
    """Statements making the protecting function and triggers of the tables present in ``tables``."""
    out = [_SERVER_FUNCTION]
    for table in FACT_TABLES:
        if table in tables:
            said = _sql_text(f"{REFUSAL} {refusal_text(table)}")
            out.append(f"CREATE TRIGGER {PREFIX}change_{table} BEFORE UPDATE OR DELETE ON {table}"
                       f" FOR EACH ROW EXECUTE FUNCTION {PREFIX}refuse({said})")
            out.append(f"CREATE TRIGGER {PREFIX}truncate_{table} BEFORE TRUNCATE ON {table}"
                       f" FOR EACH STATEMENT EXECUTE FUNCTION {PREFIX}refuse({said})")
    for table in ENTITY_TABLES:
        if table in tables:
            said = _sql_text(f"{REFUSAL} {refusal_text(table, removed_only=True)}")
            out.append(f"CREATE TRIGGER {PREFIX}delete_{table} BEFORE DELETE ON {table}"
                       f" FOR EACH ROW EXECUTE FUNCTION {PREFIX}refuse({said})")
            out.append(f"CREATE TRIGGER {PREFIX}truncate_{table} BEFORE TRUNCATE ON {table}"
                       f" FOR EACH STATEMENT EXECUTE FUNCTION {PREFIX}refuse({said})")
    return out
