"""The register: every commissioning fact of every axis of every machine, in one SQLite file.

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
import datetime as _dt
import hashlib
import json
import math
import os
import sqlite3
import time
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from fha_studio import clock, fileio, names
from fha_studio.logic.register import guard, words
from fha_studio.logic.register.guard import RegisterError as RegisterError
from fha_studio.logic.register.schema import MIGRATIONS, SCHEMA_VERSION
from fha_studio.paths import user_data_dir

#: A site chooses its register file with this environment variable (e.g. on a shared drive).
ENV_REGISTER = "FHA_STUDIO_REGISTER"
REGISTER_FILE_NAME = "register.sqlite"

SOURCES = ("link", "front_panel", "file")
_SOURCE_WORDS = {
    "link": "read over the link",
    "front_panel": "entered from the front panel",
    "file": "from a file",
}
_COMPLETED = "completed"
_ORIGIN_PREFIX = "origin: "
_NOT_APPLICABLE = "not applicable"


def default_register_path(chosen: str | Path | None = None) -> Path:
    """The register file, by one rule for the GUI and the command line: ``chosen`` (their
    ``--register FILE``) when given, else ``$FHA_STUDIO_REGISTER`` when set, else
    ``register.sqlite`` in the user data directory."""
    text = str(chosen or "").strip() or os.environ.get(ENV_REGISTER, "").strip()
    return Path(text).expanduser() if text else user_data_dir() / REGISTER_FILE_NAME


def utc_stamp(when: str | _dt.datetime | None = None) -> str:
    """A time as the register stores it: UTC, ISO 8601 to the microsecond (text order = time
    order). ``when`` may be ISO text with an offset (a naive time is taken as UTC) or a datetime;
    None is now. Raises RegisterError for text that is not a time."""
    if when is None:
        moment = clock.now_utc()
    elif isinstance(when, _dt.datetime):
        moment = when
    else:
        text = str(when).strip()
        try:
            moment = _dt.datetime.fromisoformat(text.replace("Z", "+00:00"))
        except ValueError:
            raise RegisterError(
                f"{names.quoted(str(when))} is not a time (ISO 8601 expected, e.g. 2026-11-30T04:05:06Z)"
            ) from None
    if moment.tzinfo is None:
        moment = moment.replace(tzinfo=_dt.UTC)
    try:
        return moment.astimezone(_dt.UTC).isoformat(timespec="microseconds")
    except OverflowError:  # 9999-12-31T23:59:59-05:00 is in the year 10000 in UTC
        raise RegisterError(
            f"{names.quoted(str(when))} is past the last time the register holds (9999-12-31 UTC)"
        ) from None


def file_sha256(path: str | Path) -> str:
    """SHA-256 of a file's bytes (hex)."""
    digest = hashlib.sha256()
    with Path(path).open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 16), b""):
            digest.update(block)
    return digest.hexdigest()


# -- what the queries return ------------------------------------------------------------------------


@dataclass(frozen=True)
class Machine:
    id: int
    name: str
    site: str
    notes: str
    created_utc: str


@dataclass(frozen=True)
class Axis:
    """One axis of a machine: an FHA-C actuator on its driver, at its port."""

    id: int
    machine: str
    name: str
    actuator_code: str
    driver_model: str
    port_url: str
    load_inertia_kgm2: float | None
    notes: str
    serial_number: str
    created_utc: str

    @property
    def ref(self) -> str:
        """``MACHINE/AXIS``: how the command line names it."""
        return f"{self.machine}/{self.name}"


@dataclass(frozen=True)
class ParameterValue:
    """One parameter's value (wire integer) and where it comes from."""

    mode: str
    number: int
    key: str
    value: int
    at_utc: str
    source: str  # "link", "front_panel", "file" (a snapshot) or "write" (a verified write)
    ref: int  # the snapshot's or the write's row id


@dataclass(frozen=True)
class ParameterSet:
    """A set of parameter values to compare: one snapshot, or an axis's latest known values."""

    label: str
    axis: Axis
    values: Mapping[str, ParameterValue]  # key -> value


@dataclass(frozen=True)
class Difference:
    """One parameter that differs between two sets (None: absent from that set)."""

    mode: str
    number: int
    key: str
    a: int | None
    b: int | None


@dataclass(frozen=True)
class Event:
    """One line of an axis's history."""

    at_utc: str
    kind: str  # axis, snapshot, write, check, alarm, report, recording, model_check
    who: str
    text: str  # for people
    ref: int | None = None  # the row (a snapshot's number is what `diff` takes)
    data: Mapping[str, Any] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        return {**asdict(self), "data": dict(self.data)}


@dataclass(frozen=True)
class OpenItem:
    """Something that keeps an axis from being done: an open check or an unsigned report."""

    axis: Axis
    kind: str  # "check" or "report"
    text: str


@dataclass(frozen=True)
class Found:
    """An axis whose latest known value of a parameter matches."""

    axis: Axis
    value: ParameterValue


# -- the register ------------------------------------------------------------------------------------


@guard.in_words
class Register:
    """One register file, open. Use as a context manager or call :meth:`close`.

    Every public method turns SQLite's errors into one :class:`RegisterError` line naming the
    file (read-only, damaged, locked, full; :mod:`.guard`); every write is one transaction.
    """

    def __init__(
        self,
        path: str | Path | None = None,
        busy_timeout_s: float = 30.0,
        create: bool = True,
        read_only: bool = False,
    ):
        """Opens the register at ``path`` (default: :func:`default_register_path`), created when
        missing unless ``create`` is False (then RegisterError says there is none). ``read_only``:
        for questions only; the file is not changed (a register this user may not write is
        opened so anyway)."""
        self.path = Path(path) if path is not None else default_register_path()
        self.busy_timeout_s = busy_timeout_s
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

    # -- opening, versions, transactions ------------------------------------------------------------
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

    def _migrate(self, target: int = SCHEMA_VERSION) -> None:
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
                for statement in MIGRATIONS[current]:
                    self._db.execute(statement)
                self._db.execute(f"PRAGMA user_version = {current + 1}")

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
        except sqlite3.Error as exc:
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

    def __enter__(self) -> Register:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def integrity_check(self) -> str:
        """SQLite's verdict on the file: ``"ok"`` or what is wrong."""
        return "; ".join(str(r[0]) for r in self._db.execute("PRAGMA integrity_check"))

    # -- machines and axes ----------------------------------------------------------------------------
    def add_machine(self, name: str, site: str = "", notes: str = "") -> Machine:
        """A new machine; RegisterError when the name is empty, has '/' or is taken."""
        if not name.strip():
            raise RegisterError("a machine needs a name")
        name = _checked(name, "machine name")
        site = _checked(site, "site", names.TEXT_MAX)
        if "/" in name:
            raise RegisterError(
                f"machine name {names.quoted(name)}: '/' separates machine and axis, use another sign")
        with self._transaction() as db:
            if db.execute("SELECT 1 FROM machine WHERE name = ?", (name,)).fetchone():
                raise RegisterError(f"there is already a machine called {names.quoted(name)}")
            db.execute(
                "INSERT INTO machine (name, site, notes, created_utc) VALUES (?, ?, ?, ?)",
                (name, site.strip(), notes, utc_stamp()),
            )
        return self.machine(name)

    def machine(self, name: str) -> Machine:
        row = self._db.execute("SELECT * FROM machine WHERE name = ?", (name.strip(),)).fetchone()
        if row is None:
            known = _listed(m.name for m in self.machines()) or "none yet"
            raise RegisterError(f"no machine called {names.quoted(name)} in the register (machines: {known})")
        return Machine(**dict(row))

    def ensure_machine(self, name: str, site: str = "") -> Machine:
        """The machine called ``name``, added when it is not there yet."""
        try:
            return self.machine(name)
        except RegisterError:
            try:
                return self.add_machine(name, site)
            except RegisterError as refused:
                try:
                    return self.machine(name)  # another process added it in between
                except RegisterError:
                    raise refused from None  # why it could not be added (read-only, a bad name)

    def machines(self) -> list[Machine]:
        return [Machine(**dict(r)) for r in self._db.execute("SELECT * FROM machine ORDER BY name")]

    _AXIS_SELECT = (
        "SELECT axis.*, machine.name AS machine FROM axis JOIN machine ON machine.id = axis.machine_id"
    )

    @staticmethod
    def _axis(row: sqlite3.Row) -> Axis:
        data = dict(row)
        return Axis(
            id=data["id"],
            machine=data["machine"],
            name=data["name"],
            actuator_code=data["actuator_code"],
            driver_model=data["driver_model"],
            port_url=data["port_url"],
            load_inertia_kgm2=data["load_inertia_kgm2"],
            notes=data["notes"],
            serial_number=data["serial_number"],
            created_utc=data["created_utc"],
        )

    def add_axis(
        self,
        machine: str,
        name: str,
        actuator_code: str = "",
        driver_model: str = "",
        port_url: str = "",
        load_inertia_kgm2: float | None = None,
        notes: str = "",
        serial_number: str = "",
        who: str = "",
    ) -> Axis:
        """A new axis on ``machine``; RegisterError when the name is empty or taken there."""
        if not name.strip():
            raise RegisterError(f"an axis of machine {names.quoted(machine)} needs a name")
        name = _checked(name, "axis name")
        port_url = _checked(port_url, "port", names.PORT_MAX)
        for label, text in (("actuator", actuator_code), ("driver", driver_model),
                            ("serial number", serial_number), ("operator", who)):
            _checked(text, label, names.TEXT_MAX)
        _check_inertia(load_inertia_kgm2)
        machine_row = self.machine(machine)
        with self._transaction() as db:
            if db.execute(
                "SELECT 1 FROM axis WHERE machine_id = ? AND name = ?", (machine_row.id, name)
            ).fetchone():
                raise RegisterError(f"machine {names.quoted(machine_row.name)} already has an axis "
                                    f"called {names.quoted(name)}")
            self._check_port_free(machine_row.id, port_url.strip(), name)
            now = utc_stamp()
            cursor = db.execute(
                "INSERT INTO axis (machine_id, name, actuator_code, driver_model, port_url,"
                " load_inertia_kgm2, notes, serial_number, created_utc) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (
                    machine_row.id,
                    name,
                    actuator_code.strip().upper(),
                    driver_model.strip(),
                    port_url.strip(),
                    load_inertia_kgm2,
                    notes,
                    serial_number.strip(),
                    now,
                ),
            )
            what = ", ".join(
                t
                for t in (
                    actuator_code.strip().upper(),
                    f"on {driver_model.strip()}" if driver_model.strip() else "",
                    f"at {port_url.strip()}" if port_url.strip() else "",
                )
                if t
            )
            db.execute(
                "INSERT INTO axis_event (axis_id, at_utc, who, text) VALUES (?, ?, ?, ?)",
                (cursor.lastrowid, now, who, f"axis added: {what}" if what else "axis added"),
            )
        return self.axis(f"{machine_row.name}/{name}")

    def ensure_axis(self, machine: str, name: str, **fields: Any) -> Axis:
        """The axis ``machine/name`` (machine and axis added when missing; fields given for a new
        axis, and for an existing one those that are empty there)."""
        self.ensure_machine(machine)
        try:
            axis = self.axis(f"{machine.strip()}/{name.strip()}")
        except RegisterError:
            try:
                return self.add_axis(machine, name, **fields)
            except RegisterError as refused:
                try:
                    axis = self.axis(f"{machine.strip()}/{name.strip()}")  # added in between
                except RegisterError:
                    raise refused from None
        empty = {
            k: v for k, v in fields.items() if k != "who" and v not in (None, "") and not getattr(axis, k)
        }
        return self.update_axis(axis, who=fields.get("who", ""), **empty) if empty else axis

    _AXIS_FIELDS: ClassVar[dict[str, str]] = {
        "actuator_code": "actuator",
        "driver_model": "driver",
        "port_url": "port",
        "load_inertia_kgm2": "load inertia",
        "notes": "notes",
        "serial_number": "serial number",
        "name": "name",
    }

    def update_axis(self, axis: Axis | str | int, who: str = "", **fields: Any) -> Axis:
        """Changes an axis's fields; each change goes into its history (old -> new)."""
        current = self.axis(axis)
        unknown = set(fields) - set(self._AXIS_FIELDS)
        if unknown:
            raise RegisterError(f"an axis has no field {', '.join(sorted(unknown))}")
        limits = {"name": names.NAME_MAX, "port_url": names.PORT_MAX}
        for key in ("name", "port_url", "actuator_code", "driver_model", "serial_number"):
            if key in fields:
                _checked(str(fields[key]), self._AXIS_FIELDS[key], limits.get(key, names.TEXT_MAX))
        if "actuator_code" in fields:
            fields["actuator_code"] = str(fields["actuator_code"]).strip().upper()
        if "load_inertia_kgm2" in fields:
            _check_inertia(fields["load_inertia_kgm2"])
        changes = {k: v for k, v in fields.items() if getattr(current, k) != v}
        if not changes:
            return current
        if "name" in changes and not str(changes["name"]).strip():
            raise RegisterError("an axis needs a name")
        if "port_url" in changes:
            machine_id = self.machine(current.machine).id
            self._check_port_free(machine_id, str(changes["port_url"]).strip(), current.name, current.id)
        with self._transaction() as db:
            now = utc_stamp()
            for key, value in changes.items():
                db.execute(f"UPDATE axis SET {key} = ? WHERE id = ?", (value, current.id))
                old = getattr(current, key)
                db.execute(
                    "INSERT INTO axis_event (axis_id, at_utc, who, text) VALUES (?, ?, ?, ?)",
                    (
                        current.id,
                        now,
                        who,
                        f"{self._AXIS_FIELDS[key]}: {_field_text(key, old)} → {_field_text(key, value)}",
                    ),
                )
        return self.axis(current.id)

    def _check_port_free(self, machine_id: int, port: str, name: str, axis_id: int | None = None) -> None:
        # one port, one drive: two axes on one serial line would fight over it (an embedded
        # simulated drive is made anew for every connection, so sim:// URLs may repeat)
        if not port or port.startswith("sim://"):
            return
        row = self._db.execute(
            "SELECT name FROM axis WHERE machine_id = ? AND port_url = ? AND id IS NOT ?",
            (machine_id, port, axis_id),
        ).fetchone()
        if row is not None:
            raise RegisterError(f"axis '{name}': port {port} is already axis '{row['name']}''s")

    def add_axis_note(
        self, axis: Axis | str | int, text: str, who: str = "", at_utc: str | None = None
    ) -> None:
        current = self.axis(axis)
        with self._transaction() as db:
            db.execute(
                "INSERT INTO axis_event (axis_id, at_utc, who, text) VALUES (?, ?, ?, ?)",
                (current.id, utc_stamp(at_utc), who, f"note: {text}"),
            )

    def record_origin(
        self, axis: Axis | str | int, text: str, who: str = "", at_utc: str | None = None
    ) -> None:
        """Where the axis's origin was set and how, e.g. "multi-turn data cleared (OWW) at
        +0.00°" or "origin sensor at +1.25°" (goes into its history as "origin: ...")."""
        current = self.axis(axis)
        with self._transaction() as db:
            db.execute(
                "INSERT INTO axis_event (axis_id, at_utc, who, text) VALUES (?, ?, ?, ?)",
                (current.id, utc_stamp(at_utc), who, f"{_ORIGIN_PREFIX}{text}"),
            )

    def latest_origin(self, axis: Axis | str | int) -> dict[str, str] | None:
        """The latest origin recorded for the axis: {"text", "at_utc", "who"}; None when none was."""
        current = self.axis(axis)
        row = self._db.execute(
            "SELECT * FROM axis_event WHERE axis_id = ? AND text LIKE ?"
            " ORDER BY at_utc DESC, id DESC LIMIT 1",
            (current.id, f"{_ORIGIN_PREFIX}%"),
        ).fetchone()
        if row is None:
            return None
        return {"text": row["text"][len(_ORIGIN_PREFIX) :], "at_utc": row["at_utc"], "who": row["who"]}

    def axis(self, ref: Axis | str | int) -> Axis:
        """An axis by id, by ``MACHINE/AXIS``, or by its name alone when only one axis has it."""
        if isinstance(ref, Axis):
            ref = ref.id
        if isinstance(ref, int):
            row = self._db.execute(f"{self._AXIS_SELECT} WHERE axis.id = ?", (ref,)).fetchone()
            if row is None:
                raise RegisterError(f"no axis number {ref} in the register")
            return self._axis(row)
        text = str(ref).strip()
        if "/" in text:
            machine, name = (p.strip() for p in text.split("/", 1))
            row = self._db.execute(
                f"{self._AXIS_SELECT} WHERE machine.name = ? AND axis.name = ?", (machine, name)
            ).fetchone()
            if row is None:
                known = _listed(a.name for a in self.axes(machine)) if self._has_machine(machine) else ""
                where = (f"machine {names.quoted(machine)} has no axis {names.quoted(name)}"
                         + (f" (axes: {known})" if known else ""))
                if not self._has_machine(machine):
                    where = f"no machine called {names.quoted(machine)} in the register"
                raise RegisterError(where)
            return self._axis(row)
        rows = self._db.execute(f"{self._AXIS_SELECT} WHERE axis.name = ?", (text,)).fetchall()
        if len(rows) == 1:
            return self._axis(rows[0])
        if not rows:
            raise RegisterError(
                f"no axis called {names.quoted(text)} in the register (name one as MACHINE/AXIS)")
        machines = _listed(r["machine"] for r in rows)
        raise RegisterError(f"several machines have an axis called {names.quoted(text)} ({machines}): "
                            "say MACHINE/AXIS")

    def _has_machine(self, name: str) -> bool:
        return self._db.execute("SELECT 1 FROM machine WHERE name = ?", (name,)).fetchone() is not None

    def axes(self, machine: str | None = None) -> list[Axis]:
        """Every axis (of one machine), by machine and then in the order they were added."""
        if machine is None:
            rows = self._db.execute(f"{self._AXIS_SELECT} ORDER BY machine.name, axis.id")
        else:
            machine_row = self.machine(machine)
            rows = self._db.execute(
                f"{self._AXIS_SELECT} WHERE axis.machine_id = ? ORDER BY axis.id", (machine_row.id,)
            )
        return [self._axis(r) for r in rows]

    # -- recording facts ------------------------------------------------------------------------------
    def record_snapshot(
        self,
        axis: Axis | str | int,
        values: Iterable[tuple[str, int, str, int]],
        source: str,
        who: str = "",
        at_utc: str | None = None,
        driver_model: str = "",
        file: str | Path = "",
        note: str = "",
    ) -> int:
        """A snapshot of parameter values: ``values`` are (mode, number, key, wire value);
        ``source`` is "link" (read from the drive), "front_panel" (read off the drive's panel by
        a person) or "file". Returns the snapshot's number."""
        if source not in SOURCES:
            raise RegisterError(f"snapshot source '{source}' is not one of {', '.join(SOURCES)}")
        rows = []
        for mode, number, key, value in values:
            if isinstance(value, bool) or not isinstance(value, int):
                raise RegisterError(
                    f"parameter {mode} {number} ({key}): value {value!r} is not a wire integer"
                )
            rows.append((str(mode), int(number), str(key), int(value)))
        if not rows:
            raise RegisterError("a parameter snapshot needs at least one value")
        current = self.axis(axis)
        with self._transaction() as db:
            cursor = db.execute(
                "INSERT INTO snapshot (axis_id, at_utc, who, source, driver_model, file, note)"
                " VALUES (?, ?, ?, ?, ?, ?, ?)",
                (current.id, utc_stamp(at_utc), who, source, driver_model, str(file), note),
            )
            snapshot_id = int(cursor.lastrowid or 0)
            db.executemany(
                "INSERT OR REPLACE INTO snapshot_value (snapshot_id, mode, number, key, value)"
                " VALUES (?, ?, ?, ?, ?)",
                [(snapshot_id, *row) for row in rows],
            )
        return snapshot_id

    def record_write(
        self,
        axis: Axis | str | int,
        mode: str,
        number: int,
        key: str,
        new: int,
        old: int | None = None,
        read_back: int | None = None,
        verified: bool = False,
        error: str = "",
        who: str = "",
        at_utc: str | None = None,
    ) -> int:
        """One parameter write and whether the read-back verified it. Returns its row id."""
        current = self.axis(axis)
        with self._transaction() as db:
            cursor = db.execute(
                "INSERT INTO parameter_write (axis_id, at_utc, who, mode, number, key, old, new, read_back,"
                " verified, error) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (
                    current.id,
                    utc_stamp(at_utc),
                    who,
                    str(mode),
                    int(number),
                    key,
                    old,
                    int(new),
                    read_back,
                    int(bool(verified)),
                    error or "",
                ),
            )
        return int(cursor.lastrowid or 0)

    def record_checks(
        self,
        axis: Axis | str | int,
        records: Iterable[Any],
        session_file: str | Path = "",
    ) -> int:
        """Procedure check records (objects with the fields of a session's CheckRecord). A record
        already in the register (same procedure, step and time) is not added twice. Returns how
        many were new."""
        current = self.axis(axis)
        rows = [
            (
                current.id,
                r.procedure_id,
                r.step_id,
                r.kind,
                r.section,
                r.text,
                json.dumps(r.value, ensure_ascii=False, default=str),
                r.expected,
                r.unit,
                int(bool(r.passed)),
                r.who,
                utc_stamp(r.at_utc),
                r.detail,
                str(session_file),
            )
            for r in records
        ]
        with self._transaction() as db:
            before = db.total_changes
            db.executemany(
                "INSERT OR IGNORE INTO check_result (axis_id, procedure_id, step_id, kind, section, text,"
                " value_json, expected, unit, passed, who, at_utc, detail, session_file)"
                " VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                rows,
            )
            return db.total_changes - before

    def record_procedure_status(
        self,
        axis: Axis | str | int,
        procedure_id: str,
        title: str,
        status: str,
        section: str = "",
        session_file: str | Path = "",
        at_utc: str | None = None,
    ) -> None:
        """Where a procedure of the axis stands (not_started, running, paused, stopped, completed,
        or "not applicable"); replaces what was there."""
        current = self.axis(axis)
        with self._transaction() as db:
            db.execute(
                "INSERT OR REPLACE INTO procedure_run (axis_id, procedure_id, title, section, status,"
                " updated_utc, session_file) VALUES (?, ?, ?, ?, ?, ?, ?)",
                (current.id, procedure_id, title, section, status, utc_stamp(at_utc), str(session_file)),
            )

    def record_alarm(
        self,
        axis: Axis | str | int,
        code: int,
        name: str = "",
        who: str = "",
        at_utc: str | None = None,
        note: str = "",
    ) -> int:
        current = self.axis(axis)
        with self._transaction() as db:
            cursor = db.execute(
                "INSERT INTO alarm (axis_id, at_utc, who, code, name, note) VALUES (?, ?, ?, ?, ?, ?)",
                (current.id, utc_stamp(at_utc), who, int(code), name, note),
            )
        return int(cursor.lastrowid or 0)

    def record_report(
        self,
        file: str | Path,
        axis: Axis | str | int | None = None,
        machine: str | None = None,
        signed_by: str = "",
        signed_utc: str = "",
        open_warnings: int = 0,
        who: str = "",
        at_utc: str | None = None,
    ) -> int:
        """A report file written for one axis (or a whole machine: ``machine`` without ``axis``);
        its SHA-256 is kept so that a report changed later can be told."""
        path = Path(file)
        if axis is not None:
            current = self.axis(axis)
            machine_id, axis_id = self.machine(current.machine).id, current.id
        elif machine is not None:
            machine_id, axis_id = self.machine(machine).id, None
        else:
            raise RegisterError("a report belongs to an axis or a machine")
        digest = file_sha256(path)
        with self._transaction() as db:
            cursor = db.execute(
                "INSERT INTO report (machine_id, axis_id, at_utc, who, file, sha256, signed_by, signed_utc,"
                " open_warnings) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (
                    machine_id,
                    axis_id,
                    utc_stamp(at_utc),
                    who,
                    str(path.resolve()),
                    digest,
                    signed_by,
                    utc_stamp(signed_utc) if signed_utc else "",
                    int(open_warnings),
                ),
            )
        return int(cursor.lastrowid or 0)

    def record_recording(
        self,
        axis: Axis | str | int,
        file: str | Path,
        summary: str = "",
        who: str = "",
        at_utc: str | None = None,
    ) -> int:
        """A recording file (``fha-recording/1``) taken on the axis."""
        current = self.axis(axis)
        path = Path(file)
        digest = file_sha256(path) if path.is_file() else ""
        with self._transaction() as db:
            cursor = db.execute(
                "INSERT INTO recording (axis_id, at_utc, who, file, sha256, summary)"
                " VALUES (?, ?, ?, ?, ?, ?)",
                (current.id, utc_stamp(at_utc), who, str(path.resolve()), digest, summary),
            )
        return int(cursor.lastrowid or 0)

    def record_model_check(
        self,
        axis: Axis | str | int,
        summary: str,
        file: str | Path = "",
        recording_file: str | Path = "",
        who: str = "",
        at_utc: str | None = None,
    ) -> int:
        """A model-check result: its summary, the report or model file it wrote, the recording."""
        current = self.axis(axis)
        with self._transaction() as db:
            cursor = db.execute(
                "INSERT INTO model_check (axis_id, at_utc, who, file, recording_file, summary)"
                " VALUES (?, ?, ?, ?, ?, ?)",
                (current.id, utc_stamp(at_utc), who, str(file), str(recording_file), summary),
            )
        return int(cursor.lastrowid or 0)

    # -- questions ------------------------------------------------------------------------------------
    def snapshot(self, number: int) -> ParameterSet:
        """One snapshot's values."""
        row = self._db.execute("SELECT * FROM snapshot WHERE id = ?", (int(number),)).fetchone()
        if row is None:
            raise RegisterError(f"no parameter snapshot number {number} in the register")
        axis = self.axis(int(row["axis_id"]))
        values = {
            v["key"]: ParameterValue(
                v["mode"], v["number"], v["key"], v["value"], row["at_utc"], row["source"], row["id"]
            )
            for v in self._db.execute("SELECT * FROM snapshot_value WHERE snapshot_id = ?", (row["id"],))
        }
        label = (
            f"snapshot {row['id']} of {axis.ref} ({_SOURCE_WORDS[row['source']]}, {_short(row['at_utc'])})"
        )
        return ParameterSet(label, axis, values)

    def has_snapshot(self, axis: Axis | str | int, at_utc: str, file: str | Path) -> bool:
        """True when the axis already has a snapshot taken at ``at_utc`` from ``file``."""
        current = self.axis(axis)
        row = self._db.execute(
            "SELECT 1 FROM snapshot WHERE axis_id = ? AND at_utc = ? AND file = ?",
            (current.id, utc_stamp(at_utc), str(file)),
        ).fetchone()
        return row is not None

    def snapshots(self, axis: Axis | str | int) -> list[dict[str, Any]]:
        """The axis's snapshots, oldest first: number, time, who, source, file, how many values."""
        current = self.axis(axis)
        rows = self._db.execute(
            "SELECT snapshot.*, COUNT(snapshot_value.key) AS count FROM snapshot"
            " LEFT JOIN snapshot_value ON snapshot_value.snapshot_id = snapshot.id"
            " WHERE axis_id = ? GROUP BY snapshot.id ORDER BY at_utc, snapshot.id",
            (current.id,),
        )
        return [dict(r) for r in rows]

    def current_values(self, axis: Axis | str | int) -> ParameterSet:
        """The latest known value of each parameter of the axis: from its latest snapshot holding
        the parameter or its latest verified write, whichever is newer."""
        current = self.axis(axis)
        latest: dict[str, ParameterValue] = {}
        snapshot_rows = self._db.execute(
            "SELECT v.mode, v.number, v.key, v.value, s.at_utc, s.source, s.id FROM snapshot_value v"
            " JOIN snapshot s ON s.id = v.snapshot_id WHERE s.axis_id = ?",
            (current.id,),
        )
        write_rows = self._db.execute(
            "SELECT mode, number, key, COALESCE(read_back, new) AS value, at_utc, 'write' AS source, id"
            " FROM parameter_write WHERE axis_id = ? AND verified = 1",
            (current.id,),
        )
        for row in [*snapshot_rows, *write_rows]:
            value = ParameterValue(*tuple(row))
            known = latest.get(value.key)
            if known is None or (value.at_utc, value.ref) > (known.at_utc, known.ref):
                latest[value.key] = value
        return ParameterSet(f"{current.ref} (latest known values)", current, latest)

    def parameter_set(self, ref: str | int) -> ParameterSet:
        """A snapshot by its number, or an axis's latest known values by ``MACHINE/AXIS``."""
        text = str(ref).strip().lstrip("#")
        if text.isdigit() or text.isdecimal():  # ² and ٣ are digits to Python, not to a person
            if not text.isascii() or len(text) > 18:
                raise RegisterError(f"{names.quoted(text, 40)} is not a snapshot number "
                                    "(a whole number, see history) nor MACHINE/AXIS")
            return self.snapshot(int(text))
        return self.current_values(str(ref))

    @staticmethod
    def diff(a: ParameterSet, b: ParameterSet) -> list[Difference]:
        """The parameters whose values differ between two sets (or that only one of them has)."""
        out = []
        for key in set(a.values) | set(b.values):
            va, vb = a.values.get(key), b.values.get(key)
            if va is not None and vb is not None and va.value == vb.value:
                continue
            ref = va or vb
            assert ref is not None
            out.append(
                Difference(ref.mode, ref.number, key, va.value if va else None, vb.value if vb else None)
            )
        return sorted(out, key=lambda d: (d.mode, d.number, d.key))

    def find(self, key: str, value: int | None = None, machine: str | None = None) -> list[Found]:
        """The axes whose latest known value of parameter ``key`` is ``value`` (every axis that
        has a value for it when ``value`` is None). Latest known: as in :meth:`current_values`."""
        axes = {a.id: a for a in self.axes(machine)}
        latest: dict[int, ParameterValue] = {}
        # SQLite takes the other columns of an aggregate query from the row with the MAX
        queries = (
            "SELECT s.axis_id, v.mode, v.number, v.key, v.value, MAX(s.at_utc), s.source, s.id"
            " FROM snapshot_value v JOIN snapshot s ON s.id = v.snapshot_id"
            " WHERE v.key = ? GROUP BY s.axis_id",
            "SELECT axis_id, mode, number, key, COALESCE(read_back, new), MAX(at_utc), 'write', id"
            " FROM parameter_write WHERE key = ? AND verified = 1 GROUP BY axis_id",
        )
        for query in queries:
            for row in self._db.execute(query, (key,)):
                axis_id, *fields = tuple(row)
                known = ParameterValue(*fields)
                best = latest.get(axis_id)
                if best is None or (known.at_utc, known.ref) > (best.at_utc, best.ref):
                    latest[axis_id] = known
        return [
            Found(axis, latest[axis_id])
            for axis_id, axis in axes.items()
            if axis_id in latest and (value is None or latest[axis_id].value == value)
        ]

    def known_keys(self) -> set[str]:
        """Every parameter key the register has a value for."""
        rows = self._db.execute(
            "SELECT DISTINCT key FROM snapshot_value UNION SELECT DISTINCT key FROM parameter_write"
        )
        return {r[0] for r in rows}

    def history(self, axis: Axis | str | int, since: str | None = None) -> list[Event]:
        """Everything recorded for the axis, oldest first."""
        current = self.axis(axis)
        a = current.id
        db = self._db
        events: list[Event] = []
        for r in db.execute("SELECT * FROM axis_event WHERE axis_id = ?", (a,)):
            events.append(Event(r["at_utc"], "axis", r["who"], r["text"], r["id"]))
        for r in self.snapshots(current):
            where = f" ({r['file']})" if r["file"] else ""
            events.append(
                Event(
                    r["at_utc"],
                    "snapshot",
                    r["who"],
                    f"parameters {_SOURCE_WORDS[r['source']]}: {r['count']} values,"
                    f" snapshot {r['id']}{where}",
                    r["id"],
                    {"source": r["source"], "file": r["file"], "count": r["count"]},
                )
            )
        for r in db.execute("SELECT * FROM parameter_write WHERE axis_id = ?", (a,)):
            outcome = "verified" if r["verified"] else f"NOT verified ({r['error'] or 'read-back differs'})"
            name = words.parameter_name(r["key"], current.driver_model, (r["mode"], r["number"]))
            change = words.change_text(r["key"], r["old"], r["new"], current.driver_model)
            events.append(
                Event(
                    r["at_utc"],
                    "write",
                    r["who"],
                    f"{name}: {change}, {outcome}",
                    r["id"],
                    {
                        k: r[k]
                        for k in ("mode", "number", "key", "old", "new", "read_back", "verified", "error")
                    },
                )
            )
        titles = self._procedure_titles(a)
        for r in db.execute("SELECT * FROM check_result WHERE axis_id = ?", (a,)):
            value = json.loads(r["value_json"])
            shown = ("yes" if value else "no") if r["kind"] == "confirm" else f"{value} {r['unit']}".strip()
            verdict = "pass" if r["passed"] else "FAIL"
            if isinstance(value, dict):  # a check with several readings: its own sentence says them
                shown = r["detail"] or words.readings_text(value)
            events.append(
                Event(
                    r["at_utc"],
                    "check",
                    r["who"],
                    f"{_check_name(r, titles)}: {shown} — {verdict}",
                    r["id"],
                    {
                        "procedure_id": r["procedure_id"],
                        "step_id": r["step_id"],
                        "value": value,
                        "passed": bool(r["passed"]),
                        "expected": r["expected"],
                        "detail": r["detail"],
                    },
                )
            )
        for r in db.execute("SELECT * FROM alarm WHERE axis_id = ?", (a,)):
            note = f" ({r['note']})" if r["note"] else ""
            events.append(
                Event(
                    r["at_utc"],
                    "alarm",
                    r["who"],
                    f"alarm {r['code']}: {r['name']}{note}",
                    r["id"],
                    {"code": r["code"]},
                )
            )
        for r in db.execute("SELECT * FROM report WHERE axis_id = ?", (a,)):
            signed = f"signed by {r['signed_by']}" if r["signed_by"] else "not signed"
            events.append(
                Event(
                    r["at_utc"],
                    "report",
                    r["who"],
                    f"report {r['file']} ({signed}, {r['open_warnings']} open warnings)",
                    r["id"],
                    {"file": r["file"], "sha256": r["sha256"], "signed_by": r["signed_by"]},
                )
            )
        for r in db.execute("SELECT * FROM recording WHERE axis_id = ?", (a,)):
            summary = f": {r['summary']}" if r["summary"] else ""
            events.append(
                Event(
                    r["at_utc"],
                    "recording",
                    r["who"],
                    f"recording {r['file']}{summary}",
                    r["id"],
                    {"file": r["file"]},
                )
            )
        for r in db.execute("SELECT * FROM model_check WHERE axis_id = ?", (a,)):
            events.append(
                Event(
                    r["at_utc"],
                    "model_check",
                    r["who"],
                    f"model check: {r['summary']}",
                    r["id"],
                    {"file": r["file"], "recording_file": r["recording_file"]},
                )
            )
        if since is not None:
            cutoff = utc_stamp(since)
            events = [e for e in events if e.at_utc >= cutoff]
        order = {
            "axis": 0,
            "snapshot": 1,
            "write": 2,
            "check": 3,
            "alarm": 4,
            "recording": 5,
            "model_check": 6,
            "report": 7,
        }
        return sorted(events, key=lambda e: (e.at_utc, order[e.kind], e.ref or 0))

    def _procedure_titles(self, axis_id: int) -> dict[str, str]:
        """{procedure id: its title} of the procedures recorded for the axis."""
        rows = self._db.execute("SELECT procedure_id, title FROM procedure_run WHERE axis_id = ?", (axis_id,))
        return {r["procedure_id"]: r["title"] for r in rows if r["title"]}

    def procedure_status(self, axis: Axis | str | int) -> list[dict[str, Any]]:
        current = self.axis(axis)
        rows = self._db.execute("SELECT * FROM procedure_run WHERE axis_id = ? ORDER BY rowid", (current.id,))
        return [dict(r) for r in rows]

    def session_file(self, axis: Axis | str | int) -> str:
        """The procedure session file last recorded for the axis ("" when none was)."""
        current = self.axis(axis)
        row = self._db.execute(
            "SELECT session_file FROM procedure_run WHERE axis_id = ? AND session_file != ''"
            " ORDER BY updated_utc DESC LIMIT 1",
            (current.id,),
        ).fetchone()
        return str(row[0]) if row else ""

    def check_counts(self, axis: Axis | str | int) -> tuple[int, int]:
        """(passed, failed) of the latest answer to each check of the axis."""
        current = self.axis(axis)
        rows = self._db.execute(
            "SELECT passed FROM check_result c WHERE axis_id = ? AND NOT EXISTS (SELECT 1 FROM check_result d"
            " WHERE d.axis_id = c.axis_id AND d.procedure_id = c.procedure_id AND d.step_id = c.step_id"
            " AND (d.at_utc > c.at_utc OR (d.at_utc = c.at_utc AND d.id > c.id)))",
            (current.id,),
        ).fetchall()
        passed = sum(1 for r in rows if r[0])
        return passed, len(rows) - passed

    def latest_report(self, axis: Axis | str | int) -> dict[str, Any] | None:
        current = self.axis(axis)
        row = self._db.execute(
            "SELECT * FROM report WHERE axis_id = ? ORDER BY at_utc DESC, id DESC LIMIT 1", (current.id,)
        ).fetchone()
        return dict(row) if row else None

    def open_items(self, machine: str | None = None) -> list[OpenItem]:
        """What keeps each axis from being done: procedures not completed, checks whose latest
        answer failed, no report, or a latest report that is not signed."""
        out: list[OpenItem] = []
        for axis in self.axes(machine):
            runs = self.procedure_status(axis)
            for run in runs:
                if run["status"] not in (_COMPLETED, _NOT_APPLICABLE):
                    section = f" ({run['section']})" if run["section"] else ""
                    out.append(
                        OpenItem(axis, "check", f"{run['title']}{section}: {run['status'].replace('_', ' ')}")
                    )
            failed = self._db.execute(
                "SELECT procedure_id, step_id, section, text FROM check_result c"
                " WHERE axis_id = ? AND passed = 0"
                " AND NOT EXISTS (SELECT 1 FROM check_result d WHERE d.axis_id = c.axis_id"
                " AND d.procedure_id = c.procedure_id AND d.step_id = c.step_id"
                " AND (d.at_utc > c.at_utc OR (d.at_utc = c.at_utc AND d.id > c.id)))"
                " ORDER BY at_utc",
                (axis.id,),
            ).fetchall()
            titles = self._procedure_titles(axis.id)
            for r in failed:
                out.append(OpenItem(axis, "check", f"{_check_name(r, titles)}: failed, not checked again"))
            if (
                not runs
                and not self._db.execute(
                    "SELECT 1 FROM check_result WHERE axis_id = ?", (axis.id,)
                ).fetchone()
            ):
                out.append(OpenItem(axis, "check", "no procedure recorded yet"))
            report = self.latest_report(axis)
            if report is None:
                out.append(OpenItem(axis, "report", "no commissioning report"))
            elif not report["signed_by"]:
                out.append(OpenItem(axis, "report", f"report {report['file']} is not signed"))
        return out

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
    """A register of an older schema is brought up to date before it is read (its data kept)."""
    try:
        with contextlib.closing(sqlite3.connect(guard.connect_uri(path, True, False), uri=True)) as db:
            older = int(db.execute("PRAGMA user_version").fetchone()[0]) < SCHEMA_VERSION
    except sqlite3.Error:
        return  # opening it read-only says what is wrong
    if older:
        Register(path, busy_timeout_s=busy_timeout_s, create=False).close()


def _listed(items: Iterable[str], most: int = 8) -> str:
    """Names for a refusal: each at most 40 characters and escaped, the first ``most`` of them."""
    every = list(items)
    shown = ", ".join(names.quoted(n, 40, always=False) for n in every[:most])
    return shown + (f" and {len(every) - most} more" if len(every) > most else "")


def _checked(text: str, what: str, limit: int = names.NAME_MAX) -> str:
    """``text`` stripped, or RegisterError: longer than ``limit`` or not printable text."""
    try:
        return names.check_name(text, what, limit, empty_ok=True)
    except names.NameProblem as exc:
        raise RegisterError(str(exc)) from None


def _check_inertia(value: float | None) -> None:
    if value is not None and (
        not isinstance(value, int | float) or isinstance(value, bool) or not math.isfinite(value) or value < 0
    ):
        raise RegisterError(f"load inertia {value!r}: a number of kg m² >= 0 expected")


def _shown(value: Any) -> str:
    return "(none)" if value in (None, "") else str(value)


def _field_text(key: str, value: Any) -> str:
    """An axis field's value for its history: "not given" for none, a load inertia with its unit."""
    if value in (None, ""):
        return "not given"
    if key == "load_inertia_kgm2":
        return f"{float(value):g} kg·m²"
    return str(value)


#: The checks recorded outside the procedures, by the page that makes them.
_CHECK_SOURCES = {"dgr-checks": "DGR checks"}


def _check_name(row: sqlite3.Row, titles: Mapping[str, str]) -> str:
    """A check as the checklist words it: "Receiving inspection: Actuator type label (3-1)" (the
    procedure's title and the step's text; their ids are for files)."""
    procedure_id = row["procedure_id"]
    procedure = titles.get(procedure_id) or _CHECK_SOURCES.get(procedure_id, procedure_id)
    section = f" ({row['section']})" if row["section"] else ""
    return f"{procedure}: {row['text'] or row['step_id']}{section}"


def _short(at_utc: str) -> str:
    """``2026-11-30 04:05:06`` (UTC) for people."""
    return at_utc[:19].replace("T", " ")
