"""An axis's history: every fact recorded for it as one sentence for people (and its data),
oldest first."""

from __future__ import annotations

import dataclasses
import datetime as _dt
import json
from collections.abc import Mapping
from typing import Any

from fha_studio.logic.register import guard, words
from fha_studio.logic.register.conflicts import Conflict, Conflicts, item_name, side_name, value_words
from fha_studio.logic.register.records import (
    CORRECTED_WORDS,
    KIND_TABLES,
    SNAPSHOT_SOURCE_WORDS,
    Axis,
    Event,
    EventKind,
    check_name,
    short_time,
    utc_stamp,
)

#: Facts recorded at the same time are told in this order (facts of one kind at the same time by
#: their stable ids: every register that holds them tells them in the same order, whatever order
#: they reached it in).
HISTORY_ORDER = (
    EventKind.AXIS,
    EventKind.SNAPSHOT,
    EventKind.WRITE,
    EventKind.CHECK,
    EventKind.ALARM,
    EventKind.RECORDING,
    EventKind.MODEL_CHECK,
    EventKind.REPORT,
    EventKind.CONFLICT,
    EventKind.SETTLED,
)


@guard.in_words
class History(Conflicts):
    """The history of an axis."""

    def history(self, axis: Axis | str | int, since: str | None = None) -> list[Event]:
        """Everything recorded for the axis, oldest first."""
        current = self.axis(axis)
        a = current.id

        def rows(kind: EventKind) -> Any:
            return self._db.execute(f"SELECT * FROM {KIND_TABLES[kind]} WHERE axis_id = ?", (a,))

        events = [_event(r, EventKind.AXIS, r["text"]) for r in rows(EventKind.AXIS)]
        for r in self.snapshots(current):
            where = f" ({r['file']})" if r["file"] else ""
            events.append(_event(
                r, EventKind.SNAPSHOT,
                f"parameters {SNAPSHOT_SOURCE_WORDS[r['source']]}: {r['count']} values,"
                f" snapshot {r['id']}{where}",
                {"source": r["source"], "file": r["file"], "count": r["count"]},
            ))
        for r in rows(EventKind.WRITE):
            outcome = "verified" if r["verified"] else f"NOT verified ({r['error'] or 'read-back differs'})"
            name = words.parameter_name(r["key"], current.driver_model, (r["mode"], r["number"]))
            change = words.change_text(r["key"], r["old"], r["new"], current.driver_model)
            events.append(_event(
                r, EventKind.WRITE, f"{name}: {change}, {outcome}",
                {k: r[k] for k in ("mode", "number", "key", "old", "new", "read_back", "verified", "error")},
            ))
        titles = self._procedure_titles(a)
        for r in rows(EventKind.CHECK):
            value = json.loads(r["value_json"])
            shown = ("yes" if value else "no") if r["kind"] == "confirm" else f"{value} {r['unit']}".strip()
            verdict = "pass" if r["passed"] else "FAIL"
            if isinstance(value, dict):  # a check with several readings: its own sentence says them
                shown = r["detail"] or words.readings_text(value)
            events.append(_event(
                r, EventKind.CHECK, f"{check_name(r, titles)}: {shown} — {verdict}",
                {
                    "procedure_id": r["procedure_id"],
                    "step_id": r["step_id"],
                    "value": value,
                    "passed": bool(r["passed"]),
                    "expected": r["expected"],
                    "detail": r["detail"],
                },
            ))
        for r in rows(EventKind.ALARM):
            note = f" ({r['note']})" if r["note"] else ""
            events.append(_event(r, EventKind.ALARM, f"alarm {r['code']}: {r['name']}{note}",
                                 {"code": r["code"]}))
        for r in rows(EventKind.REPORT):
            signed = f"signed by {r['signed_by']}" if r["signed_by"] else "not signed"
            events.append(_event(
                r, EventKind.REPORT, f"report {r['file']} ({signed}, {r['open_warnings']} open warnings)",
                {"file": r["file"], "sha256": r["sha256"], "signed_by": r["signed_by"]},
            ))
        for r in rows(EventKind.RECORDING):
            summary = f": {r['summary']}" if r["summary"] else ""
            events.append(_event(r, EventKind.RECORDING, f"recording {r['file']}{summary}",
                                 {"file": r["file"]}))
        for r in rows(EventKind.MODEL_CHECK):
            events.append(_event(
                r, EventKind.MODEL_CHECK, f"model check: {r['summary']}",
                {"file": r["file"], "recording_file": r["recording_file"]},
            ))
        events += _conflict_events(self.conflicts(current, open_only=False))
        events = self._with_receipts(_with_corrections(events), a)
        if since is not None:
            cutoff = utc_stamp(since)
            events = [e for e in events if e.at_utc >= cutoff]
        order = {kind: n for n, kind in enumerate(HISTORY_ORDER)}
        return sorted(events, key=lambda e: (e.at_utc, order[e.kind], e.uid, e.ref or 0))

    def _with_receipts(self, events: list[Event], axis_id: int) -> list[Event]:
        """On a server with roles: when each fact reached the server and from which login (its
        data: ``received_utc``, ``received_by``), said in its line when that was more than the
        roles' tolerance after its own time (a laptop that worked offline, or a fact dated back)."""
        if not self._url:
            return events
        from fha_studio.logic.register import roles

        if not roles.has_receipts(self._db):
            return events
        kinds = {e.kind for e in events}
        got = {kind: roles.receipts(self._db, KIND_TABLES[kind], axis_id) for kind in kinds}
        late = _dt.timedelta(seconds=roles.FUTURE_TOLERANCE_S)
        out = []
        for e in events:
            receipt = got[e.kind].get(e.ref) if e.ref is not None else None
            if receipt is None:
                out.append(e)
                continue
            received, login = receipt
            text = e.text
            if _moment(received) - _moment(e.at_utc) > late:
                text += f" — reached the server {short_time(received)} UTC from {login}"
            out.append(dataclasses.replace(e, text=text, data={**e.data, "received_utc": received,
                                                               "received_by": login}))
        return out


def _moment(stamp: str) -> _dt.datetime:
    return _dt.datetime.fromisoformat(stamp)


def _conflict_events(conflicts: list[Conflict]) -> list[Event]:
    """A conflict a sync found (open: how to settle it), and each settlement of it."""
    out = []
    for c in conflicts:
        hint = f" — settle it: fha-studio register resolve {c.short} --keep 1 or 2" if c.open else ""
        out.append(Event(c.at_utc, EventKind.CONFLICT, c.who, f"conflict {c.short}: {c.summary()}{hint}",
                         c.id, {"conflict": c.short, "subject": c.subject, "open": c.open,
                                **({"hint": hint} if hint else {})}, c.uid))
        for r in c.resolutions:
            side = c.sides[r.kept - 1] if 0 < r.kept <= len(c.sides) else None
            kept = "; ".join(
                f"{item_name(c.subject, k, c.sides, c.axis.driver_model)} "
                f"{value_words(c.subject, k, v, c.axis.driver_model)}"
                for k, v in (side.values.items() if side else ()))
            note = f" ({r.note})" if r.note else ""
            out.append(Event(r.at_utc, EventKind.SETTLED, r.who,
                             f"conflict {c.short} settled: kept {r.kept}, {side_name(side) if side else ''}: "
                             f"{kept}{note}", r.id, {"conflict": c.short, "kept": r.kept}, r.uid))
    return out


def _event(row: Mapping[str, Any], kind: EventKind, text: str,
           data: Mapping[str, Any] | None = None) -> Event:
    """A fact's row as a history line: its time, who, row id and stable id as every fact table
    holds them, ``data`` with the fact it corrects."""
    return Event(row["at_utc"], kind, row["who"], text, row["id"], {**(data or {}), **_corrects(row)},
                 uid=row["uid"])


def _corrects(row: Mapping[str, Any]) -> dict[str, int]:
    """A history line's data names the fact it corrects (none: nothing)."""
    return {} if row["corrects"] is None else {"corrects": int(row["corrects"])}


def _with_corrections(events: list[Event]) -> list[Event]:
    """Each correction says which fact it corrects, and each corrected fact by which (its data
    lists them in ``corrected_by``); the corrected fact stays, as it was recorded."""
    by: dict[tuple[EventKind, int | None], list[int | None]] = {}
    for e in events:
        if "corrects" in e.data:
            by.setdefault((e.kind, e.data["corrects"]), []).append(e.ref)
    if not by:
        return events
    out = []
    for e in events:
        word = CORRECTED_WORDS[KIND_TABLES[e.kind]]
        text, data = e.text, dict(e.data)
        if "corrects" in data:
            text += f" — corrects {word} {data['corrects']}"
        later = by.get((e.kind, e.ref))
        if later:
            text += f" — corrected by {word} {', '.join(str(n) for n in later)}"
            data["corrected_by"] = later
        out.append(dataclasses.replace(e, text=text, data=data))
    return out
