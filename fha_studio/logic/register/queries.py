"""Questions to the register: snapshots and an axis's latest known values, differences, which
axes hold a value, where the procedures stand, the latest report, what is still open."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from fha_studio import names
from fha_studio.logic.register import guard
from fha_studio.logic.register.facts import Facts
from fha_studio.logic.register.guard import RegisterError
from fha_studio.logic.register.records import (
    SNAPSHOT_SOURCE_WORDS,
    Axis,
    Difference,
    Found,
    OpenItem,
    ParameterSet,
    ParameterValue,
    check_name,
    short_time,
    utc_stamp,
)

_COMPLETED = "completed"
_NOT_APPLICABLE = "not applicable"


@guard.in_words
class Queries(Facts):
    """Questions (nothing is changed)."""

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
            f"snapshot {row['id']} of {axis.ref} "
            f"({SNAPSHOT_SOURCE_WORDS[row['source']]}, {short_time(row['at_utc'])})"
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
        """The axis's snapshots, oldest first (then by their stable ids): number, time, who, source,
        file, how many values."""
        current = self.axis(axis)
        rows = self._db.execute(
            "SELECT snapshot.*, COUNT(snapshot_value.key) AS count FROM snapshot"
            " LEFT JOIN snapshot_value ON snapshot_value.snapshot_id = snapshot.id"
            " WHERE axis_id = ? GROUP BY snapshot.id ORDER BY at_utc, snapshot.uid",
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
        settled = [value for _, value in self._settled_values(current.id)]
        for value in [*(ParameterValue(*tuple(row)) for row in [*snapshot_rows, *write_rows]), *settled]:
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
        # each axis's latest row (the newest time, then the highest number), found by its own index
        # entries (a thousand axes with ten years of writes each: milliseconds, on either store);
        # the CTE is made first, then joined (never planned as a join over every snapshot), and
        # ``key || ''`` keeps both planners on the snapshot's own values, not on every value of the key;
        # a key no snapshot holds (written only) is seen at once, not after every snapshot of every axis
        queries = (
            "WITH latest AS MATERIALIZED (SELECT (SELECT t.id FROM snapshot t WHERE t.axis_id = a.id"
            " AND EXISTS (SELECT 1 FROM snapshot_value u WHERE u.snapshot_id = t.id AND u.key || '' = ?)"
            " ORDER BY t.at_utc DESC, t.id DESC LIMIT 1) AS id FROM axis a"
            " WHERE EXISTS (SELECT 1 FROM snapshot_value k WHERE k.key = ?))"
            " SELECT s.axis_id, v.mode, v.number, v.key, v.value, s.at_utc, s.source, s.id FROM latest"
            " JOIN snapshot s ON s.id = latest.id"
            " JOIN snapshot_value v ON v.snapshot_id = s.id AND v.key || '' = ?",
            "WITH latest AS MATERIALIZED (SELECT (SELECT x.id FROM parameter_write x WHERE x.axis_id = a.id"
            " AND x.key = ? AND x.verified = 1 ORDER BY x.at_utc DESC, x.id DESC LIMIT 1) AS id FROM axis a)"
            " SELECT w.axis_id, w.mode, w.number, w.key, COALESCE(w.read_back, w.new), w.at_utc, 'write',"
            " w.id"
            " FROM latest JOIN parameter_write w ON w.id = latest.id",
        )
        found = [
            (int(axis_id), ParameterValue(*fields))
            for query in queries
            for axis_id, *fields in (tuple(row) for row in self._db.execute(query, (key,) * query.count("?")))
        ]
        for axis_id, known in [*found, *self._settled_values(None, key)]:
            best = latest.get(axis_id)
            if best is None or (known.at_utc, known.ref) > (best.at_utc, best.ref):
                latest[axis_id] = known
        return [
            Found(axis, latest[axis_id])
            for axis_id, axis in axes.items()
            if axis_id in latest and (value is None or latest[axis_id].value == value)
        ]

    def _settled_values(
        self, axis_id: int | None, key: str | None = None
    ) -> list[tuple[int, ParameterValue]]:
        """(axis id, value) of the parameter values people settled in conflicts (of one axis, of
        one key): a settlement is a newer known value than those it settles (conflicts.py)."""
        sql = ("SELECT r.axis_id, r.id, r.at_utc, r.settled_json FROM conflict_resolution r"
               " JOIN conflict c ON c.uid = r.conflict_uid WHERE c.subject = 'parameters'")
        rows = self._db.execute(sql + " AND r.axis_id = ?", (axis_id,)) if axis_id is not None else (
            self._db.execute(sql))
        out = []
        for r in rows:
            try:
                settled = json.loads(r["settled_json"])
            except ValueError:
                continue
            for name, held in settled.items() if isinstance(settled, dict) else ():
                wire = held.get("value") if isinstance(held, dict) else None
                if key not in (None, name) or not isinstance(wire, int):
                    continue
                value = ParameterValue(str(held.get("mode", "")), int(held.get("number", 0)), name, wire,
                                       r["at_utc"], "settled", int(r["id"]))
                out.append((int(r["axis_id"]), value))
        return out

    def known_keys(self) -> set[str]:
        """Every parameter key the register has a value for."""
        rows = self._db.execute(
            "SELECT DISTINCT key FROM snapshot_value UNION SELECT DISTINCT key FROM parameter_write"
        )
        return {r[0] for r in rows}

    def _procedure_titles(self, axis_id: int) -> dict[str, str]:
        """{procedure id: its title} of the procedures recorded for the axis."""
        return {r["procedure_id"]: r["title"] for r in self._procedure_rows(axis_id) if r["title"]}

    def _procedure_rows(self, axis_id: int) -> list[Any]:
        """Where each procedure of the axis stands: its latest row (by time, then as recorded),
        in the order they were last recorded."""
        return list(self._db.execute(
            "SELECT axis_id, procedure_id, title, section, status, updated_utc, session_file"
            " FROM procedure_run p WHERE axis_id = ? AND NOT EXISTS (SELECT 1 FROM procedure_run q"
            " WHERE q.axis_id = p.axis_id AND q.procedure_id = p.procedure_id"
            " AND (q.updated_utc > p.updated_utc OR (q.updated_utc = p.updated_utc AND q.id > p.id)))"
            " ORDER BY id",
            (axis_id,),
        ))

    def procedure_status(self, axis: Axis | str | int) -> list[dict[str, Any]]:
        """Where each procedure of the axis stands (the latest of its states), in the order they
        were last recorded."""
        return [dict(r) for r in self._procedure_rows(self.axis(axis).id)]

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
                out.append(OpenItem(axis, "check", f"{check_name(r, titles)}: failed, not checked again"))
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
