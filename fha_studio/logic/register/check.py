"""``register check``: SQLite's integrity check of a register file, and what a damaged register
still holds (no Qt). The file is opened read-only and never changed."""

from __future__ import annotations

import contextlib
import sqlite3
from dataclasses import dataclass, field
from pathlib import Path

from fha_studio.logic.register import guard
from fha_studio.logic.register.guard import TABLE_WORDS, RegisterError


@dataclass(frozen=True)
class TableState:
    """How much of one table can be read: ``rows`` read before the first damage (all of them when
    ``complete``)."""

    table: str
    words: str
    rows: int
    complete: bool
    damage: str = ""  # SQLite's words for what stopped the reading


@dataclass(frozen=True)
class CheckResult:
    path: Path
    ok: bool
    findings: tuple[str, ...]  # SQLite's integrity check, line by line ("ok" when sound)
    tables: tuple[TableState, ...] = ()
    machines: tuple[str, ...] = ()  # the machine names that can be read
    axes: tuple[str, ...] = ()  # MACHINE/AXIS that can be read
    notes: tuple[str, ...] = field(default_factory=tuple)


#: The most integrity-check findings kept (SQLite's check lists one line per damaged cell).
MAX_FINDINGS = 20


def check_register(path: str | Path) -> CheckResult:
    """Checks the register at ``path`` (read-only). RegisterError when it cannot be opened at all
    (not there, a device, not an SQLite file)."""
    path = Path(path)
    guard.check_before_opening(path, create=False)
    try:
        db = sqlite3.connect(guard.connect_uri(path, True, False), uri=True, isolation_level=None)
    except sqlite3.Error as exc:
        raise guard.problem(path, exc, opening=True) from None
    with contextlib.closing(db):
        try:
            findings = tuple(str(r[0]) for r in db.execute(f"PRAGMA integrity_check({MAX_FINDINGS})"))
        except sqlite3.Error as exc:
            findings = (f"SQLite cannot finish its check: {exc}",)
        ok = findings == ("ok",)
        try:
            names = [r[0] for r in db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")]
        except sqlite3.Error as exc:
            raise RegisterError(f"{guard.shown_path(path)} is damaged where it lists its tables "
                                f"({exc}): nothing in it can be read") from None
        tables = tuple(_read_table(db, name) for name in names if not name.startswith("sqlite_"))
        machines = tuple(_names(db, "SELECT name FROM machine ORDER BY name"))
        axes = tuple(_names(db, "SELECT machine.name || '/' || axis.name FROM axis"
                            " JOIN machine ON machine.id = axis.machine_id ORDER BY 1"))
    return CheckResult(path, ok and all(t.complete for t in tables), findings, tables, machines, axes)


def _read_table(db: sqlite3.Connection, name: str) -> TableState:
    rows = 0
    words = TABLE_WORDS.get(name, name)
    try:
        for _ in db.execute(f'SELECT * FROM "{name}"'):
            rows += 1
    except sqlite3.Error as exc:
        return TableState(name, words, rows, False, str(exc))
    return TableState(name, words, rows, True)


def _names(db: sqlite3.Connection, query: str) -> list[str]:
    out: list[str] = []
    try:
        for (name,) in db.execute(query):
            out.append(str(name))
    except sqlite3.Error:
        pass  # what was read before the damage is what can be saved
    return out
