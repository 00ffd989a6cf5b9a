"""Correcting a mistake in the register: a new fact of the same kind that points at the one it
corrects (its ``corrects``), never a change of that fact (the history is append-only,
:mod:`.append_only`). What a person can get wrong is what a person entered: parameter values read
off the front panel, a check's answer, a note. What the drive or a file said (a write, an alarm, a
report, a recording, a model check) is recorded again, or a note says what was wrong with it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

from fha_studio.logic.register.guard import RegisterError
from fha_studio.logic.register.records import utc_stamp
from fha_studio.logic.register.store import Register

#: What can be corrected here, as the command names it, and its table.
KINDS = {"snapshot": "snapshot", "check": "check_result", "note": "axis_event"}


@dataclass(frozen=True)
class Correction:
    """A correction recorded: its kind, its number, the number of the fact it corrects, the axis."""

    kind: str
    number: int
    corrects: int
    axis: str
    what: str  # the change in words

    def as_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "number": self.number, "corrects": self.corrects, "axis": self.axis,
                "what": self.what}


def _row(register: Register, kind: str, number: int) -> Any:
    row = register._db.execute(f"SELECT * FROM {KINDS[kind]} WHERE id = ?", (int(number),)).fetchone()
    if row is None:
        raise RegisterError(f"there is no {kind} number {number} in the register")
    return row


def correct_snapshot(
    register: Register, number: int, values: dict[str, int], reason: str, who: str = ""
) -> Correction:
    """A snapshot with snapshot ``number``'s values, those in ``values`` (by key) as they should
    have been: entered by a person (``front_panel``), noted with ``reason``."""
    if not values:
        raise RegisterError("a corrected snapshot needs the values that were wrong (KEY=VALUE)")
    wrong = register.snapshot(number)
    unknown = sorted(set(values) - set(wrong.values))
    if unknown:
        raise RegisterError(f"snapshot {number} holds no {', '.join(unknown)}: a correction gives the "
                            "right value of a value it holds")
    changed = {k: v for k, v in values.items() if wrong.values[k].value != v}
    if not changed:
        raise RegisterError(f"snapshot {number} already holds those values: nothing to correct")
    rows = [(v.mode, v.number, v.key, changed.get(k, v.value)) for k, v in sorted(wrong.values.items())]
    made = register.record_snapshot(wrong.axis, rows, "front_panel", who=who,
                                    driver_model=wrong.axis.driver_model, note=_said(reason), corrects=number)
    what = ", ".join(f"{k}: {wrong.values[k].value} → {v}" for k, v in sorted(changed.items()))
    return Correction("snapshot", made, number, wrong.axis.ref, what)


def correct_check(
    register: Register, number: int, reason: str, passed: bool | None = None, value: Any = None,
    who: str = "",
) -> Correction:
    """The answer check ``number`` should have had (``passed``, ``value``: what changes), a new
    answer of the same check, noted with ``reason``."""
    if passed is None and value is None:
        raise RegisterError("a corrected check needs its right answer (passed or not, its value)")
    row = _row(register, "check", number)
    axis = register.axis(int(row["axis_id"]))
    old_value = json.loads(row["value_json"])
    record = SimpleNamespace(
        procedure_id=row["procedure_id"], step_id=row["step_id"], kind=row["kind"], section=row["section"],
        text=row["text"], value=old_value if value is None else value, expected=row["expected"],
        unit=row["unit"], passed=bool(row["passed"]) if passed is None else passed, who=who,
        at_utc=utc_stamp(), detail=_said(reason), corrects=number)
    if register.record_checks(axis, [record]) != 1:
        raise RegisterError(f"check {number} was just answered again: correct it in a moment")
    made = register._db.execute(
        "SELECT id FROM check_result WHERE corrects = ? ORDER BY id DESC LIMIT 1", (number,)).fetchone()[0]
    parts = []
    if passed is not None and passed != bool(row["passed"]):
        parts.append(f"{'FAIL' if row['passed'] == 0 else 'pass'} → {'pass' if passed else 'FAIL'}")
    if value is not None and value != old_value:
        parts.append(f"{old_value} → {value}")
    return Correction("check", int(made), number, axis.ref, ", ".join(parts) or "answered again")


def correct_note(register: Register, number: int, text: str, who: str = "") -> Correction:
    """A note of the axis that corrects its entry ``number`` (a note, an origin, a change)."""
    if not text.strip():
        raise RegisterError("a correcting note needs its text")
    row = _row(register, "note", number)
    axis = register.axis(int(row["axis_id"]))
    made = register.add_axis_note(axis, text.strip(), who=who, corrects=number)
    return Correction("note", made, number, axis.ref, text.strip())


def _said(reason: str) -> str:
    reason = " ".join(reason.split())
    if not reason:
        raise RegisterError("a correction says why (--reason): the history keeps it")
    return f"correction: {reason}"
