"""The register's machines and their axes: added, changed (each change into the axis's history),
found by name; notes and the origin in an axis's history."""

from __future__ import annotations

import json
import math
import sqlite3
from collections.abc import Iterable
from typing import Any, ClassVar

from fha_studio import names
from fha_studio.logic.register import guard
from fha_studio.logic.register.connection import FACT_ID_MARKS, FACT_IDS, Connection
from fha_studio.logic.register.guard import RegisterError
from fha_studio.logic.register.records import CORRECTED_WORDS, Axis, Machine, utc_stamp

ORIGIN_PREFIX = "origin: "


@guard.in_words
class Axes(Connection):
    """Machines and axes."""

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
            added = {
                "actuator_code": actuator_code.strip().upper(),
                "driver_model": driver_model.strip(),
                "port_url": port_url.strip(),
                "load_inertia_kgm2": load_inertia_kgm2,
                "notes": notes,
                "serial_number": serial_number.strip(),
            }
            text = f"axis added: {what}" if what else "axis added"
            self._axis_event(int(cursor.lastrowid or 0), now, who, text, {"axis_added": added})
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
                self._axis_event(
                    current.id,
                    now,
                    who,
                    f"{self._AXIS_FIELDS[key]}: {_field_text(key, old)} → {_field_text(key, value)}",
                    {"field": key, "old": old, "new": value},
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
        self, axis: Axis | str | int, text: str, who: str = "", at_utc: str | None = None,
        corrects: int | None = None,
    ) -> int:
        """A note in the axis's history (``corrects``: the number of the axis entry of the same
        axis it corrects). Returns its number."""
        current = self.axis(axis)
        with self._transaction():
            return self._axis_event(current.id, utc_stamp(at_utc), who, f"note: {text}",
                                    corrects=self._corrected("axis_event", corrects, current))

    def _axis_event(
        self, axis_id: int, at_utc: str, who: str, text: str, data: dict[str, Any] | None = None,
        corrects: int | None = None,
    ) -> int:
        """A line of the axis's history (inside the caller's transaction); ``data`` says what it
        set, so that a register it is synced to sets the same (the fields of an axis added, a
        field changed, an origin). Returns its number."""
        cursor = self._db.execute(
            f"INSERT INTO axis_event (axis_id, at_utc, who, text, data, corrects, {FACT_IDS})"
            f" VALUES (?, ?, ?, ?, ?, ?, {FACT_ID_MARKS})",
            (axis_id, at_utc, who, text, json.dumps(data, ensure_ascii=False) if data else "", corrects,
             *self._fact_ids()),
        )
        return int(cursor.lastrowid or 0)

    def _corrected(
        self, table: str, ref: int | None, axis: Axis | None, machine_id: int | None = None
    ) -> int | None:
        """``ref``, the number of the fact of ``table`` a new fact corrects, when that fact is of
        the same axis (a machine's report: of the same machine); None for None."""
        if ref is None:
            return None
        word = CORRECTED_WORDS[table]
        if isinstance(ref, bool) or not isinstance(ref, int) or ref <= 0:
            raise RegisterError(f"{names.quoted(str(ref), 40)}: a correction names the number of the "
                                f"{word} it corrects")
        row = self._db.execute(f"SELECT * FROM {table} WHERE id = ?", (ref,)).fetchone()
        if row is None:
            raise RegisterError(f"there is no {word} number {ref} in the register to correct")
        same = row["axis_id"] == (axis.id if axis is not None else None)
        if table == "report" and machine_id is not None:
            same = same and row["machine_id"] == machine_id
        if not same:
            whose = axis.ref if axis is not None else "this machine"
            raise RegisterError(f"{word} {ref} is not one of {names.quoted(whose, 60)}'s: a correction "
                                f"is recorded for the axis of the fact it corrects")
        return ref

    def record_origin(
        self, axis: Axis | str | int, text: str, who: str = "", at_utc: str | None = None
    ) -> None:
        """Where the axis's origin was set and how, e.g. "multi-turn data cleared (OWW) at
        +0.00°" or "origin sensor at +1.25°" (goes into its history as "origin: ...")."""
        current = self.axis(axis)
        with self._transaction():
            self._axis_event(current.id, utc_stamp(at_utc), who, f"{ORIGIN_PREFIX}{text}", {"origin": text})

    def latest_origin(self, axis: Axis | str | int) -> dict[str, str] | None:
        """The latest origin recorded for the axis: {"text", "at_utc", "who"}; None when none was."""
        current = self.axis(axis)
        row = self._db.execute(
            "SELECT * FROM axis_event WHERE axis_id = ? AND text LIKE ?"
            " ORDER BY at_utc DESC, id DESC LIMIT 1",
            (current.id, f"{ORIGIN_PREFIX}%"),
        ).fetchone()
        if row is None:
            return None
        return {"text": row["text"][len(ORIGIN_PREFIX) :], "at_utc": row["at_utc"], "who": row["who"]}

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


def _field_text(key: str, value: Any) -> str:
    """An axis field's value for its history: "not given" for none, a load inertia with its unit."""
    if value in (None, ""):
        return "not given"
    if key == "load_inertia_kgm2":
        return f"{float(value):g} kg·m²"
    return str(value)
