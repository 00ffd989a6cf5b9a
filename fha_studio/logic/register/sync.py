"""Syncing two registers (no Qt): a laptop's file and the plant's server, or any two, come to hold
the same facts, each once. Callable from any thread (the GUI's worker): :func:`sync_registers`.

A sync, in this order:

1. the registers each knows of (their ids and names), the machines (one machine per name) and
   the axes: an axis is the same axis in both when its machine's name and its own name are the
   same (an axis renamed in one register is found by its former name), made where it is missing;
   a field of an axis given in one and not in the other is filled in (a change in its history);
2. the signing keys, their revocations and the signatures (each known by an id of its own);
3. the facts: per axis (and per machine for its own reports) and per table, each register's count
   of facts and sum of their ``uid_hash``; where those differ, the facts' stable ids say which
   facts one register lacks (:mod:`.identity`);
4. before any fact moves: what the two disagree on, for an axis both changed while they were
   apart, recorded in both as conflicts (:mod:`.conflicts`), nothing picked (a value one side
   changed after the other last recorded the value both held is a later change:
   :func:`.conflicts.changed_apart`);
5. the facts each lacks, in batches, each batch one transaction on the register it goes to (all
   the facts of an axis both changed in one batch, so that a sync stopped in the middle and run
   again finds the same conflicts, or none, never half of them). A fact is known by its stable id,
   so a sync run twice, or stopped anywhere and run again, leaves each fact there once.

An axis entry that set a field (an axis added, a field changed) sets it in the register it goes
to too, the newest such entry counting (the port is each computer's own: it is only filled in
where none is given).

A sync that only sends (``send_only``: the GUI's queue for a server delivers so) moves facts,
machines, axes and keys from the source to the target and nothing back: a window on a plant's
register of years of facts does not copy them to this computer. It compares only what the source
has (per group and per register a fact was recorded in), so it costs what the source holds, not
what the target holds. What the two disagree on is found as in a sync both ways, with the
target's facts that came while they were apart: for an axis and a table, those that reached the
target after the last of the source's own facts there (the target's row ids say the order); where
the source has sent none of that table yet, those recorded no earlier than the source's first
fact being sent (what the target knew before is the history the source's facts add to, not a
side of a conflict).
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from fha_studio.logic.register import guard
from fha_studio.logic.register.axes import ORIGIN_PREFIX
from fha_studio.logic.register.conflicts import (
    COMPARED_FIELDS,
    Conflict,
    ConflictSide,
    SideValue,
    changed_apart,
    conflict_uid,
    disagreement,
    field_settings,
    latest_origin,
    latest_parameters,
    sides_json,
)
from fha_studio.logic.register.connection import FACT_IDS
from fha_studio.logic.register.guard import RegisterError
from fha_studio.logic.register.identity import BATCH_FACTS, UID_TABLES, uid_hash
from fha_studio.logic.register.records import utc_stamp
from fha_studio.logic.register.store import Register

__all__ = ["BATCH_FACTS", "SyncProgress", "SyncResult", "sync_registers"]

#: Ids in one ``IN (...)``.
_IN_LIST = 500
#: The facts that say what an axis holds (a conflict is about them).
_STATE_TABLES = ("snapshot", "parameter_write", "axis_event", "conflict_resolution")
#: The facts known by an id of their own, in the order they go (a key before what names it).
_KEYED_TABLES = (("signing_key", "key_id"), ("key_revocation", "key_id"), ("report_signature", "signature"))
_AXIS_SELECT = "SELECT axis.*, machine.name AS machine FROM axis JOIN machine ON machine.id = axis.machine_id"
_AXIS_COLUMNS = (
    "name",
    "actuator_code",
    "driver_model",
    "port_url",
    "load_inertia_kgm2",
    "notes",
    "serial_number",
    "created_utc",
)

#: A group of facts compared as one: ("a", axis id in the source) or ("m", machine name) for a
#: machine's own reports.
GroupKey = tuple[str, Any]


@dataclass(frozen=True)
class SyncProgress:
    """How far a sync is: ``done`` of ``total`` facts moved, in ``batches`` transactions."""

    stage: str  # "comparing", "conflicts", "sending", "receiving", "done"
    done: int
    total: int
    batches: int


@dataclass(frozen=True)
class SyncResult:
    """What a sync did (``fha-studio register sync --json`` prints :meth:`as_dict`)."""

    source: str
    target: str
    sent: int  # facts the target lacked, now there
    received: int  # facts the source lacked, now there
    already_there: int  # facts both had
    conflicts: tuple[Conflict, ...]  # the open conflicts of the registers after the sync
    found_now: frozenset[str] = field(default=frozenset())  # the uids of those this sync found
    machines_added: int = 0
    axes_added: int = 0
    batches: int = 0

    def as_dict(self) -> dict[str, Any]:
        return {
            "source": self.source,
            "target": self.target,
            "sent": self.sent,
            "received": self.received,
            "already_there": self.already_there,
            "machines_added": self.machines_added,
            "axes_added": self.axes_added,
            "conflicts": [{**c.as_dict(), "found_now": c.uid in self.found_now} for c in self.conflicts],
        }


Progress = Callable[[SyncProgress], None]


def sync_registers(
    source: Register | str | Path,
    target: Register | str | Path,
    progress: Progress | None = None,
    who: str = "",
    batch_facts: int = BATCH_FACTS,
    send_only: bool = False,
) -> SyncResult:
    """Brings ``source`` and ``target`` (registers, or where they are: a file or a
    ``postgresql://`` URL; a missing target file is made) to the same facts, both ways; with
    ``send_only`` the target to every fact of the source, and nothing back into the source but
    the conflicts found. ``progress`` hears each committed batch (an exception it raises stops the
    sync there: what was committed stays). ``who`` is who runs it (the conflicts it finds, the
    fields it fills say so). Raises RegisterError, one line: a register that cannot be opened, a
    server gone in the middle (what was moved before is kept; run it again)."""
    opened: list[Register] = []
    try:
        s = source if isinstance(source, Register) else _opened(opened, source, create=False)
        t = target if isinstance(target, Register) else _opened(opened, target, create=True)
        job = _Sync(_Side(s), _Side(t), progress, who, max(1, int(batch_facts)), send_only)
        try:
            return job.run()
        except RegisterError as exc:
            if job.done:  # a server away stays one (a window tries again later)
                raise type(exc)(
                    f"{exc} (the sync had moved {job.done} of {job.total} facts: they are "
                    "kept; run it again to finish)"
                ) from None
            raise
    finally:
        for reg in opened:
            with contextlib.suppress(Exception):
                reg.close()


def _opened(opened: list[Register], where: str | Path, create: bool) -> Register:
    reg = Register(where, create=create)
    opened.append(reg)
    return reg


class _Side:
    """One of the two registers of a sync, with the SQL it is asked."""

    def __init__(self, reg: Register):
        if reg.read_only:
            raise RegisterError(
                f"the register {guard.shown_path(reg.path)} is open for questions only: "
                "a sync writes into both registers"
            )
        self.reg, self.db, self.server = reg, reg._db, bool(reg._url)
        with self.speaking():
            self.id = reg.register_id
            row = self.db.execute(
                "SELECT name FROM known_register WHERE register_id = ?", (self.id,)
            ).fetchone()
        self.name = str(row[0]) if row and row[0] else str(reg.path)
        self.shown = guard.shown_path(reg.path)
        self.machines: dict[str, int] = {}  # name -> id
        self.axes: dict[int, dict[str, Any]] = {}  # id -> row

    @contextlib.contextmanager
    def speaking(self) -> Iterator[None]:
        """The store's errors as one line naming this register."""
        try:
            yield
        except Exception as exc:
            if guard.is_db_error(exc):
                raise self.reg._problem(exc) from None
            raise

    def rows(self, sql: str, args: Sequence[Any] = ()) -> list[dict[str, Any]]:
        with self.speaking():
            found = self.db.execute(sql, tuple(args)).fetchall()
        if not found:
            return []
        names = found[0].keys()  # once: a row's keys() is a new list each time
        return [dict(zip(names, r, strict=True)) for r in found]

    def rows_in(self, sql: str, values: Sequence[Any], args: Sequence[Any] = ()) -> list[dict[str, Any]]:
        """``sql`` with ``{}`` for an ``IN`` list, over ``values`` in parts."""
        out: list[dict[str, Any]] = []
        for start in range(0, len(values), _IN_LIST):
            part = list(values[start : start + _IN_LIST])
            out.extend(self.rows(sql.format(", ".join("?" * len(part))), [*args, *part]))
        return out

    def execute(self, sql: str, args: Sequence[Any] = ()) -> None:
        with self.speaking():
            self.db.execute(sql, tuple(args))

    def insert(self, table: str, columns: Sequence[str], rows: Sequence[Sequence[Any]]) -> int:
        """Rows not there yet (by their keys); how many were new."""
        if not rows:
            return 0
        with self.speaking():
            if self.server:
                return int(self.db.insert_rows(table, columns, rows))
            before = self.db.total_changes
            self.db.executemany(
                f"INSERT OR IGNORE INTO {table} ({', '.join(columns)})"
                f" VALUES ({', '.join('?' * len(columns))})",
                [tuple(r) for r in rows],
            )
            return int(self.db.total_changes - before)

    def prepare_inserts(self) -> None:
        """On a server: the temporary tables the facts are copied through, made once."""
        if self.server:
            with self.speaking():
                tables = (*UID_TABLES, "snapshot_value")
                self.db.prepare_inserts({t: [c for c in self.db.columns(t) if c not in ("id", "rowid")]
                                         for t in tables})

    def transaction(self) -> contextlib.AbstractContextManager[Any]:
        return self.reg._transaction()

    def read_entities(self) -> None:
        self.machines = {r["name"]: int(r["id"]) for r in self.rows("SELECT id, name FROM machine")}
        self.axes = {int(r["id"]): r for r in self.rows(_AXIS_SELECT)}


@dataclass
class _Plan:
    """What moves: per group and table, the uids the target lacks and those the source lacks;
    and the target's facts that came while the two were apart (what a conflict is found among:
    in a sync both ways, what the source lacks)."""

    send: dict[GroupKey, dict[str, list[str]]] = field(default_factory=dict)
    receive: dict[GroupKey, dict[str, list[str]]] = field(default_factory=dict)
    theirs: dict[GroupKey, dict[str, list[str]]] = field(default_factory=dict)


class _Sync:
    def __init__(
        self, s: _Side, t: _Side, progress: Progress | None, who: str, batch_facts: int,
        send_only: bool = False,
    ):
        if s.id == t.id:
            raise RegisterError(
                f"{s.shown} and {t.shown} are one register (the same id: one is a copy of the "
                "other, which is no register of its own); sync the one with a new file instead"
            )
        self.s, self.t, self.progress, self.who, self.batch_facts = s, t, progress, who, batch_facts
        self.send_only = send_only
        #: the directions things move in: (from, to)
        self.ways = ((s, t),) if send_only else ((s, t), (t, s))
        self.pairs: dict[int, int] = {}  # source axis id -> target axis id
        self.back: dict[int, int] = {}  # target axis id -> source axis id
        self.machine_names: dict[_Side, dict[int, str]] = {}
        self._both_changed: frozenset[GroupKey] = frozenset()  # axes both registers changed
        self.sent = self.received = self.already = 0
        self.machines_added = self.axes_added = 0
        self.done = self.total = self.batches = 0

    # -- the steps ---------------------------------------------------------------------------------
    def run(self) -> SyncResult:
        self._tell("comparing")
        self._registers()
        self._machines()
        self._axes()
        self._keys()
        plan = self._compare_sent() if self.send_only else self._compare()
        self.total += sum(
            len(u) for side in (plan.send, plan.receive) for g in side.values() for u in g.values()
        )
        self._tell("conflicts")
        found = self._conflicts(plan)
        self._move(plan.send, self.s, self.t, "sending")
        self._move(plan.receive, self.t, self.s, "receiving")
        self._tell("done")
        open_now = tuple(self.t.reg.conflicts(open_only=True))
        return SyncResult(
            self.s.shown,
            self.t.shown,
            self.sent,
            self.received,
            self.already,
            open_now,
            frozenset(found),
            self.machines_added,
            self.axes_added,
            self.batches,
        )

    def _tell(self, stage: str) -> None:
        if self.progress is not None:
            self.progress(SyncProgress(stage, self.done, self.total, self.batches))

    def _registers(self) -> None:
        """Each register learns the ids and names of the registers the other knows."""
        known = {
            side: {r["register_id"]: r for r in side.rows("SELECT * FROM known_register")}
            for side in (self.s, self.t)
        }
        for src, dst in ((self.s, self.t), (self.t, self.s)):
            missing = [r for k, r in known[src].items() if k not in known[dst]]
            if missing:
                with dst.transaction():
                    dst.insert(
                        "known_register",
                        ("register_id", "name", "created_utc"),
                        [(r["register_id"], r["name"], r["created_utc"]) for r in missing],
                    )

    def _machines(self) -> None:
        """One machine per name, in both."""
        for side in (self.s, self.t):
            side.read_entities()
        for src, dst in self.ways:
            missing = sorted(set(src.machines) - set(dst.machines))
            if not missing:
                continue
            rows = src.rows_in(
                "SELECT name, site, notes, created_utc FROM machine WHERE name IN ({})", missing
            )
            with dst.transaction():
                self.machines_added += dst.insert(
                    "machine",
                    ("name", "site", "notes", "created_utc"),
                    [(r["name"], r["site"], r["notes"], r["created_utc"]) for r in rows],
                )
            dst.read_entities()

    def _axes(self) -> None:
        """One axis per machine name and axis name (or a former name of it), in both; the fields
        one lacks filled in from the other."""

        def by_name(side: _Side) -> dict[tuple[str, str], int]:
            return {(r["machine"], r["name"]): i for i, r in side.axes.items()}

        names_s, names_t = by_name(self.s), by_name(self.t)
        pairs = {i: names_t[k] for k, i in names_s.items() if k in names_t}
        # an axis renamed in one register is known by its former name in the other (sending
        # only: the target's axes the source has under a former name, not every other one)
        for i, j in self._renamed(self.s, names_t, set(pairs.values()), set(pairs)):
            pairs[i] = j
        unpaired_s = {k: i for k, i in names_s.items() if i not in pairs}
        for j, i in self._renamed(self.t, unpaired_s if self.send_only else names_s, set(pairs),
                                  set(pairs.values())):
            pairs[i] = j
        self.pairs = pairs
        paired_t = set(pairs.values())
        self._add_axes(self.s, self.t, [r for i, r in self.s.axes.items() if i not in self.pairs])
        if not self.send_only:
            self._add_axes(self.t, self.s, [r for j, r in self.t.axes.items() if j not in paired_t])
        names_s, names_t = by_name(self.s), by_name(self.t)
        self.pairs.update({i: names_t[k] for k, i in names_s.items() if k in names_t and i not in self.pairs})
        for i, j in self.pairs.items():
            if not self.send_only:
                self._fill(self.s, i, self.t.axes[j])
            self._fill(self.t, j, self.s.axes[i])

    def _renamed(
        self, side: _Side, others: Mapping[tuple[str, str], int], taken: set[int], mine: set[int]
    ) -> Iterator[tuple[int, int]]:
        """(axis of ``side``, axis of the other register) for each axis of ``side`` not paired
        yet whose former name the other register's axis still has."""
        machines = {m for m, _ in others}
        for i, r in side.axes.items():
            if i in mine or (r["machine"], r["name"]) in others or r["machine"] not in machines:
                continue
            for old in self._former_names(side, i):
                j = others.get((r["machine"], old))
                if j is not None and j not in taken:
                    taken.add(j)
                    yield i, j
                    break

    def _former_names(self, side: _Side, axis_id: int) -> list[str]:
        rows = side.rows(
            "SELECT data FROM axis_event WHERE axis_id = ? AND data LIKE ? ORDER BY at_utc DESC",
            (axis_id, '%"field": "name"%'),
        )
        out = []
        for r in rows:
            with contextlib.suppress(ValueError, TypeError, KeyError):
                out.append(str(json.loads(r["data"])["old"]))
        return out

    def _add_axes(self, src: _Side, dst: _Side, rows: list[dict[str, Any]]) -> None:
        if not rows:
            return
        with dst.transaction():
            self.axes_added += dst.insert(
                "axis",
                ("machine_id", *_AXIS_COLUMNS),
                [(dst.machines[r["machine"]], *(r[c] for c in _AXIS_COLUMNS)) for r in rows],
            )
        dst.read_entities()

    def _fill(self, side: _Side, axis_id: int, other: Mapping[str, Any]) -> None:
        """The fields the axis lacks in ``side`` that the other register gives (the port aside)."""
        mine = side.axes[axis_id]
        given = {f: other[f] for f in COMPARED_FIELDS if mine[f] in (None, "") and other[f] not in (None, "")}
        if given:
            side.reg.update_axis(axis_id, who=self.who, **given)
            side.axes[axis_id] = side.rows(f"{_AXIS_SELECT} WHERE axis.id = ?", (axis_id,))[0]

    def _keys(self) -> None:
        """Signing keys, revocations and signatures: each known by an id of its own."""
        def held(side: _Side, table: str, key: str, only: list[str] | None = None) -> dict[str, Any]:
            if only is None:
                return {r[key]: r for r in side.rows(f"SELECT * FROM {table}")}
            return {r[key]: r for r in side.rows_in(f"SELECT * FROM {table} WHERE {key} IN ({{}})", only)}

        rows = {self.s: {t: held(self.s, t, k) for t, k in _KEYED_TABLES}}
        # sending only: of the target's, those the source has
        rows[self.t] = {
            t: held(self.t, t, k, list(rows[self.s][t]) if self.send_only else None) for t, k in _KEYED_TABLES
        }
        for src, dst in self.ways:
            moving = {
                t: [r for k, r in rows[src][t].items() if k not in rows[dst][t]] for t, _ in _KEYED_TABLES
            }
            if not any(moving.values()):
                continue
            with dst.transaction():
                for table, _ in _KEYED_TABLES:
                    if moving[table]:
                        columns = list(moving[table][0])
                        added = dst.insert(table, columns, [[r[c] for c in columns] for r in moving[table]])
                        self._count(src, added, len(moving[table]))
        self.already += sum(len(rows[self.s][t].keys() & rows[self.t][t].keys()) for t, _ in _KEYED_TABLES)

    def _count(self, src: _Side, added: int, tried: int) -> None:
        if src is self.s:
            self.sent += added
        else:
            self.received += added
        self.already += tried - added  # there by now (another sync, or the same answer recorded twice)

    # -- what differs ------------------------------------------------------------------------------------
    def _group(self, side: _Side, value: int) -> GroupKey:
        if value < 0:
            return ("m", self.machine_names[side][-value])
        return ("a", value if side is self.s else self.back[value])

    def _compare(self) -> _Plan:
        plan = _Plan()
        self.back = {j: i for i, j in self.pairs.items()}
        self.machine_names = {side: {i: n for n, i in side.machines.items()} for side in (self.s, self.t)}
        for table in UID_TABLES:
            g = "COALESCE(axis_id, -machine_id)" if table == "report" else "axis_id"
            sums = {}
            for side in (self.s, self.t):
                sums[side] = {
                    self._group(side, int(r["g"])): (int(r["n"]), int(r["h"] or 0))
                    for r in side.rows(
                        f"SELECT {g} AS g, COUNT(*) AS n, SUM(uid_hash) AS h FROM {table} GROUP BY {g}"
                    )
                }
            differ = [
                k
                for k in sums[self.s].keys() | sums[self.t].keys()
                if sums[self.s].get(k) != sums[self.t].get(k)
            ]
            self.already += sum(n for k, (n, _) in sums[self.s].items() if k not in differ)
            if not differ:
                continue
            uids = {side: self._uids(side, table, g, differ, len(sums[side])) for side in (self.s, self.t)}
            for key in differ:
                mine, theirs = uids[self.s].get(key, {}), uids[self.t].get(key, {})
                send = sorted((u for u in mine if u not in theirs), key=mine.__getitem__)
                receive = sorted((u for u in theirs if u not in mine), key=theirs.__getitem__)
                self.already += len(mine) - len(send)
                if send:
                    plan.send.setdefault(key, {})[table] = send
                if receive:
                    plan.receive.setdefault(key, {})[table] = receive
        plan.theirs = plan.receive
        return plan

    def _compare_sent(self) -> _Plan:
        """What the target lacks of the source's facts, by each group's count and ``uid_hash``
        sum per register the facts were recorded in (the target's rows of the source's groups
        only); then the target's facts that came while they were apart, for the axes the source
        changed."""
        plan = _Plan()
        self.back = {j: i for i, j in self.pairs.items()}
        self.machine_names = {side: {i: n for n, i in side.machines.items()} for side in (self.s, self.t)}
        for table in UID_TABLES:
            g = "COALESCE(axis_id, -machine_id)" if table == "report" else "axis_id"
            sql = f"SELECT {g} AS g, recorded_in, COUNT(*) AS n, SUM(uid_hash) AS h FROM {table}"
            group_by = f" GROUP BY {g}, recorded_in"
            mine = {
                (self._group(self.s, int(r["g"])), r["recorded_in"]): (int(r["n"]), int(r["h"] or 0))
                for r in self.s.rows(sql + group_by)
            }
            if not mine:
                continue
            there = {self._there(key) for key, _ in mine}
            there.discard(None)
            theirs = {
                (self._group(self.t, int(r["g"])), r["recorded_in"]): (int(r["n"]), int(r["h"] or 0))
                for r in self.t.rows_in(sql + f" WHERE {g} IN ({{}})" + group_by, sorted(there))
            }
            differ = {key for key in mine if theirs.get(key) != mine[key]}
            self.already += sum(n for key, (n, _) in mine.items() if key not in differ)
            for group, origin in sorted(differ, key=str):
                one = f"SELECT uid, id FROM {table} WHERE {g} = ? AND recorded_in = ?"
                held = self.s.rows(one, (self._here(group), origin))
                target_group = self._there(group)
                there_now = [] if target_group is None else self.t.rows(one, (target_group, origin))
                got = {r["uid"] for r in there_now}
                send = [r["uid"] for r in sorted(held, key=lambda r: int(r["id"])) if r["uid"] not in got]
                self.already += len(held) - len(send)
                if send:
                    plan.send.setdefault(group, {}).setdefault(table, []).extend(send)
        for key in plan.send:
            if key[0] == "a" and key[1] in self.pairs and any(plan.send[key].get(t) for t in _STATE_TABLES):
                came = self._came_meanwhile(key, plan.send[key])
                if came:
                    plan.theirs[key] = came
        return plan

    def _here(self, key: GroupKey) -> int:
        """The group's value (an axis id, or minus a machine id) in the source."""
        return int(key[1]) if key[0] == "a" else -self.s.machines[key[1]]

    def _there(self, key: GroupKey) -> int | None:
        """The group's value in the target (None: the target has no such axis or machine yet)."""
        if key[0] == "a":
            return self.pairs.get(key[1])
        machine = self.t.machines.get(key[1])
        return None if machine is None else -machine

    def _came_meanwhile(self, key: GroupKey, sent: Mapping[str, list[str]]) -> dict[str, list[str]]:
        """Of an axis the source changed, the target's facts (state tables) that came while the
        two were apart: after the last of the source's own facts there, table by table (the
        target's row ids say the order); with none there yet, those recorded no earlier than the
        first fact the source sends now."""
        axis_t = self.pairs[key[1]]
        first = min(
            (r["recorded_utc"] for t, uids in sent.items() if t in _STATE_TABLES
             for r in self.s.rows_in(f"SELECT recorded_utc FROM {t} WHERE uid IN ({{}})", uids)),
            default="",
        )
        came: dict[str, list[str]] = {}
        for table in _STATE_TABLES:
            others = f"SELECT uid, id FROM {table} WHERE axis_id = ? AND recorded_in != ?"
            last = self.t.rows(
                f"SELECT MAX(id) AS last FROM {table} WHERE axis_id = ? AND recorded_in = ?",
                (axis_t, self.s.id),
            )
            mark = last[0]["last"] if last else None
            if mark is not None:
                rows = self.t.rows(others + " AND id > ?", (axis_t, self.s.id, int(mark)))
            else:
                rows = self.t.rows(others + " AND recorded_utc >= ?", (axis_t, self.s.id, first))
            if not rows:
                continue
            uids = [r["uid"] for r in rows]
            known = {r["uid"] for r in self.s.rows_in(f"SELECT uid FROM {table} WHERE uid IN ({{}})", uids)}
            fresh = [r["uid"] for r in sorted(rows, key=lambda r: int(r["id"])) if r["uid"] not in known]
            if fresh:
                came[table] = fresh
        return came

    def _uids(
        self, side: _Side, table: str, g: str, keys: list[GroupKey], groups: int
    ) -> dict[GroupKey, dict[str, int]]:
        """{group: {uid: row id}} of the groups ``keys`` in ``side``."""
        if side is self.s:
            values = [
                k[1] if k[0] == "a" else -side.machines[k[1]]
                for k in keys
                if k[0] == "a" or k[1] in side.machines
            ]
        else:
            values = [
                self.pairs[k[1]] if k[0] == "a" else -side.machines[k[1]]
                for k in keys
                if (k[0] == "a" and k[1] in self.pairs) or k[1] in side.machines
            ]
        if len(values) * 2 > groups:  # most of the table: one read of it
            rows = side.rows(f"SELECT {g} AS g, uid, id FROM {table}")
        else:
            rows = side.rows_in(f"SELECT {g} AS g, uid, id FROM {table} WHERE {g} IN ({{}})", values)
        out: dict[GroupKey, dict[str, int]] = {}
        wanted = set(keys)
        for r in rows:
            key = self._group(side, int(r["g"]))
            if key in wanted:
                out.setdefault(key, {})[r["uid"]] = int(r["id"])
        return out

    # -- conflicts ------------------------------------------------------------------------------------------
    def _conflicts(self, plan: _Plan) -> set[str]:
        """The conflicts of the axes both registers changed while apart, recorded in both before
        any fact moves; their uids."""
        found: list[tuple[int, str, tuple[ConflictSide, ...]]] = []
        both_changed = set()
        for i, j in self.pairs.items():
            key: GroupKey = ("a", i)
            sent, got = plan.send.get(key, {}), plan.theirs.get(key, {})
            if any(sent.get(t) for t in _STATE_TABLES) and any(got.get(t) for t in _STATE_TABLES):
                both_changed.add(key)
                mine, theirs = self._state(self.s, sent), self._state(self.t, got)
                picked = {
                    subject: (pick(mine[subject]), pick(theirs[subject]))
                    for subject, pick in (("parameters", latest_parameters), ("origin", latest_origin))
                }
                if any(disagreement(a, b) for a, b in picked.values()):
                    before = self._held_before(i, sent, sorted(set(picked["parameters"][0])))
                    for subject, (a, b) in picked.items():
                        items = changed_apart(a, b, before[subject])
                        if items:
                            found.append(
                                (i, subject, self._sides({k: a[k] for k in items}, {k: b[k] for k in items}))
                            )
            fields = self._field_conflict(i, j, sent.get("axis_event", []), got.get("axis_event", []))
            if fields is not None:
                found.append((i, "axis", fields))
        self._both_changed = frozenset(both_changed)
        if not found:
            return set()
        now = utc_stamp()
        rows = []
        for i, subject, sides in found:
            uid = conflict_uid(f"{self.s.axes[i]['machine']}/{self.s.axes[i]['name']}", subject, sides)
            rows.append((i, subject, sides_json(sides), uid))
        # a conflict found again (its values unchanged, not settled yet) is the one already there
        known = {
            r["uid"]
            for side in (self.s, self.t)
            for r in side.rows_in("SELECT uid FROM conflict WHERE uid IN ({})", [r[-1] for r in rows])
        }
        for side in (self.s, self.t):
            with side.transaction():
                side.insert(
                    "conflict",
                    ("axis_id", "at_utc", "who", "subject", "sides_json", *FACT_IDS.split(", ")),
                    [
                        (
                            i if side is self.s else self.pairs[i],
                            now,
                            self.who,
                            subject,
                            text,
                            uid,
                            self.s.id,
                            now,
                            uid_hash(uid),
                        )
                        for i, subject, text, uid in rows
                    ],
                )
        return {uid for *_, uid in rows} - known

    def _sides(self, a: Mapping[str, SideValue], b: Mapping[str, SideValue]) -> tuple[ConflictSide, ...]:
        """The two sides, each value with the name of the register it was recorded in."""
        known = self.s.rows("SELECT register_id, name FROM known_register")
        names = {r["register_id"]: r["name"] for r in known}

        def named(values: Mapping[str, SideValue]) -> dict[str, SideValue]:
            return {k: replace(v, where=names.get(v.recorded_in, "")) for k, v in values.items()}

        sides = (ConflictSide(self.s.id, self.s.name, named(a)),
                 ConflictSide(self.t.id, self.t.name, named(b)))
        return tuple(sorted(sides, key=lambda x: x.register_id))

    def _state(self, side: _Side, new: Mapping[str, list[str]]) -> dict[str, list[dict[str, Any]]]:
        """What the new facts of a side say: parameter values, axis entries."""
        values = side.rows_in(f"{_SNAPSHOT_VALUES} WHERE s.uid IN ({{}})", new.get("snapshot", []))
        values += side.rows_in(f"{_WRITTEN_VALUES} AND uid IN ({{}})", new.get("parameter_write", []))
        values += _settled_values(
            side.rows_in(f"{_SETTLEMENTS} AND r.uid IN ({{}})", new.get("conflict_resolution", []))
        )
        entries = side.rows_in(f"{_AXIS_ENTRIES} WHERE uid IN ({{}})", new.get("axis_event", []))
        return {"parameters": values, "origin": entries}

    def _held_before(
        self, i: int, new: Mapping[str, list[str]], keys: list[str]
    ) -> dict[str, dict[str, SideValue]]:
        """What both registers held for the axis (``i`` in the source) before either's new facts:
        the latest of its facts both have (the source's facts but the ``new`` ones), parameters
        ``keys`` and the origin."""
        fresh = {uid for uids in new.values() for uid in uids}
        side = self.s
        values = side.rows_in(f"{_SNAPSHOT_VALUES} WHERE s.axis_id = ? AND v.key IN ({{}})", keys, (i,))
        values += side.rows_in(f"{_WRITTEN_VALUES} AND axis_id = ? AND key IN ({{}})", keys, (i,))
        values += _settled_values(side.rows(f"{_SETTLEMENTS} AND r.axis_id = ?", (i,)))
        entries = side.rows(f"{_AXIS_ENTRIES} WHERE axis_id = ? AND text LIKE ?", (i, f"{ORIGIN_PREFIX}%"))
        return {
            "parameters": latest_parameters(r for r in values if r["uid"] not in fresh),
            "origin": latest_origin(r for r in entries if r["uid"] not in fresh),
        }

    def _field_conflict(
        self, i: int, j: int, sent: list[str], got: list[str]
    ) -> tuple[ConflictSide, ...] | None:
        """The fields an axis holds differently in the two registers that neither side's new
        entries explain (a change in one register while the other kept the value it had)."""
        mine, theirs = self.s.axes[i], self.t.axes[j]
        differ = [
            f
            for f in COMPARED_FIELDS
            if mine[f] not in (None, "") and theirs[f] not in (None, "") and mine[f] != theirs[f]
        ]
        if not differ:
            return None
        sql = "SELECT uid, at_utc, who, recorded_in, data FROM axis_event WHERE axis_id = ? AND data != ''"
        every_s, every_t = self.s.rows(sql, (i,)), self.t.rows(sql, (j,))
        fresh_s = [r for r in every_s if r["uid"] in set(sent)]
        fresh_t = [r for r in every_t if r["uid"] in set(got)]
        new_s, new_t = field_settings(fresh_s), field_settings(fresh_t)
        held_s, held_t = field_settings(every_s), field_settings(every_t)
        settled_s, settled_t = _settled_fields(fresh_s), _settled_fields(fresh_t)
        items = []
        for f in differ:
            if f in new_s and f not in new_t and (
                f in settled_s or (f in held_t and held_t[f].value == theirs[f])
            ):
                continue  # changed (or settled by a person) in the source; the target kept what it had
            if f in new_t and f not in new_s and (
                f in settled_t or (f in held_s and held_s[f].value == mine[f])
            ):
                continue
            items.append(f)
        if not items:
            return None

        def side_values(row: Mapping[str, Any], held: Mapping[str, SideValue]) -> dict[str, SideValue]:
            return {
                f: held[f] if f in held and held[f].value == row[f] else SideValue(row[f], kind="axis")
                for f in items
            }

        return self._sides(side_values(mine, held_s), side_values(theirs, held_t))

    # -- moving facts ---------------------------------------------------------------------------------------
    def _move(self, moving: dict[GroupKey, dict[str, list[str]]], src: _Side, dst: _Side, stage: str) -> None:
        if moving:
            dst.prepare_inserts()
        for batch in self._batches(moving, src):
            tables: dict[str, list[str]] = {}
            for table, uids in batch:  # each table's facts of the batch in one insert
                tables.setdefault(table, []).extend(uids)
            with dst.transaction():
                touched: set[int] = set()
                for table in UID_TABLES:
                    if table in tables:
                        added = self._copy(src, dst, table, tables[table], touched)
                        self._count(src, added, len(tables[table]))
                for axis_id in touched:
                    self._apply_fields(dst, axis_id)
            self.done += sum(len(u) for _, u in batch)
            self.batches += 1
            self._tell(stage)

    def _batches(
        self, moving: dict[GroupKey, dict[str, list[str]]], src: _Side
    ) -> Iterator[list[tuple[str, list[str]]]]:
        """Batches of at most ``batch_facts`` facts (an axis both registers changed: all its facts
        in one), each table's facts in the order they were recorded."""
        both = {key for key in moving if key in self._both_changed}
        batch: list[tuple[str, list[str]]] = []
        size = 0
        for key in sorted(moving, key=str):
            if key in both:
                yield [(t, moving[key][t]) for t in UID_TABLES if t in moving[key]]
                continue
            for table in UID_TABLES:
                uids = moving[key].get(table, [])
                while uids:
                    room = self.batch_facts - size
                    batch.append((table, uids[:room]))
                    size += len(uids[:room])
                    uids = uids[room:]
                    if size >= self.batch_facts:
                        yield batch
                        batch, size = [], 0
        if batch:
            yield batch

    def _copy(self, src: _Side, dst: _Side, table: str, uids: list[str], touched: set[int]) -> int:
        rows = sorted(
            src.rows_in(f"SELECT * FROM {table} WHERE uid IN ({{}})", uids), key=lambda r: int(r["id"])
        )
        if not rows:
            return 0
        to_dst = self.pairs if src is self.s else {j: i for i, j in self.pairs.items()}
        columns = [c for c in rows[0] if c not in ("id", "rowid")]
        names = {i: n for n, i in src.machines.items()}
        plain: list[dict[str, Any]] = []
        corrections: list[dict[str, Any]] = []
        for r in rows:
            r = dict(r)
            if r.get("axis_id") is not None:
                r["axis_id"] = to_dst[int(r["axis_id"])]
                if table == "axis_event" and r["data"]:
                    touched.add(r["axis_id"])
            if "machine_id" in r:
                r["machine_id"] = dst.machines[names[int(r["machine_id"])]]
            (corrections if r.get("corrects") is not None else plain).append(r)
        added = dst.insert(table, columns, [[r[c] for c in columns] for r in plain])
        for r in corrections:  # the fact it corrects is there by now (recorded before it, same axis)
            corrected = src.rows(f"SELECT uid FROM {table} WHERE id = ?", (r["corrects"],))
            there = (
                dst.rows(f"SELECT id FROM {table} WHERE uid = ?", (corrected[0]["uid"],)) if corrected else []
            )
            r["corrects"] = int(there[0]["id"]) if there else None
            added += dst.insert(table, columns, [[r[c] for c in columns]])
        if table == "snapshot":
            self._copy_values(src, dst, rows)
        return added

    def _copy_values(self, src: _Side, dst: _Side, snapshots: list[dict[str, Any]]) -> None:
        ids = {int(r["id"]): r["uid"] for r in snapshots}
        there = {
            r["uid"]: int(r["id"])
            for r in dst.rows_in("SELECT uid, id FROM snapshot WHERE uid IN ({})", list(ids.values()))
        }
        values = src.rows_in(
            "SELECT snapshot_id, mode, number, key, value FROM snapshot_value WHERE snapshot_id IN ({})",
            list(ids),
        )
        dst.insert(
            "snapshot_value",
            ("snapshot_id", "mode", "number", "key", "value"),
            [
                (there[ids[int(v["snapshot_id"])]], v["mode"], v["number"], v["key"], v["value"])
                for v in values
            ],
        )

    def _apply_fields(self, side: _Side, axis_id: int) -> None:
        """The axis's fields as its newest entries set them (the port only where none is given;
        a name only when no other axis of the machine has it)."""
        row = side.rows(f"{_AXIS_SELECT} WHERE axis.id = ?", (axis_id,))[0]
        held = field_settings(
            side.rows(
                "SELECT uid, at_utc, who, recorded_in, data FROM axis_event WHERE axis_id = ? AND data != ''",
                (axis_id,),
            )
        )
        for key, value in held.items():
            if key not in (*COMPARED_FIELDS, "port_url", "name") or row[key] == value.value:
                continue
            if key == "port_url" and row[key]:
                continue
            if key == "name" and side.rows(
                "SELECT 1 FROM axis WHERE machine_id = ? AND name = ? AND id != ?",
                (row["machine_id"], value.value, axis_id),
            ):
                continue
            side.execute(f"UPDATE axis SET {key} = ? WHERE id = ?", (value.value, axis_id))


#: A parameter's values as a snapshot holds them, as a verified write leaves them, as a person
#: settled them (a conflict's kept side), for :func:`.conflicts.latest_parameters`; and the axis's
#: entries (the origin among them).
_SNAPSHOT_VALUES = (
    "SELECT s.uid, s.at_utc, s.who, s.recorded_in, 'snapshot' AS kind, v.mode, v.number, v.key, v.value"
    " FROM snapshot s JOIN snapshot_value v ON v.snapshot_id = s.id"
)
_WRITTEN_VALUES = (
    "SELECT uid, at_utc, who, recorded_in, 'write' AS kind, mode, number, key,"
    " COALESCE(read_back, new) AS value FROM parameter_write WHERE verified = 1"
)
_SETTLEMENTS = (
    "SELECT r.uid, r.at_utc, r.who, r.recorded_in, r.settled_json FROM conflict_resolution r"
    " JOIN conflict c ON c.uid = r.conflict_uid WHERE c.subject = 'parameters'"
)
_AXIS_ENTRIES = "SELECT uid, at_utc, who, recorded_in, text, data FROM axis_event"


def _settled_values(settlements: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The parameter values that settlements kept, as rows of values."""
    values = []
    for r in settlements:
        for key, held in _json(r["settled_json"]).items():
            if isinstance(held, dict) and isinstance(held.get("value"), int):
                values.append(
                    {
                        **r,
                        "kind": "settled",
                        "key": key,
                        "value": held["value"],
                        "mode": held.get("mode", ""),
                        "number": held.get("number", 0),
                    }
                )
    return values


def _settled_fields(entries: list[dict[str, Any]]) -> set[str]:
    """The fields that axis entries among ``entries`` set in settling a conflict."""
    return {str(d["field"]) for d in (_json(r["data"]) for r in entries) if d.get("settles") and "field" in d}


def _json(text: Any) -> dict[str, Any]:
    try:
        data = json.loads(text) if text else {}
    except ValueError:
        return {}
    return data if isinstance(data, dict) else {}
