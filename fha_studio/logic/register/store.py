"""The register: every commissioning fact of every axis of every machine, in one SQLite file or
in a database on a PostgreSQL server (a ``postgresql://`` URL; :mod:`.server`), the same tables
and migrations in both.

Machines have axes; an axis has a history of parameter snapshots (read over the link, entered
from the front panel or taken from a parameter file), verified writes, procedure checks, alarms,
reports, recordings and model-check results. Files (reports, recordings, model-check reports,
session and parameter files) stay files: the register keeps their path (and a SHA-256 where a
later change must show) and a summary.

The file is opened in WAL mode with ``synchronous=FULL``: every write is one transaction, and a
committed transaction survives the process being killed (and the machine losing power).
Several processes (two FHA Studio windows, the command line) may use one file at once; a writer
waits up to ``busy_timeout_s`` for another's transaction. WAL needs the file on a local disk: on
a network share SQLite's locking is only as good as the share's.
"""

from __future__ import annotations

import contextlib
import sqlite3
from dataclasses import asdict
from pathlib import Path
from typing import Any

from fha_studio import fileio
from fha_studio.logic.register import append_only, guard
from fha_studio.logic.register.connection import (
    ENV_REGISTER,
    REGISTER_FILE_NAME,
    default_register_path,
    register_location,
)
from fha_studio.logic.register.guard import RegisterError
from fha_studio.logic.register.keys import Keys
from fha_studio.logic.register.records import (
    SOURCES,
    Axis,
    Difference,
    Event,
    EventKind,
    Found,
    Machine,
    OpenItem,
    ParameterSet,
    ParameterValue,
    file_sha256,
    utc_stamp,
)
from fha_studio.logic.register.schema import MIGRATIONS, SCHEMA_VERSION


@guard.in_words
class Register(Keys):
    """One register file, open. Use as a context manager or call :meth:`close`.

    Every public method turns SQLite's errors into one :class:`RegisterError` line naming the
    file (read-only, damaged, locked, full; :mod:`.guard`); every write is one transaction. The
    parts, each on the one below: the connection (connection.py), machines and axes (axes.py),
    the facts recorded (facts.py), the questions (queries.py), the history (history.py).
    """

    def __init__(
        self,
        path: str | Path | None = None,
        busy_timeout_s: float = 30.0,
        create: bool = True,
        read_only: bool = False,
    ):
        """Opens the register at ``path`` (default: :func:`default_register_path`; a
        ``postgresql://`` URL: the register in that database on the server), created when
        missing unless ``create`` is False (then RegisterError says there is none). ``read_only``:
        for questions only; the file is not changed (a register this user may not write is
        opened so anyway)."""
        self.busy_timeout_s = busy_timeout_s
        target = register_location(path)
        if isinstance(target, str):
            self._open_on_server(target, create, read_only)
            return
        self.path = Path(target)
        # a device, a FIFO or a file that is no database is refused before SQLite opens it
        cannot_write = guard.check_before_opening(self.path, create and not read_only)
        if read_only and not cannot_write:
            _upgrade_if_older(self.path, busy_timeout_s)
        self.read_only = cannot_write or read_only
        try:
            if create and not self.read_only:
                self.path.parent.mkdir(parents=True, exist_ok=True)
            self._db = sqlite3.connect(
                guard.connect_uri(self.path, self.read_only, create and not read_only), uri=True,
                timeout=busy_timeout_s, isolation_level=None,
            )
        except OSError as exc:
            raise RegisterError(f"register {guard.shown_path(self.path)}: cannot open it: "
                                f"{fileio.os_reason(exc)}") from None
        except sqlite3.Error as exc:
            raise guard.problem(self.path, exc, opening=True) from None
        try:
            self._db.row_factory = sqlite3.Row
            self._db.execute("PRAGMA foreign_keys = ON")
            if self.read_only:  # questions only: the file stays as it is
                self.journal_mode = str(self._db.execute("PRAGMA journal_mode").fetchone()[0]).lower()
                if self.version != SCHEMA_VERSION:
                    raise RegisterError(
                        f"the register {guard.shown_path(self.path)} is read-only and was written by "
                        f"another FHA Studio (schema {self.version}; this one reads {SCHEMA_VERSION})")
            else:
                self._db.execute("PRAGMA synchronous = FULL")
                self.journal_mode = self._set_wal(busy_timeout_s)
                self._migrate()
        except sqlite3.Error as exc:
            failure = guard.problem(self.path, exc, self._db, busy_timeout_s, opening=True)
            self._db.close()
            raise failure from None
        except RegisterError:
            self._db.close()
            raise

    def _open_on_server(self, url: str, create: bool, read_only: bool) -> None:
        from fha_studio.logic.register import server

        self._url, self.path = url, server.shown_url(url)
        self.journal_mode, self._checked_sound = "server", True
        try:
            self._db = server.ServerDatabase(url, connect_timeout_s=min(self.busy_timeout_s, 10.0))
        except Exception as exc:
            if not guard.is_db_error(exc):
                raise
            raise server.problem(url, exc, opening=True) from None
        try:
            if not self._db.prepare_register(create and not read_only):
                raise RegisterError(f"there is no register at {guard.shown_path(self.path)}")
            self.read_only = read_only
            if read_only and self.version < SCHEMA_VERSION:
                self.read_only = False  # an older register is brought up to date before it is read
            if self.read_only:
                if self.version != SCHEMA_VERSION:
                    raise RegisterError(
                        f"the register {guard.shown_path(self.path)} was written by another FHA Studio "
                        f"(schema {self.version}; this one reads {SCHEMA_VERSION})")
            else:
                self._migrate()
            self.read_only = read_only
        except Exception as exc:
            self._db.close()
            if guard.is_db_error(exc):
                raise server.problem(url, exc, opening=True) from None
            raise

    def _migrate(self, target: int | None = None) -> None:
        target = len(MIGRATIONS) if target is None else target
        if self.version > SCHEMA_VERSION:
            raise RegisterError(
                f"register {self.path}: written by a newer FHA Studio (schema {self.version}; "
                f"this one knows up to {SCHEMA_VERSION}); not changed"
            )
        while self.version < target:
            with self._transaction():
                current = self.version  # again inside the lock: another process may have migrated
                if current >= target:
                    break
                # a migration may rebuild a table: the triggers that keep the history as it was
                # written are taken away first and made again with the last one (append_only.py)
                for statement in self._protection(make=False):
                    self._db.execute(statement)
                for step in MIGRATIONS[current]:
                    if callable(step):
                        step(self._db)
                    else:
                        self._db.execute(step)
                self._db.execute(f"PRAGMA user_version = {current + 1}")
                if current + 1 == len(MIGRATIONS):
                    for statement in self._protection(make=True):
                        self._db.execute(statement)
                    if self._url:
                        self._roles_again()

    def _roles_again(self) -> None:
        """On a server with the register's roles, the new tables get their rights and triggers."""
        from fha_studio.logic.register import roles

        if roles.is_set_up(self._db):
            for statement in roles.protection(roles.Catalog.read(self._db)):
                self._db.execute_raw(statement)

    def _protection(self, make: bool) -> list[str]:
        """The statements that make (or take away) the append-only triggers of this store."""
        if self._url:
            tables = {r[0] for r in self._db.execute(
                "SELECT tablename FROM pg_tables WHERE schemaname = current_schema()")}
            if make:
                return append_only.server_create(tables)
            from fha_studio.logic.register.roles import TRIGGER_PREFIX  # the roles' too: made again after

            return append_only.server_drop([(r[0], r[1]) for r in self._db.execute(
                "SELECT c.relname, t.tgname FROM pg_trigger t JOIN pg_class c ON c.oid = t.tgrelid"
                " WHERE NOT t.tgisinternal AND c.relnamespace = current_schema()::regnamespace")],
                (append_only.PREFIX, TRIGGER_PREFIX))
        if make:
            tables = {r[0] for r in self._db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
            return append_only.sqlite_create(tables)
        return append_only.sqlite_drop(
            [r[0] for r in self._db.execute("SELECT name FROM sqlite_master WHERE type = 'trigger'")])

    def export(self, machine: str | None = None) -> dict[str, Any]:
        """Everything about the machines (or one) as plain data (``fha-register-export/1``)."""
        machines = [self.machine(machine)] if machine else self.machines()
        out: dict[str, Any] = {"format": "fha-register-export/1", "exported_utc": utc_stamp(), "machines": []}
        for m in machines:
            axes = []
            for axis in self.axes(m.name):
                axes.append(
                    {
                        **asdict(axis),
                        "current_values": {
                            k: asdict(v) for k, v in sorted(self.current_values(axis).values.items())
                        },
                        "procedures": self.procedure_status(axis),
                        "history": [e.as_dict() for e in self.history(axis)],
                    }
                )
            reports = [
                dict(r)
                for r in self._db.execute(
                    "SELECT * FROM report WHERE machine_id = ? AND axis_id IS NULL ORDER BY at_utc", (m.id,)
                )
            ]
            out["machines"].append({**asdict(m), "axes": axes, "machine_reports": reports})
        return out


def _upgrade_if_older(path: Path, busy_timeout_s: float) -> None:
    """A register of an older schema is brought up to date before it is read (its data kept);
    a damaged one is refused as it is: an upgrade would write into it (WAL, the new tables) before
    a question is asked, and `register check` is to find the file as it was left."""
    try:
        with contextlib.closing(sqlite3.connect(guard.connect_uri(path, True, False), uri=True)) as db:
            older = int(db.execute("PRAGMA user_version").fetchone()[0]) < SCHEMA_VERSION
            if older and not guard.sound(db):
                raise guard.damaged(path, db)
    except sqlite3.Error:
        return  # opening it read-only says what is wrong
    if older:
        Register(path, busy_timeout_s=busy_timeout_s, create=False).close()


__all__ = [
    "ENV_REGISTER",
    "REGISTER_FILE_NAME",
    "SOURCES",
    "Axis",
    "Difference",
    "Event",
    "EventKind",
    "Found",
    "Machine",
    "OpenItem",
    "ParameterSet",
    "ParameterValue",
    "Register",
    "RegisterError",
    "default_register_path",
    "file_sha256",
    "register_location",
    "utc_stamp",
]
