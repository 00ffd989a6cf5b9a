"""The register file's connection: WAL, one write transaction at a time (or a batch of them),
SQLite's errors in words; which file the register is (one rule for the GUI and the command line).
The layers of :class:`~fha_studio.logic.register.store.Register` build on :class:`Connection`."""

from __future__ import annotations

import contextlib
import os
import sqlite3
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Self

from fha_studio.logic.register import guard
from fha_studio.logic.register.guard import RegisterError
from fha_studio.paths import user_data_dir

#: A site chooses its register file with this environment variable (e.g. on a shared drive).
ENV_REGISTER = "FHA_STUDIO_REGISTER"
REGISTER_FILE_NAME = "register.sqlite"


def default_register_path(chosen: str | Path | None = None) -> Path:
    """The register file, by one rule for the GUI and the command line: ``chosen`` (their
    ``--register FILE``) when given, else ``$FHA_STUDIO_REGISTER`` when set, else
    ``register.sqlite`` in the user data directory."""
    text = str(chosen or "").strip() or os.environ.get(ENV_REGISTER, "").strip()
    return Path(text).expanduser() if text else user_data_dir() / REGISTER_FILE_NAME


@guard.in_words
class Connection:
    """An open register file (opened by :class:`~fha_studio.logic.register.store.Register`)."""

    path: Path
    busy_timeout_s: float
    read_only: bool
    journal_mode: str
    _db: sqlite3.Connection
    #: SQLite's quick check found the file sound at this connection's first write (it is run
    #: once: 0.27 s for a register of 46 MB, measured under load)
    _checked_sound = False

    @property
    def version(self) -> int:
        return int(self._db.execute("PRAGMA user_version").fetchone()[0])

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
                if not guard.sound(self._db):
                    failure = guard.damaged(self.path, self._db)
                    self._db.execute("ROLLBACK")
                    raise failure
                self._checked_sound = True
        except sqlite3.Error as exc:
            with contextlib.suppress(sqlite3.Error):
                self._db.execute("ROLLBACK")
            raise self._problem(exc) from None
        try:
            yield self._db
        except BaseException:
            with contextlib.suppress(sqlite3.Error):  # the error that ended it is the one to tell
                self._db.execute("ROLLBACK")
            raise
        try:
            self._db.execute("COMMIT")
        except sqlite3.Error as exc:
            with contextlib.suppress(sqlite3.Error):
                self._db.execute("ROLLBACK")
            raise self._problem(exc) from None

    def _problem(self, exc: sqlite3.Error) -> RegisterError:
        """SQLite's error as one line naming this register and what to do."""
        return guard.problem(self.path, exc, self._db, self.busy_timeout_s)

    def close(self) -> None:
        self._db.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def integrity_check(self) -> str:
        """SQLite's verdict on the file: ``"ok"`` or what is wrong."""
        return "; ".join(str(r[0]) for r in self._db.execute("PRAGMA integrity_check"))
