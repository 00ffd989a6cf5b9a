"""The register's connection: to an SQLite file (WAL, one write transaction at a time, or a batch
of them) or to a PostgreSQL server (:mod:`.server` speaks the register's SQL there); their errors
in words; which register it is (one rule for the GUI and the command line). The layers of
:class:`~fha_studio.logic.register.store.Register` build on :class:`Connection`."""

from __future__ import annotations

import contextlib
import os
import sqlite3
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any, Self

from fha_studio.logic.register import guard
from fha_studio.logic.register.guard import RegisterError
from fha_studio.logic.register.identity import FACT_ID_COLUMNS, fact_ids
from fha_studio.logic.register.records import utc_stamp
from fha_studio.paths import user_data_dir

#: A new fact's identity columns and their placeholders, for an INSERT's column list and VALUES.
FACT_IDS = ", ".join(FACT_ID_COLUMNS)
FACT_ID_MARKS = ", ".join("?" for _ in FACT_ID_COLUMNS)

#: A site chooses its register file with this environment variable (e.g. on a shared drive).
ENV_REGISTER = "FHA_STUDIO_REGISTER"
REGISTER_FILE_NAME = "register.sqlite"


def register_location(chosen: str | Path | None = None) -> Path | str:
    """The register by the rule of :func:`default_register_path`: a ``postgresql://`` URL (a
    register on a server) as it is, else the file's path."""
    from fha_studio.logic.register.server import is_server_url

    text = str(chosen or "").strip() or os.environ.get(ENV_REGISTER, "").strip()
    return text if is_server_url(text) else default_register_path(chosen)


def default_register_path(chosen: str | Path | None = None) -> Path:
    """The register file, by one rule for the GUI and the command line: ``chosen`` (their
    ``--register FILE``) when given, else ``$FHA_STUDIO_REGISTER`` when set, else
    ``register.sqlite`` in the user data directory."""
    text = str(chosen or "").strip() or os.environ.get(ENV_REGISTER, "").strip()
    return Path(text).expanduser() if text else user_data_dir() / REGISTER_FILE_NAME


@guard.in_words
class Connection:
    """An open register file (opened by :class:`~fha_studio.logic.register.store.Register`)."""

    #: the file, or for a register on a server its URL without the password
    path: Path | str
    busy_timeout_s: float
    read_only: bool
    journal_mode: str
    #: an ``sqlite3.Connection``, or a :class:`~.server.ServerDatabase` that takes the same SQL
    _db: Any
    #: the server's URL (with its password) for a register on a server, else ""
    _url = ""
    #: SQLite's quick check found the file sound at this connection's first write (it is run
    #: once: 0.27 s for a register of 46 MB, measured under load)
    _checked_sound = False

    #: this register's id, read once (:attr:`register_id`)
    _register_id = ""

    @property
    def version(self) -> int:
        return int(self._db.execute("PRAGMA user_version").fetchone()[0])

    @property
    def register_id(self) -> str:
        """This register's own id (a UUID made with it; every fact recorded here carries it)."""
        if not self._register_id:
            row = self._db.execute("SELECT register_id FROM this_register").fetchone()
            if row is None:
                raise RegisterError(f"the register {guard.shown_path(self.path)} has no id of its own")
            self._register_id = str(row[0])
        return self._register_id

    def _fact_ids(self) -> tuple[str, str, str, int]:
        """The identity of a fact recorded now: (uid, recorded_in, recorded_utc, uid_hash), for the
        columns of :data:`FACT_IDS`."""
        return fact_ids(self.register_id, utc_stamp())

    def _set_wal(self, busy_timeout_s: float) -> str:
        """Switch the file to WAL. SQLite does not wait on its busy timeout for this switch: while
        another process creates or writes the same new file, it says "database is locked" at
        once, so try again until the busy timeout has passed."""
        deadline = time.monotonic() + busy_timeout_s
        while True:
            try:
                return str(self._db.execute("PRAGMA journal_mode = WAL").fetchone()[0]).lower()
            except sqlite3.OperationalError as exc:
                if "locked" not in str(exc) or time.monotonic() > deadline:
                    raise
                time.sleep(0.05)

    @contextlib.contextmanager
    def batch(self) -> Iterator[None]:
        """Several facts as one transaction: all of them are committed, or none (an import, a
        session recorded after an answer); the writes inside do not commit on their own."""
        with self._transaction():
            yield

    @contextlib.contextmanager
    def _transaction(self) -> Iterator[sqlite3.Connection]:
        """One write transaction: all of it is committed, or none of it. Inside :meth:`batch`
        it is part of the batch's transaction."""
        if self._db.in_transaction:
            yield self._db
            return
        try:
            self._db.execute("BEGIN IMMEDIATE")
            if not self._checked_sound:  # the first write of this connection: is the file sound?
                if not self._url and not guard.sound(self._db):  # a server checks its own pages
                    failure = guard.damaged(Path(self.path), self._db)
                    self._db.execute("ROLLBACK")
                    raise failure
                self._checked_sound = True
        except Exception as exc:
            if not guard.is_db_error(exc):
                raise
            self._rollback()
            raise self._problem(exc) from None
        try:
            yield self._db
        except BaseException:
            self._rollback()  # the error that ended it is the one to tell
            raise
        try:
            self._db.execute("COMMIT")
        except Exception as exc:
            if not guard.is_db_error(exc):
                raise
            self._rollback()
            raise self._problem(exc) from None

    def _rollback(self) -> None:
        try:
            self._db.execute("ROLLBACK")
        except Exception as exc:
            if not guard.is_db_error(exc):
                raise

    def _problem(self, exc: BaseException) -> RegisterError:
        """SQLite's (or the server's) error as one line naming this register and what to do."""
        if self._url:
            from fha_studio.logic.register import server

            return server.problem(self._url, exc)
        assert isinstance(exc, sqlite3.Error) and isinstance(self.path, Path)
        return guard.problem(self.path, exc, self._db, self.busy_timeout_s)

    def close(self) -> None:
        self._db.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def integrity_check(self) -> str:
        """SQLite's verdict on the file: ``"ok"`` or what is wrong (on a server: "ok" when it
        answers; it keeps its pages and constraints itself)."""
        if self._url:
            return "ok" if self._db.execute("SELECT 1").fetchone() is not None else "no answer"
        return "; ".join(str(r[0]) for r in self._db.execute("PRAGMA integrity_check"))
