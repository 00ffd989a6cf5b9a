"""The facts recorded for an axis: parameter snapshots, verified writes, procedure checks and
where each procedure stands, alarms, reports, recordings, model checks."""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from fha_studio.logic.register import guard
from fha_studio.logic.register.axes import Axes
from fha_studio.logic.register.connection import FACT_ID_MARKS, FACT_IDS
from fha_studio.logic.register.guard import RegisterError
from fha_studio.logic.register.records import SOURCES, Axis, file_sha256, utc_stamp


@guard.in_words
class Facts(Axes):
    """Recording facts: every write is one transaction."""

    def _insert_fact(self, db: Any, table: str, current: Axis, at_utc: str, who: str, corrects: int | None,
                     **columns: Any) -> int:
        """A fact's row in ``table`` (one with an axis): ``columns`` with what every such row holds
        (the axis, the time, who, the fact of the axis it corrects, its identity: FACT_IDS); its
        row id."""
        names = ["axis_id", "at_utc", "who", *columns, "corrects"]
        values = (current.id, at_utc, who, *columns.values(), self._corrected(table, corrects, current))
        cursor = db.execute(
            f"INSERT INTO {table} ({', '.join(names)}, {FACT_IDS})"
            f" VALUES ({', '.join('?' for _ in names)}, {FACT_ID_MARKS})",
            (*values, *self._fact_ids()),
        )
        return int(cursor.lastrowid or 0)

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
        corrects: int | None = None,
    ) -> int:
        """A snapshot of parameter values: ``values`` are (mode, number, key, wire value);
        ``source`` is "link" (read from the drive), "front_panel" (read off the drive's panel by
        a person) or "file"; ``corrects``: the number of the snapshot of the axis it corrects (one
        entered wrong). Returns the snapshot's number."""
        if source not in SOURCES:
            raise RegisterError(f"snapshot source '{source}' is not one of {', '.join(SOURCES)}")
        rows: dict[tuple[str, int], tuple[str, int, str, int]] = {}
        for mode, number, key, value in values:
            if isinstance(value, bool) or not isinstance(value, int):
                raise RegisterError(
                    f"parameter {mode} {number} ({key}): value {value!r} is not a wire integer"
                )
            # a parameter given twice: the last value given
            rows[(str(mode), int(number))] = (str(mode), int(number), str(key), int(value))
        if not rows:
            raise RegisterError("a parameter snapshot needs at least one value")
        current = self.axis(axis)
        with self._transaction() as db:
            snapshot_id = self._insert_fact(db, "snapshot", current, utc_stamp(at_utc), who, corrects,
                                            source=source, driver_model=driver_model, file=str(file),
                                            note=note)
            db.executemany(
                "INSERT INTO snapshot_value (snapshot_id, mode, number, key, value) VALUES (?, ?, ?, ?, ?)",
                [(snapshot_id, *row) for row in rows.values()],
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
        corrects: int | None = None,
    ) -> int:
        """One parameter write and whether the read-back verified it. Returns its row id."""
        current = self.axis(axis)
        with self._transaction() as db:
            return self._insert_fact(
                db, "parameter_write", current, utc_stamp(at_utc), who, corrects, mode=str(mode),
                number=int(number), key=key, old=old, new=int(new), read_back=read_back,
                verified=int(bool(verified)), error=error or "",
            )

    def record_checks(
        self,
        axis: Axis | str | int,
        records: Iterable[Any],
        session_file: str | Path = "",
    ) -> int:
        """Procedure check records (objects with the fields of a session's CheckRecord; one with
        a ``corrects`` attribute corrects that check of the axis). A record already in the
        register (same procedure, step and time) is not added twice. Returns how many were new."""
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
                self._corrected("check_result", getattr(r, "corrects", None), current),
                *self._fact_ids(),
            )
            for r in records
        ]
        with self._transaction() as db:
            before = db.total_changes
            db.executemany(
                "INSERT OR IGNORE INTO check_result (axis_id, procedure_id, step_id, kind, section, text,"
                " value_json, expected, unit, passed, who, at_utc, detail, session_file, corrects,"
                f" {FACT_IDS}) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, {FACT_ID_MARKS})",
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
        """Where a procedure of the axis stands from now on (not_started, running, paused,
        stopped, completed, or "not applicable"): a row of its own, the latest one counts; nothing
        is added when it stands as the latest row says."""
        current = self.axis(axis)
        with self._transaction() as db:
            latest = db.execute(
                "SELECT title, section, status, session_file FROM procedure_run WHERE axis_id = ?"
                " AND procedure_id = ? ORDER BY updated_utc DESC, id DESC LIMIT 1",
                (current.id, procedure_id),
            ).fetchone()
            if latest is not None and tuple(latest) == (title, section, status, str(session_file)):
                return
            db.execute(
                "INSERT INTO procedure_run (axis_id, procedure_id, title, section, status,"
                f" updated_utc, session_file, {FACT_IDS}) VALUES (?, ?, ?, ?, ?, ?, ?, {FACT_ID_MARKS})",
                (current.id, procedure_id, title, section, status, utc_stamp(at_utc), str(session_file),
                 *self._fact_ids()),
            )

    def record_alarm(
        self,
        axis: Axis | str | int,
        code: int,
        name: str = "",
        who: str = "",
        at_utc: str | None = None,
        note: str = "",
        corrects: int | None = None,
    ) -> int:
        current = self.axis(axis)
        with self._transaction() as db:
            return self._insert_fact(db, "alarm", current, utc_stamp(at_utc), who, corrects, code=int(code),
                                     name=name, note=note)

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
        corrects: int | None = None,
    ) -> int:
        """A report file written for one axis (or a whole machine: ``machine`` without ``axis``);
        its SHA-256 is kept so that a report changed later can be told."""
        path = Path(file)
        current: Axis | None = None
        if axis is not None:
            current = self.axis(axis)
            machine_id, axis_id = self.machine(current.machine).id, current.id
        elif machine is not None:
            machine_id, axis_id = self.machine(machine).id, None
        else:
            raise RegisterError("a report belongs to an axis or a machine")
        digest = file_sha256(path)
        corrected = self._corrected("report", corrects, current, machine_id)
        with self._transaction() as db:
            cursor = db.execute(
                "INSERT INTO report (machine_id, axis_id, at_utc, who, file, sha256, signed_by, signed_utc,"
                f" open_warnings, corrects, {FACT_IDS})"
                f" VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, {FACT_ID_MARKS})",
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
                    corrected,
                    *self._fact_ids(),
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
        corrects: int | None = None,
    ) -> int:
        """A recording file (``fha-recording/1``) taken on the axis."""
        current = self.axis(axis)
        path = Path(file)
        digest = file_sha256(path) if path.is_file() else ""
        with self._transaction() as db:
            return self._insert_fact(db, "recording", current, utc_stamp(at_utc), who, corrects,
                                     file=str(path.resolve()), sha256=digest, summary=summary)

    def record_model_check(
        self,
        axis: Axis | str | int,
        summary: str,
        file: str | Path = "",
        recording_file: str | Path = "",
        who: str = "",
        at_utc: str | None = None,
        corrects: int | None = None,
    ) -> int:
        """A model-check result: its summary, the report or model file it wrote, the recording."""
        current = self.axis(axis)
        with self._transaction() as db:
            return self._insert_fact(db, "model_check", current, utc_stamp(at_utc), who, corrects,
                                     file=str(file), recording_file=str(recording_file), summary=summary)
