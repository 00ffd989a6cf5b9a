"""Which event of a commissioning session becomes which register fact (no Qt).

An axis's link and pages report what happened: the parameters read, a verified write, an alarm,
values read off the front panel, a check of the DGR checks page, a report written, a recording
saved, a model check run. The functions here say what each is in the register: a snapshot, a
write, an alarm, a check with its verdict or a note without one, the axis's origin, a report with
its signature and open warnings. Each fact is a frozen dataclass with ``what`` (its name in the
line that says it was not recorded); :func:`record_fact` writes one into a :class:`Register`.
A machine window's own facts (the machine and its axes, the machine report) are a machine's, not
an axis's: :func:`record_machine_fact`.

The GUI's ``AxisRecorder`` only hears the events and hands what they carry to these functions;
the procedure session itself goes in through :func:`~fha_studio.logic.register.importers.record_session`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from copy import deepcopy
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fha_studio.hardware.parameters import ParameterModel, load_alarm_table
from fha_studio.logic.absolute import CHECK_TITLES, DgrCheckRecord
from fha_studio.logic.procedures.report import build_report
from fha_studio.logic.procedures.session import CheckRecord, ProcedureSession
from fha_studio.logic.register.importers import record_session
from fha_studio.logic.register.store import Register, RegisterError

#: A parameter of a snapshot as the register takes it: (mode, number, key, wire value).
ParameterRow = tuple[str, int, str, int]

#: The procedure the DGR checks page's checks are filed under.
DGR_PROCEDURE_ID = "dgr-checks"


@dataclass(frozen=True)
class AxisFact:
    """The axis the facts after it go to, added (with its machine) when the register lacks it:
    the single-axis window's axis, named by a person or by default. ``fields``: what a new axis is
    given (its actuator, its declared load); an axis already there gets those it lacks."""

    fields: tuple[tuple[str, Any], ...]
    who: str
    what: str = "axis"


@dataclass(frozen=True)
class ActuatorFact:
    """The actuator declared on the axis (the model code from its label)."""

    actuator_code: str
    who: str
    what: str = "actuator"


@dataclass(frozen=True, eq=False)
class SessionFact:
    """A procedure session as it stood when a step was answered: its checks, where each procedure
    stands, its parameter values (a copy, :func:`session_fact`: the page goes on with its own)."""

    session: ProcedureSession
    what: str = "procedure check"


@dataclass(frozen=True)
class DriverFact:
    """The driver the axis's drive says it is (its TYPE line)."""

    driver_model: str
    who: str
    what: str = "driver"


@dataclass(frozen=True)
class SnapshotFact:
    """Parameter values: read over the link (``source`` "link") or off the drive's front panel
    by a person ("front_panel")."""

    rows: tuple[ParameterRow, ...]
    source: str
    who: str
    at_utc: str | None = None
    driver_model: str = ""
    note: str = ""

    @property
    def what(self) -> str:
        return "parameter read" if self.source == "link" else "front-panel value"


@dataclass(frozen=True)
class WriteFact:
    """One parameter write and whether its read-back verified it."""

    mode: str
    number: int
    key: str
    new: int
    old: int | None
    read_back: int | None
    verified: bool
    error: str
    who: str
    what: str = "parameter write"


@dataclass(frozen=True)
class AlarmFact:
    """An alarm the drive raised, by its code and the manual's name."""

    code: int
    name: str
    who: str
    what: str = "alarm"


@dataclass(frozen=True, eq=False)
class CheckFact:
    """A check with its verdict: a procedure check's record, as a session holds one."""

    record: CheckRecord
    what: str = "check"


@dataclass(frozen=True)
class NoteFact:
    """A line in the axis's history (a check recorded without a verdict)."""

    text: str
    who: str
    at_utc: str | None = None
    what: str = "note"


@dataclass(frozen=True)
class OriginFact:
    """Where the axis's origin was set and how."""

    text: str
    who: str
    at_utc: str | None = None
    what: str = "origin"


@dataclass(frozen=True)
class ReportFact:
    """A report file written for the axis, with its signature and how many warnings it leaves open."""

    path: Path
    signed_by: str
    signed_utc: str
    open_warnings: int
    who: str
    what: str = "report"


@dataclass(frozen=True)
class RecordingFact:
    """A recording (``fha-recording/1``) saved on the axis."""

    path: Path
    summary: str
    who: str
    what: str = "recording"


@dataclass(frozen=True)
class ModelCheckFact:
    """A model check's summary and the recording it ran on."""

    summary: str
    recording_file: str
    who: str
    what: str = "model check"


@dataclass(frozen=True)
class SettlementFact:
    """A person's settlement of a conflict between registers (the register dialog): the side kept
    (1, 2, as the conflict numbers them) and why. ``conflict``: the conflict as the register it
    was read from holds it (``Register.conflict_record``), for a register that lacks it (this
    computer's queue for a server: the settlement goes there, and from there to the server)."""

    conflict_uid: str
    keep: int
    who: str
    note: str = ""
    conflict: tuple[tuple[str, Any], ...] = ()
    what: str = "settlement of a conflict"


def settlement_fact(
    conflict_uid: str, keep: int, who: str, note: str = "", record: Mapping[str, Any] | None = None
) -> SettlementFact:
    """A settlement of conflict ``conflict_uid``, with the conflict as the register it was read
    from holds it (``Register.conflict_record``: for a register that lacks it)."""
    return SettlementFact(conflict_uid, keep, who, note, tuple(sorted((record or {}).items())))


Fact = (
    AxisFact
    | ActuatorFact
    | SessionFact
    | DriverFact
    | SnapshotFact
    | WriteFact
    | AlarmFact
    | CheckFact
    | NoteFact
    | OriginFact
    | ReportFact
    | RecordingFact
    | ModelCheckFact
    | SettlementFact
)


@dataclass(frozen=True)
class MachineFact:
    """A machine and its axes as a machine window holds them (``MachineProject.to_json()``, a
    copy: recorded later, in another thread, it is unchanged): put into the register."""

    data: Mapping[str, Any]
    who: str
    what: str = "machine and its axes"


@dataclass(frozen=True)
class MachineReportFact:
    """A machine report file written (not signed itself: each axis's report is)."""

    machine: str
    path: Path
    open_warnings: int
    who: str
    what: str = "machine report"


MachineLevelFact = MachineFact | MachineReportFact


# -- events into facts -------------------------------------------------------------------------------
def axis_fact(fields: Mapping[str, Any], who: str) -> AxisFact:
    """The axis with what a new one is given (fields with no value are left out)."""
    return AxisFact(tuple((k, v) for k, v in fields.items() if v not in (None, "")), who)


def session_fact(session: ProcedureSession) -> SessionFact:
    """The session as it stands now, copied (recorded later, in another thread, it is unchanged)."""
    copy = deepcopy(session)
    copy.path = session.path
    return SessionFact(copy)


def parameter_key(model: ParameterModel, mode: str, number: int) -> str:
    """The item's key (``rotary_direction``), or ``<mode>_<number>`` for one the driver lacks."""
    try:
        return model.item(mode, number).key
    except (KeyError, ValueError):
        return f"{mode}_{number}"


def read_facts(
    model: ParameterModel, values: Mapping[tuple[str, int], int], who: str, driver_model: str = ""
) -> list[SnapshotFact]:
    """Values read over the link: one snapshot (none when nothing was read)."""
    rows = tuple(
        (str(mode), int(number), parameter_key(model, str(mode), int(number)), int(value))
        for (mode, number), value in values.items()
    )
    return [SnapshotFact(rows, "link", who, driver_model=driver_model)] if rows else []


def write_fact(model: ParameterModel, entry: Mapping[str, Any], who: str) -> WriteFact:
    """A write as the link reports it (``mode``, ``number``, ``new``, ``old``, ``read_back``,
    ``verified``, ``error``)."""
    mode, number = str(entry["mode"]), int(entry["number"])
    return WriteFact(
        mode,
        number,
        parameter_key(model, mode, number),
        int(entry["new"]),
        entry.get("old"),
        entry.get("read_back"),
        bool(entry.get("verified")),
        entry.get("error") or "",
        who,
    )


def alarm_facts(code: int, driver: str, who: str) -> list[AlarmFact]:
    """An alarm code the drive shows (0, no alarm, is no fact), named by the driver's table."""
    if code == 0:
        return []
    alarm = load_alarm_table(driver).get(code)
    return [AlarmFact(code, alarm.name if alarm is not None else "unknown code", who)]


def front_panel_facts(
    model: ParameterModel, entries: Iterable[Any], seen: set[tuple[str, int, int, str]]
) -> list[SnapshotFact]:
    """Values entered from the drive's front panel (objects with ``mode``, ``number``, ``value``,
    ``who``, ``time``): one snapshot per person and entry time. An entry in ``seen`` is left
    out; the ones taken are added to it, so an entry is recorded once."""
    groups: dict[tuple[str, str], list[ParameterRow]] = {}
    for entry in entries:
        mark = (entry.mode, entry.number, entry.value, entry.time)
        if mark in seen:
            continue
        seen.add(mark)
        groups.setdefault((entry.who, entry.time), []).append(
            (entry.mode, entry.number, parameter_key(model, entry.mode, entry.number), entry.value)
        )
    return [SnapshotFact(tuple(rows), "front_panel", who, at_utc=at) for (who, at), rows in groups.items()]


def facts_from_dgr_check(record: DgrCheckRecord) -> list[Fact]:
    """A check of the DGR checks page: a check with its verdict (a note when it has none); an
    absolute origin set with OWW, or the origin sensor's angle, as the axis's origin; parameter 8
    of a rotary-direction check as entered from the front panel."""
    title = CHECK_TITLES.get(record.check, record.check)
    by_hand = " (given by hand)" if record.by_hand else ""
    facts: list[Fact] = []
    if record.passed is None:
        facts.append(NoteFact(f"{title}{by_hand}: {record.detail}", record.who, record.at, what="check"))
    else:
        facts.append(
            CheckFact(CheckRecord(
                procedure_id=DGR_PROCEDURE_ID,
                step_id=record.check,
                kind="dgr",
                section="",
                text=title + by_hand,
                value=dict(record.values),
                expected="",
                unit="",
                passed=bool(record.passed),
                who=record.who,
                at_utc=record.at,
                detail=record.detail,
            ))
        )
    if record.check == "absolute_origin" and record.passed:
        where = record.values.get("position_deg")
        read_back = f", read back at {where:+.2f}°" if isinstance(where, float) else ""
        facts.append(OriginFact(f"absolute origin set (OWW){read_back}", record.who, record.at))
    if record.check == "sensor_dog" and record.passed and record.values.get("sensor") == "origin_sensor":
        angle = float(record.values["angle_deg"])
        facts.append(OriginFact(f"origin sensor at {angle:+.2f}° (4-7-2)", record.who, record.at))
    entered = record.values.get("rotary_direction") if record.check == "rotary_direction" else None
    if isinstance(entered, int) and not isinstance(entered, bool):
        facts.append(
            SnapshotFact(
                (("system", 8, "rotary_direction", entered),),
                "front_panel",
                record.who,
                at_utc=record.at,
                note="parameter 8 as read on the drive's front panel",
            )
        )
    return facts


def report_facts(
    session: ProcedureSession | None,
    context: Mapping[str, Any] | None,
    html: Path,
    pdf: Path | None,
    who: str,
) -> list[ReportFact]:
    """A commissioning report written: the PDF when there is one (the file that is handed over),
    else the HTML, with the session's signature and the warnings the report leaves open."""
    signature = session.signature if session is not None else {}
    warnings = len(build_report(session, context).warnings) if session is not None else 0
    path = pdf if pdf is not None else html
    return [
        ReportFact(
            Path(path), signature.get("who", ""), signature.get("at_utc", ""), warnings, who
        )
    ]


def model_check_facts(
    summary_lines: Sequence[str], recording_file: str | Path, who: str
) -> list[ModelCheckFact]:
    """A model check run: its first three summary lines, and the recording it ran on ("" when
    not known)."""
    summary = "; ".join(summary_lines[:3]) if summary_lines else "model check run"
    return [ModelCheckFact(summary, str(recording_file), who)]


# -- facts into the register ------------------------------------------------------------------------
def _axis(register: Register, axis: str, f: AxisFact) -> None:
    machine, name = axis.split("/", 1)
    register.ensure_axis(machine, name, who=f.who, **dict(f.fields))


def _actuator(register: Register, axis: str, f: ActuatorFact) -> None:
    register.update_axis(axis, who=f.who, actuator_code=f.actuator_code)


def _session(register: Register, axis: str, f: SessionFact) -> None:
    record_session(register, axis, f.session)


def _driver(register: Register, axis: str, f: DriverFact) -> None:
    register.update_axis(axis, who=f.who, driver_model=f.driver_model)


def _snapshot(register: Register, axis: str, f: SnapshotFact) -> None:
    register.record_snapshot(
        axis, f.rows, f.source, who=f.who, at_utc=f.at_utc, driver_model=f.driver_model, note=f.note
    )


def _write(register: Register, axis: str, f: WriteFact) -> None:
    register.record_write(
        axis, f.mode, f.number, f.key, f.new, f.old, f.read_back, f.verified, error=f.error, who=f.who
    )


def _alarm(register: Register, axis: str, f: AlarmFact) -> None:
    register.record_alarm(axis, f.code, f.name, who=f.who)


def _check(register: Register, axis: str, f: CheckFact) -> None:
    register.record_checks(axis, [f.record])


def _note(register: Register, axis: str, f: NoteFact) -> None:
    register.add_axis_note(axis, f.text, who=f.who, at_utc=f.at_utc)


def _origin(register: Register, axis: str, f: OriginFact) -> None:
    register.record_origin(axis, f.text, who=f.who, at_utc=f.at_utc)


def _report(register: Register, axis: str, f: ReportFact) -> None:
    register.record_report(
        f.path,
        axis=axis,
        signed_by=f.signed_by,
        signed_utc=f.signed_utc,
        open_warnings=f.open_warnings,
        who=f.who,
    )


def _recording(register: Register, axis: str, f: RecordingFact) -> None:
    register.record_recording(axis, f.path, f.summary, who=f.who)


def _model_check(register: Register, axis: str, f: ModelCheckFact) -> None:
    register.record_model_check(axis, f.summary, recording_file=f.recording_file, who=f.who)


def _settlement(register: Register, axis: str, f: SettlementFact) -> None:
    if f.conflict:
        register.take_conflict(dict(f.conflict))
    found = register.conflict(f.conflict_uid)
    if found.axis.ref != register.axis(axis).ref:
        raise RegisterError(f"conflict {found.short} is of {found.axis.ref}, not of {axis}")
    register.resolve_conflict(f.conflict_uid, f.keep, who=f.who, note=f.note)


#: How each kind of fact is written (``tests/register/test_facts_from_session.py`` checks every
#: kind has its row).
WRITERS: dict[type, Callable[[Register, str, Any], None]] = {
    AxisFact: _axis,
    ActuatorFact: _actuator,
    SessionFact: _session,
    DriverFact: _driver,
    SnapshotFact: _snapshot,
    WriteFact: _write,
    AlarmFact: _alarm,
    CheckFact: _check,
    NoteFact: _note,
    OriginFact: _origin,
    ReportFact: _report,
    RecordingFact: _recording,
    ModelCheckFact: _model_check,
    SettlementFact: _settlement,
}


def record_fact(register: Register, axis: str, fact: Fact) -> None:
    """Writes ``fact`` into ``register`` for ``axis`` ("MACHINE/AXIS"); the register's errors
    (RegisterError, OSError) are the caller's to say."""
    WRITERS[type(fact)](register, axis, fact)


def record_machine_fact(register: Register, fact: MachineLevelFact) -> None:
    """Writes a machine's own fact into ``register``; the register's errors (RegisterError,
    ValueError, OSError) are the caller's to say."""
    if isinstance(fact, MachineFact):
        from fha_studio.logic.machine import MachineProject

        MachineProject.from_json(dict(fact.data)).save_to(register, who=fact.who)
    else:
        register.record_report(
            fact.path, machine=fact.machine, open_warnings=fact.open_warnings, who=fact.who
        )
