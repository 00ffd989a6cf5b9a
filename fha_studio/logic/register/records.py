"""What the register holds and returns: machines, axes, parameter values and sets, history
events, open items; how it stamps a time and fingerprints a file; a check's name in words."""

from __future__ import annotations

import datetime as _dt
import hashlib
import sqlite3
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import Any

from fha_studio import clock, names
from fha_studio.logic.register.guard import RegisterError

SOURCES = ("link", "front_panel", "file")
#: Where a snapshot's values come from, as its history line says it.
SNAPSHOT_SOURCE_WORDS = {
    "link": "read over the link",
    "front_panel": "entered from the front panel",
    "file": "from a file",
}


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


class EventKind(StrEnum):
    """What a line of an axis's history is (the text is what exports and ``--json`` carry)."""

    AXIS = "axis"
    SNAPSHOT = "snapshot"
    WRITE = "write"
    CHECK = "check"
    ALARM = "alarm"
    REPORT = "report"
    RECORDING = "recording"
    MODEL_CHECK = "model_check"
    CONFLICT = "conflict"
    SETTLED = "settled"


#: A fact of each table a person may correct, as a correction names it ("snapshot 12").
CORRECTED_WORDS = {
    "axis_event": "axis entry",
    "snapshot": "snapshot",
    "parameter_write": "write",
    "check_result": "check",
    "alarm": "alarm",
    "report": "report",
    "recording": "recording",
    "model_check": "model check",
    "conflict": "conflict",
    "conflict_resolution": "settlement",
}
#: The table of each kind of history line.
KIND_TABLES = {
    EventKind.AXIS: "axis_event",
    EventKind.SNAPSHOT: "snapshot",
    EventKind.WRITE: "parameter_write",
    EventKind.CHECK: "check_result",
    EventKind.ALARM: "alarm",
    EventKind.REPORT: "report",
    EventKind.RECORDING: "recording",
    EventKind.MODEL_CHECK: "model_check",
    EventKind.CONFLICT: "conflict",
    EventKind.SETTLED: "conflict_resolution",
}


@dataclass(frozen=True)
class Event:
    """One line of an axis's history."""

    at_utc: str
    kind: EventKind
    who: str
    text: str  # for people
    ref: int | None = None  # the row (a snapshot's number is what `diff` takes)
    data: Mapping[str, Any] = field(default_factory=dict)
    uid: str = ""  # the fact's stable id, the same in every register it is synced to

    def as_dict(self) -> dict[str, Any]:
        return {**asdict(self), "kind": str(self.kind), "data": dict(self.data)}


@dataclass(frozen=True)
class OpenItem:
    """Something that keeps an axis from being done: an open check or an unsigned report."""

    axis: Axis
    kind: str  # "check", "report" or "conflict" (registers that disagree)
    text: str


@dataclass(frozen=True)
class Found:
    """An axis whose latest known value of a parameter matches."""

    axis: Axis
    value: ParameterValue


#: The checks recorded outside the procedures, by the page that makes them.
CHECK_SOURCES = {"dgr-checks": "DGR checks"}


def check_name(row: sqlite3.Row, titles: Mapping[str, str]) -> str:
    """A check as the checklist words it: "Receiving inspection: Actuator type label (3-1)" (the
    procedure's title and the step's text; their ids are for files)."""
    procedure_id = row["procedure_id"]
    procedure = titles.get(procedure_id) or CHECK_SOURCES.get(procedure_id, procedure_id)
    section = f" ({row['section']})" if row["section"] else ""
    return f"{procedure}: {row['text'] or row['step_id']}{section}"


def short_time(at_utc: str) -> str:
    """``2026-11-30 04:05:06`` (UTC) for people."""
    return at_utc[:19].replace("T", " ")
