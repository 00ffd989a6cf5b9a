"""Conflicts: an axis changed in two registers while they were apart (a laptop offline and the
plant's server, or two laptops), on which they disagree. A sync (:mod:`.sync`) finds them; both
registers keep every fact of both sides, and the conflict, a fact of its own, says what each side
holds, for a person to settle. Nothing is picked silently.

What two sides can disagree on (:data:`SUBJECTS`):

- ``parameters``: the latest known value of a parameter (a snapshot or a verified write) differs
  between what each side recorded while apart, and both changed it (:func:`changed_apart`: a
  value one side changed while the other only read again the value both held before is a later
  change, not a conflict, unless that reading came after the change);
- ``origin``: the latest origin set on the axis differs (the same rule);
- ``axis``: a field of the axis (actuator, driver, serial number, load inertia, notes) holds
  different values in the two registers and neither side's change explains it.

A person settles one by a resolution (:meth:`Conflicts.resolve_conflict`): a new fact that names
the conflict and the side kept. The history stays as it was written: the facts of both sides
stay, the conflict stays, the resolution is added. What it settles takes effect as any newer fact
does: a kept origin is the axis's origin again, a kept field the axis's field, kept parameter
values the axis's latest known values (``settled``).
"""

from __future__ import annotations

import json
import uuid
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, field
from typing import Any

from fha_studio import names
from fha_studio.logic.register import guard, words
from fha_studio.logic.register.axes import ORIGIN_PREFIX
from fha_studio.logic.register.connection import FACT_ID_MARKS, FACT_IDS
from fha_studio.logic.register.guard import RegisterError
from fha_studio.logic.register.queries import Queries
from fha_studio.logic.register.records import Axis, OpenItem, utc_stamp

#: What a conflict is about, in words: what differs.
SUBJECTS = {"parameters": "parameters differ", "origin": "the origin differs", "axis": "axis fields differ"}
#: The fields of an axis two registers may disagree on (the port is each computer's own: a laptop's
#: COM3 is another's /dev/ttyUSB0; the name is how the axis is found).
COMPARED_FIELDS = ("actuator_code", "driver_model", "serial_number", "load_inertia_kgm2", "notes")
#: A field's name in words.
FIELD_WORDS = {
    "actuator_code": "actuator",
    "driver_model": "driver",
    "serial_number": "serial number",
    "load_inertia_kgm2": "load inertia",
    "notes": "notes",
}
#: How short a conflict's id may be given (its first characters; ``register conflicts`` shows 8).
SHORTEST_REF = 4
_NAMESPACE = uuid.UUID("8a0f3a53-5b0e-4d6f-9a43-26c0ff11c7e1")


@dataclass(frozen=True)
class SideValue:
    """What one side holds for one item, and the fact that says it ("" for a value an axis held
    before facts said what they set)."""

    value: Any
    fact: str = ""
    kind: str = ""  # "snapshot", "write", "settled", "axis entry", "axis"
    who: str = ""
    at_utc: str = ""
    recorded_in: str = ""
    mode: str = ""  # a parameter's mode and number
    number: int = 0
    where: str = ""  # the name of the register it was recorded in


@dataclass(frozen=True)
class ConflictSide:
    """What one register held when the two met."""

    register_id: str
    register: str
    values: Mapping[str, SideValue]

    def as_dict(self) -> dict[str, Any]:
        return {
            "register_id": self.register_id,
            "register": self.register,
            "values": {k: _clean(asdict(v)) for k, v in self.values.items()},
        }


@dataclass(frozen=True)
class Resolution:
    """A person's settlement of a conflict: the side kept, and what it settles."""

    uid: str
    at_utc: str
    who: str
    kept: int
    note: str
    recorded_in: str
    settled: Mapping[str, Any]
    id: int = 0  # its row in this register


@dataclass(frozen=True)
class HeldWords:
    """What one side of a conflict held for one item, for people."""

    value: str  # in the item's words: "1: FWD turns CCW (reversed)", "25 pulse"
    source: str  # the fact that says it: "parameters read", "verified write", "axis entry"
    who: str
    when: str  # UTC, "2026-12-05 08:12:40"
    where: str  # the register it was recorded in


@dataclass(frozen=True)
class Conflict:
    """An axis changed in two registers while apart, on which they disagree."""

    uid: str
    id: int
    axis: Axis
    subject: str
    at_utc: str
    who: str
    recorded_in: str
    sides: tuple[ConflictSide, ...]
    resolutions: tuple[Resolution, ...] = field(default=())

    @property
    def short(self) -> str:
        """The conflict as a person names it (``register resolve 1a2b3c4d``)."""
        return self.uid[:8]

    @property
    def open(self) -> bool:
        """Not settled yet, or settled twice differently (two people apart)."""
        return len({json.dumps(r.settled, sort_keys=True) for r in self.resolutions}) != 1

    def items(self) -> list[str]:
        return sorted({k for side in self.sides for k in side.values})

    def item_name(self, key: str) -> str:
        """An item in the manual's words: ``parameter 8 Rotary direction``, ``origin``, ``actuator``."""
        return item_name(self.subject, key, self.sides, self.axis.driver_model)

    def held_words(self, key: str, side: ConflictSide) -> HeldWords | None:
        """What ``side`` held for ``key``, in words (None: nothing recorded)."""
        held = side.values.get(key)
        if held is None:
            return None
        return HeldWords(
            value_words(self.subject, key, held, self.axis.driver_model),
            _KIND_WORDS.get(held.kind, held.kind),
            held.who,
            words.when_text(held.at_utc),
            held.where or side.register,
        )

    def lines(self) -> list[str]:
        """The conflict for people: what it is about, then each side's values (numbered: the
        number ``--keep`` takes)."""
        out = []
        for key in self.items():
            out.append(f"  {self.item_name(key)}:")
            for n, side in enumerate(self.sides, 1):
                held = self.held_words(key, side)
                if held is None:
                    out.append(f"    {n}. {side_name(side)}: (nothing recorded)")
                    continue
                by = ", ".join(t for t in (held.who, held.when) if t)
                from_what = f" — {held.source}" if held.source else ""
                out.append(f"    {n}. {held.value}{from_what}{f' ({by})' if by else ''}, in {held.where}")
        return out

    def differs_words(self) -> str:
        """What differs, in words: "parameters differ: parameter 8 Rotary direction"; the origin is
        one item, which its subject names ("the origin differs", not "the origin differs: origin")."""
        subject = SUBJECTS.get(self.subject, self.subject)
        if self.subject == "origin":
            return subject
        return f"{subject}: {', '.join(self.item_name(k) for k in self.items())}"

    def summary(self) -> str:
        """One line: what differs, and where it stands."""
        what = ", ".join(item_name(self.subject, k, self.sides, self.axis.driver_model) for k in self.items())
        where = " and ".join(side_name(side) for side in self.sides)
        state = "open" if self.open else f"settled: kept {self.resolutions[-1].kept}"
        if self.open and len(self.resolutions) > 1:
            state = "open: settled twice differently"
        items = "" if self.subject == "origin" else f" ({what})"  # the subject names the origin
        return f"{SUBJECTS.get(self.subject, self.subject)} between {where}{items}: {state}"

    def as_dict(self) -> dict[str, Any]:
        return {
            "id": self.short,
            "uid": self.uid,
            "axis": self.axis.ref,
            "subject": self.subject,
            "found_utc": self.at_utc,
            "found_by": self.who,
            "open": self.open,
            "text": self.summary(),
            "sides": [s.as_dict() for s in self.sides],
            "resolutions": [_clean(asdict(r)) for r in self.resolutions],
        }


_KIND_WORDS = {
    "snapshot": "parameters read",
    "write": "verified write",
    "settled": "settled by a person",
    "axis entry": "axis entry",
    "axis": "as the register held it",
}


def side_name(side: ConflictSide) -> str:
    """A side by where its facts were recorded (a laptop's register, not the server they met on)."""
    found = sorted({v.where for v in side.values.values() if v.where})
    return " and ".join(found) if found else side.register


def _clean(data: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in data.items() if v not in ("", None) or k == "value"}


def item_name(subject: str, key: str, sides: Iterable[ConflictSide], driver_model: str = "") -> str:
    if subject == "parameters":
        held = next((s.values[key] for s in sides if key in s.values), None)
        where = (held.mode, held.number) if held is not None and held.mode else None
        return words.parameter_name(key, driver_model, where)
    if subject == "axis":
        return FIELD_WORDS.get(key, key)
    return "origin"


def value_words(subject: str, key: str, held: SideValue, driver_model: str = "") -> str:
    if subject == "parameters":
        return words.value_text(key, held.value, driver_model)
    if held.value in (None, ""):
        return "not given"
    if key == "load_inertia_kgm2":
        return f"{float(held.value):g} kg·m²"
    return str(held.value)


def conflict_uid(ref: str, subject: str, sides: Iterable[ConflictSide]) -> str:
    """A conflict's id from what it is (the same conflict found again, by a sync run again after
    it was stopped, is the same fact): the axis, the subject, each side's values and facts."""
    seed = [
        ref,
        subject,
        sorted(
            [side.register_id, sorted((k, json.dumps(v.value), v.fact) for k, v in side.values.items())]
            for side in sides
        ),
    ]
    return str(uuid.uuid5(_NAMESPACE, json.dumps(seed, sort_keys=True)))


# -- what each side holds ------------------------------------------------------------------------------
def latest_parameters(rows: Iterable[Mapping[str, Any]]) -> dict[str, SideValue]:
    """Each parameter's latest value among ``rows`` (a snapshot's values, verified writes, settled
    values: ``key``, ``value``, ``mode``, ``number``, ``uid``, ``kind``, ``who``, ``at_utc``,
    ``recorded_in``): the newest, then the greatest uid (the same choice in every register)."""
    latest: dict[str, tuple[tuple[str, str], SideValue]] = {}
    for r in rows:
        order = (str(r["at_utc"]), str(r["uid"]))
        known = latest.get(r["key"])
        if known is None or order > known[0]:
            latest[r["key"]] = (
                order,
                SideValue(
                    int(r["value"]),
                    r["uid"],
                    r["kind"],
                    r["who"],
                    r["at_utc"],
                    r["recorded_in"],
                    r["mode"],
                    int(r["number"]),
                ),
            )
    return {k: v for k, (_, v) in latest.items()}


def latest_origin(rows: Iterable[Mapping[str, Any]]) -> dict[str, SideValue]:
    """The latest origin among axis entries (``text``, ``uid``, ``who``, ``at_utc``, ``recorded_in``)."""
    found: tuple[tuple[str, str], SideValue] | None = None
    for r in rows:
        if not str(r["text"]).startswith(ORIGIN_PREFIX):
            continue
        order = (str(r["at_utc"]), str(r["uid"]))
        if found is None or order > found[0]:
            found = (
                order,
                SideValue(
                    r["text"][len(ORIGIN_PREFIX) :],
                    r["uid"],
                    "axis entry",
                    r["who"],
                    r["at_utc"],
                    r["recorded_in"],
                ),
            )
    return {"origin": found[1]} if found else {}


def field_settings(rows: Iterable[Mapping[str, Any]]) -> dict[str, SideValue]:
    """The latest value each axis entry among ``rows`` set for each field (an axis added sets
    the fields it was given; a change sets its field), the newest, then the greatest uid."""
    latest: dict[str, tuple[tuple[str, str], SideValue]] = {}
    for r in rows:
        data = _data(r["data"])
        order = (str(r["at_utc"]), str(r["uid"]))
        if isinstance(data.get("axis_added"), dict):
            setting = {k: v for k, v in data["axis_added"].items() if v not in (None, "")}
        elif "field" in data:
            setting = {str(data["field"]): data.get("new")}
        else:
            continue
        for key, value in setting.items():
            known = latest.get(key)
            if known is None or order > known[0]:
                latest[key] = (
                    order,
                    SideValue(value, r["uid"], "axis entry", r["who"], r["at_utc"], r["recorded_in"]),
                )
    return {k: v for k, (_, v) in latest.items()}


def _data(text: Any) -> dict[str, Any]:
    try:
        data = json.loads(text) if text else {}
    except ValueError:
        return {}
    return data if isinstance(data, dict) else {}


def disagreement(a: Mapping[str, SideValue], b: Mapping[str, SideValue]) -> list[str]:
    """The items both hold with different values."""
    return sorted(k for k in set(a) & set(b) if a[k].value != b[k].value)


def changed_apart(
    a: Mapping[str, SideValue], b: Mapping[str, SideValue], before: Mapping[str, SideValue]
) -> list[str]:
    """The items on which two sides' latest values while apart (``a``, ``b``) are a conflict.
    ``before``: what both held before (the latest of the facts both registers have).

    A side changed an item when its value is not the one both held before. Both changed it
    (to different values): a conflict. Only one changed it: the other recorded the value both
    held (a parameter read again, unchanged), so the change is no conflict when it is the later
    of the two (it was made after the value it replaces was known, as any later change); when the
    other side recorded the old value after the change, not knowing of it, the register's latest
    value would silently undo the change: a conflict, for a person to look at."""
    out = []
    for key in disagreement(a, b):
        held = before.get(key)
        a_new = held is None or a[key].value != held.value
        b_new = held is None or b[key].value != held.value
        if a_new and b_new:
            out.append(key)
            continue
        changed, kept = (a[key], b[key]) if a_new else (b[key], a[key])
        if (kept.at_utc, kept.fact) > (changed.at_utc, changed.fact):
            out.append(key)
    return out


@guard.in_words
class Conflicts(Queries):
    """The conflicts a sync found, and their settlement."""

    def conflicts(
        self, axis: Axis | str | int | None = None, open_only: bool = True, machine: str | None = None
    ) -> list[Conflict]:
        """The conflicts (of one axis, or one machine's), oldest first (then by their stable ids, the
        same order in every register); only open ones unless ``open_only`` is False."""
        sql, args = "SELECT * FROM conflict", []
        if axis is not None:
            sql, args = sql + " WHERE axis_id = ?", [self.axis(axis).id]
        rows = list(self._db.execute(sql + " ORDER BY at_utc, uid", tuple(args)))
        if not rows:
            return []
        settled: dict[str, list[Resolution]] = {}
        for r in self._db.execute("SELECT * FROM conflict_resolution ORDER BY at_utc, uid"):
            settled.setdefault(r["conflict_uid"], []).append(
                Resolution(
                    r["uid"],
                    r["at_utc"],
                    r["who"],
                    int(r["kept"]),
                    r["note"],
                    r["recorded_in"],
                    _data(r["settled_json"]),
                    int(r["id"]),
                )
            )
        axes: dict[int, Axis] = {}
        out = []
        for r in rows:
            if r["axis_id"] not in axes:
                axes[r["axis_id"]] = self.axis(int(r["axis_id"]))
            found = Conflict(
                r["uid"],
                int(r["id"]),
                axes[r["axis_id"]],
                r["subject"],
                r["at_utc"],
                r["who"],
                r["recorded_in"],
                _sides(r["sides_json"]),
                tuple(settled.get(r["uid"], ())),
            )
            if machine is not None and found.axis.machine != machine.strip():
                continue
            if found.open or not open_only:
                out.append(found)
        return out

    def open_items(self, machine: str | None = None) -> list[OpenItem]:
        """What keeps each axis from being done (:meth:`Queries.open_items`), and its open
        conflicts."""
        items = super().open_items(machine)
        for c in self.conflicts(machine=machine):
            items.append(OpenItem(c.axis, "conflict", f"conflict {c.short}: {c.summary()}"))
        return items

    def conflict(self, ref: str) -> Conflict:
        """A conflict by its id or its first characters (at least four)."""
        text = str(ref).strip().lower()
        if len(text) < SHORTEST_REF:
            raise RegisterError(
                f"{names.quoted(str(ref), 40)}: name a conflict by at least {SHORTEST_REF} "
                "characters of its id (fha-studio register conflicts lists them)"
            )
        found = [c for c in self.conflicts(open_only=False) if c.uid.startswith(text)]
        if not found:
            raise RegisterError(
                f"no conflict {names.quoted(str(ref), 40)} in the register "
                "(fha-studio register conflicts lists them)"
            )
        if len(found) > 1:
            raise RegisterError(
                f"{names.quoted(str(ref), 40)} names {len(found)} conflicts: give more of its id"
            )
        return found[0]

    def conflict_record(self, uid: str) -> dict[str, Any]:
        """The conflict with stable id ``uid`` as this register holds it (its columns, the axis by
        ``MACHINE/AXIS``), for a register that lacks it: :meth:`take_conflict`."""
        row = self._db.execute(
            "SELECT conflict.*, machine.name AS machine_name, axis.name AS axis_name FROM conflict"
            " JOIN axis ON axis.id = conflict.axis_id JOIN machine ON machine.id = axis.machine_id"
            " WHERE conflict.uid = ?",
            (uid,),
        ).fetchone()
        if row is None:
            raise RegisterError(f"no conflict {names.quoted(uid, 40)} in the register")
        columns = row.keys()  # a row's keys (iterating a row gives its values)
        record = {k: row[k] for k in columns if k not in ("id", "axis_id", "machine_name", "axis_name")}
        return {**record, "axis": f"{row['machine_name']}/{row['axis_name']}"}

    def take_conflict(self, record: Mapping[str, Any]) -> None:
        """A conflict another register found (:meth:`conflict_record`), the same fact with the same
        stable id, into this register (its axis there already); nothing when it is here. So a
        settlement can be recorded in a register that did not hold the conflict (this computer's
        queue for a server, which the server's facts do not come back to)."""
        axis = self.axis(str(record["axis"]))
        columns = ("at_utc", "who", "subject", "sides_json", *FACT_IDS.split(", "))
        with self._transaction() as db:
            if db.execute("SELECT 1 FROM conflict WHERE uid = ?", (record["uid"],)).fetchone():
                return
            db.execute(
                f"INSERT INTO conflict (axis_id, {', '.join(columns)})"
                f" VALUES (?, {', '.join('?' * len(columns))})",
                (axis.id, *(record[c] for c in columns)),
            )

    def resolve_conflict(
        self, ref: str, keep: int, who: str = "", note: str = "", at_utc: str | None = None
    ) -> Resolution:
        """Settles a conflict by keeping side ``keep`` (1, 2, as :meth:`Conflict.lines` numbers
        them): a new fact naming the conflict; a kept origin or axis field is recorded again for
        the axis (its history says it settles the conflict), kept parameter values are the axis's
        latest known values from now on."""
        found = self.conflict(ref)
        if not found.open and found.resolutions:
            last = found.resolutions[-1]
            by = f" by {last.who}" if last.who else ""
            raise RegisterError(
                f"conflict {found.short} was settled{by} at {words.when_text(last.at_utc)} UTC"
                f" (kept {last.kept})"
            )
        if isinstance(keep, bool) or not isinstance(keep, int) or not 1 <= keep <= len(found.sides):
            raise RegisterError(
                f"conflict {found.short}: keep one of its sides, 1 to {len(found.sides)} "
                f"(not {names.quoted(str(keep), 20)})"
            )
        try:
            names.check_name(who, "operator", names.TEXT_MAX, empty_ok=True)
        except names.NameProblem as exc:
            raise RegisterError(str(exc)) from None
        side = found.sides[keep - 1]
        settled = {k: _clean(asdict(v)) for k, v in side.values.items()}
        now = utc_stamp(at_utc)
        with self._transaction() as db:
            ids = self._fact_ids()
            cursor = db.execute(
                "INSERT INTO conflict_resolution (conflict_uid, axis_id, at_utc, who, kept, settled_json,"
                f" note, {FACT_IDS}) VALUES (?, ?, ?, ?, ?, ?, ?, {FACT_ID_MARKS})",
                (
                    found.uid,
                    found.axis.id,
                    now,
                    who,
                    keep,
                    json.dumps(settled, ensure_ascii=False),
                    note,
                    *ids,
                ),
            )
            tag = f" (settles conflict {found.short})"
            if found.subject == "origin" and "origin" in side.values:
                text = str(side.values["origin"].value)
                self._axis_event(
                    found.axis.id,
                    now,
                    who,
                    f"{ORIGIN_PREFIX}{text}{tag}",
                    {"origin": text, "settles": found.uid},
                )
            elif found.subject == "axis":
                current = self.axis(found.axis.id)
                for key, held in side.values.items():
                    if key not in COMPARED_FIELDS:
                        continue
                    db.execute(f"UPDATE axis SET {key} = ? WHERE id = ?", (held.value, found.axis.id))
                    old = SideValue(getattr(current, key))
                    self._axis_event(
                        found.axis.id,
                        now,
                        who,
                        f"{FIELD_WORDS[key]}: {value_words('axis', key, old)} → "
                        f"{value_words('axis', key, held)}{tag}",
                        {"field": key, "old": old.value, "new": held.value, "settles": found.uid},
                    )
        return Resolution(ids[0], now, who, keep, note, ids[1], settled, int(cursor.lastrowid or 0))


def _sides(text: str) -> tuple[ConflictSide, ...]:
    try:
        raw = json.loads(text)
    except ValueError:
        return ()
    out = []
    for side in raw if isinstance(raw, list) else []:
        values = {
            str(k): SideValue(**{f: v.get(f) for f in SideValue.__dataclass_fields__ if f in v})
            for k, v in dict(side.get("values", {})).items()
        }
        out.append(ConflictSide(str(side.get("register_id", "")), str(side.get("register", "")), values))
    return tuple(out)


def sides_json(sides: Iterable[ConflictSide]) -> str:
    return json.dumps([s.as_dict() for s in sides], ensure_ascii=False, sort_keys=True)
