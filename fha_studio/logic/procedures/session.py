"""The commissioning session of one axis: every check recorded, saved as JSON (``fha-session/1``).

A session is the single source of the commissioning report: the report is rendered from the
session file alone (with the procedures and the parameter model it names), so it can be
reproduced later. Times are UTC, ISO 8601.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from fha_studio import clock, fileio, plausible
from fha_studio.names import kind_of

FORMAT = "fha-session/1"
#: Bound on a session file's size: a fully walked session is some tens of kB.
MAX_FILE_BYTES = 16 * 1024 * 1024

# Run states of one procedure in a session.
NOT_STARTED, RUNNING, PAUSED, STOPPED, COMPLETED = "not_started", "running", "paused", "stopped", "completed"


class SessionError(ValueError):
    """A session file cannot be read or does not fit (says which file and what)."""


#: What a session's signature holds: who and when; with a key also its id, the report's SHA-256
#: and the signature (hex).
SIGNATURE_FIELDS = ("who", "at_utc", "key_id", "sha256", "ed25519")


def utc_now() -> str:
    """Now, UTC, ISO 8601 to the second."""
    return clock.utc_iso()


@dataclass
class CheckRecord:
    """One answer to one step: who, when (UTC), the value, what passes, pass or fail."""

    procedure_id: str
    step_id: str
    kind: str
    section: str
    text: str
    value: Any
    expected: str
    unit: str
    passed: bool
    who: str
    at_utc: str
    detail: str = ""


@dataclass
class RunState:
    """Where one procedure stands in the session."""

    procedure_id: str
    step_ids: list[str] = field(default_factory=list)  # fingerprint of the procedure as walked
    status: str = NOT_STARTED
    position: int = 0  # index into step_ids of the step waiting for an answer
    answers: dict[str, Any] = field(default_factory=dict)
    records: list[CheckRecord] = field(default_factory=list)
    stop_step_id: str = ""
    stop_warning: str = ""
    started_utc: str = ""
    finished_utc: str = ""

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> RunState:
        records = [CheckRecord(**r) for r in data.get("records", [])]
        fields = {k: v for k, v in data.items() if k != "records"}
        return cls(records=records, **fields)


@dataclass
class ProcedureSession:
    """Everything recorded while commissioning one axis."""

    actuator_code: str
    axis: str = "axis 1"
    operator: str = ""
    site: str = ""
    driver: dict[str, str] = field(
        default_factory=dict
    )  # model, adjusted_for, version (from IDN or the label)
    created_utc: str = field(default_factory=utc_now)
    runs: dict[str, RunState] = field(default_factory=dict)
    sensor_angles_deg: dict[str, float] = field(
        default_factory=dict
    )  # limit_switch_1, limit_switch_2, origin_sensor
    parameters: dict[str, Any] = field(
        default_factory=dict
    )  # {"file": path, "values": {key: value}, "read_utc": ...}
    plots: list[dict[str, str]] = field(default_factory=list)  # {"title": ..., "path": PNG}
    notes: list[dict[str, str]] = field(default_factory=list)  # {"who", "at_utc", "text"}
    # {"who", "at_utc"}, and with a key: "key_id", "sha256" of the report, "ed25519" (its signature)
    signature: dict[str, str] = field(default_factory=dict)
    path: Path | None = field(default=None, compare=False, repr=False)

    def run(self, procedure_id: str) -> RunState:
        """The run state of a procedure (created, not started, when first asked for)."""
        if procedure_id not in self.runs:
            self.runs[procedure_id] = RunState(procedure_id=procedure_id)
        return self.runs[procedure_id]

    def to_json(self) -> dict[str, Any]:
        data = asdict(self)
        data.pop("path")
        return {"format": FORMAT, **data}

    def save(self, path: str | Path | None = None) -> Path:
        """Write the session (atomically: a crash leaves the old file whole); remembers the path."""
        target = Path(path) if path is not None else self.path
        if target is None:
            raise SessionError("the session has no file yet: give a path to save it to")
        try:
            if not os.path.lexists(target.parent):
                target.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise fileio.FileProblem(target, f"its folder cannot be made: {fileio.os_reason(exc)}") from None
        fileio.write_text(target, json.dumps(self.to_json(), indent=2, ensure_ascii=False) + "\n")
        self.path = target
        return target

    @classmethod
    def load(cls, path: str | Path) -> ProcedureSession:
        """Read a session file; raises :class:`SessionError` naming the file and the problem."""
        path = Path(path)
        try:
            text = fileio.read_text(path, limit_bytes=MAX_FILE_BYTES)
        except fileio.FileProblem as exc:
            if exc.reason == "no such file or directory":
                raise SessionError(f"{path}: no such session file") from None
            raise SessionError(str(exc)) from None
        try:
            data = fileio.parse_json(text)  # bounded in depth, finite numbers
        except json.JSONDecodeError as exc:
            raise SessionError(
                f"{path}: line {exc.lineno}: not a session file (not JSON: {exc.msg})") from None
        except fileio.NestedTooDeep as exc:
            raise SessionError(f"{path}: not a session file (nested too deep: {exc})") from None
        except ValueError as exc:
            raise SessionError(f"{path}: not a session file ({exc})") from None
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise SessionError(f"{path}: not an {FORMAT} session file (no \"format\": \"{FORMAT}\")")
        try:
            session = _session_from_json(data)
        except _ShapeError as exc:
            raise SessionError(f"{path}: field {exc.where}: {exc.what}") from None
        session.path = path
        return session

    def add_note(self, text: str, who: str = "") -> None:
        self.notes.append({"who": who or self.operator, "at_utc": utc_now(), "text": text})

    def add_plot(self, title: str, png_path: str | Path) -> None:
        self.plots.append({"title": title, "path": str(png_path)})


# -- reading: every field checked against its shape -------------------------------------------------

_STATUSES = (NOT_STARTED, RUNNING, PAUSED, STOPPED, COMPLETED)
#: the longest text a session field may hold (a note, a check's text); longer is not ours
MAX_TEXT = 100_000


class _ShapeError(Exception):
    def __init__(self, where: str, what: str):
        self.where, self.what = where, what


def _text(value: Any, where: str) -> str:
    if not isinstance(value, str):
        raise _ShapeError(where, f"must be text, got {kind_of(value)}")
    if len(value) > MAX_TEXT:
        raise _ShapeError(where, f"is {len(value)} characters long; at most {MAX_TEXT}")
    return value


def _table(value: Any, where: str, what: str) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise _ShapeError(where, f"must be a table of {what}, got {kind_of(value)}")
    return value


def _list(value: Any, where: str, what: str) -> list[Any]:
    if not isinstance(value, list):
        raise _ShapeError(where, f"must be a list of {what}, got {kind_of(value)}")
    return value


def _texts(value: Any, where: str, keys: tuple[str, ...] | None = None,
           optional: tuple[str, ...] = ()) -> dict[str, str]:
    """A table of texts; ``keys`` (said in the refusal) and ``optional`` the ones it may hold."""
    what = "texts" if keys is None else f"texts ({', '.join(keys)})"
    table = _table(value, where, what)
    if keys is not None:
        allowed = keys + optional
        unknown = sorted(set(table) - set(allowed))
        if unknown:
            raise _ShapeError(f"{where}.{unknown[0]}", f"unknown; allowed: {', '.join(allowed)}")
    return {k: _text(v, f"{where}.{k}") for k, v in table.items()}


def _session_from_json(data: dict[str, Any]) -> ProcedureSession:
    from fha_studio.catalog import ModelCodeError, parse_model_code

    known = {f.name for f in dataclasses.fields(ProcedureSession)} - {"path"}
    for key in data:
        if key != "format" and key not in known:
            raise _ShapeError(key, f"unknown; allowed: {', '.join(sorted(known))}")
    if "actuator_code" not in data:
        raise _ShapeError("actuator_code", "missing (the actuator model code, e.g. FHA-25C-50-US250)")
    code = _text(data["actuator_code"], "actuator_code")
    try:
        parse_model_code(code)
    except ModelCodeError as exc:
        raise _ShapeError("actuator_code", str(exc)) from None
    values: dict[str, Any] = {"actuator_code": code}
    for key in ("axis", "operator", "site", "created_utc"):
        if key in data:
            values[key] = _text(data[key], key)
    if "driver" in data:
        values["driver"] = _texts(data["driver"], "driver")
    if "signature" in data:
        signature = data["signature"]
        values["signature"] = _texts(signature, "signature", SIGNATURE_FIELDS[:2], SIGNATURE_FIELDS[2:])
    for key, fields in (("notes", ("who", "at_utc", "text")), ("plots", ("title", "path"))):
        if key in data:
            values[key] = [_texts(v, f"{key}[{i}]", fields)
                           for i, v in enumerate(_list(data[key], key, f"tables ({', '.join(fields)})"))]
    if "sensor_angles_deg" in data:
        angles = {}
        for name, value in _table(data["sensor_angles_deg"], "sensor_angles_deg", "angles").items():
            where = f"sensor_angles_deg.{name}"
            if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
                raise _ShapeError(where, f"must be a number of degrees, got {kind_of(value)}")
            if not plausible.SENSOR_ANGLE_DEG.contains(value):
                raise _ShapeError(where, f"{value:g} deg is outside {plausible.SENSOR_ANGLE_DEG.allowed()}")
            angles[name] = float(value)
        values["sensor_angles_deg"] = angles
    if "parameters" in data:
        values["parameters"] = _parameters(data["parameters"])
    if "runs" in data:
        runs = _table(data["runs"], "runs", "procedure runs by procedure id")
        values["runs"] = {pid: _run_from_json(run, f"runs.{pid}") for pid, run in runs.items()}
    return ProcedureSession(**values)


def _parameters(data: Any) -> dict[str, Any]:
    """``{"file": text, "read_utc": text, "values": {key: wire integer}, "front_panel": {key:
    {"who": text, "time": text}}}`` (front_panel: the values entered from the drive's front panel,
    as the Procedures page writes them)."""
    table = _table(data, "parameters", "fields (file, read_utc, values, front_panel)")
    allowed = ("file", "read_utc", "values", "front_panel")
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise _ShapeError(f"parameters.{unknown[0]}", f"unknown; allowed: {', '.join(allowed)}")
    out: dict[str, Any] = {k: _text(table[k], f"parameters.{k}") for k in ("file", "read_utc") if k in table}
    if "values" in table:
        found = _table(table["values"], "parameters.values", "wire integers by parameter key")
        for key, wire in found.items():
            if isinstance(wire, bool) or not isinstance(wire, int):
                raise _ShapeError(f"parameters.values.{key}", f"must be a whole number (the drive's value), "
                                  f"got {kind_of(wire)}")
            if not -(2**31) <= wire < 2**31:
                raise _ShapeError(f"parameters.values.{key}", f"{wire:g} is no value a drive holds")
        out["values"] = dict(found)
    if "front_panel" in table:
        entries = _table(table["front_panel"], "parameters.front_panel",
                         "front-panel entries by parameter key")
        panel: dict[str, dict[str, str]] = {}
        for key, entry in entries.items():
            where = f"parameters.front_panel.{key}"
            fields = _table(entry, where, "fields (who, time)")
            unknown = sorted(set(fields) - {"who", "time"})
            if unknown:
                raise _ShapeError(f"{where}.{unknown[0]}", "unknown; allowed: who, time")
            panel[key] = {k: _text(fields[k], f"{where}.{k}") for k in ("who", "time") if k in fields}
        out["front_panel"] = panel
    return out


def _run_from_json(data: Any, where: str) -> RunState:
    table = _table(data, where, "run fields")
    known = {f.name for f in dataclasses.fields(RunState)}
    for key in table:
        if key not in known:
            raise _ShapeError(f"{where}.{key}", f"unknown; allowed: {', '.join(sorted(known))}")
    values: dict[str, Any] = {}
    for key in ("procedure_id", "stop_step_id", "stop_warning", "started_utc", "finished_utc"):
        if key in table:
            values[key] = _text(table[key], f"{where}.{key}")
    if "procedure_id" not in values:
        raise _ShapeError(f"{where}.procedure_id", "missing")
    if "status" in table:
        status = table["status"]
        if status not in _STATUSES:
            raise _ShapeError(f"{where}.status", f"is {kind_of(status)}; allowed: {', '.join(_STATUSES)}")
        values["status"] = status
    if "step_ids" in table:
        step_ids = _list(table["step_ids"], f"{where}.step_ids", "step ids")
        values["step_ids"] = [_text(v, f"{where}.step_ids[{i}]") for i, v in enumerate(step_ids)]
    if "position" in table:
        position = table["position"]
        limit = len(values.get("step_ids", []))
        if isinstance(position, bool) or not isinstance(position, int) or not 0 <= position <= limit:
            raise _ShapeError(f"{where}.position", f"must be a whole number 0 ... {limit} (a step), "
                              f"got {kind_of(position)}")
        values["position"] = position
    if "answers" in table:  # any JSON value: what a step recorded (engine._plain)
        values["answers"] = _table(table["answers"], f"{where}.answers", "answers by step id")
    if "records" in table:
        records = _list(table["records"], f"{where}.records", "check records")
        values["records"] = [_record_from_json(r, f"{where}.records[{i}]") for i, r in enumerate(records)]
    return RunState(**values)


def _record_from_json(data: Any, where: str) -> CheckRecord:
    fields = {f.name: f for f in dataclasses.fields(CheckRecord)}
    table = _table(data, where, "check fields")
    for key in table:
        if key not in fields:
            raise _ShapeError(f"{where}.{key}", f"unknown; allowed: {', '.join(fields)}")
    values: dict[str, Any] = {}
    for name, f in fields.items():
        if name not in table:
            if f.default is dataclasses.MISSING:
                raise _ShapeError(f"{where}.{name}", "missing")
            continue
        value = table[name]
        if name == "passed":
            if not isinstance(value, bool):
                raise _ShapeError(f"{where}.passed", f"must be true or false, got {kind_of(value)}")
        elif name == "value":
            pass  # any JSON value: what the step recorded
        else:
            value = _text(value, f"{where}.{name}")
        values[name] = value
    return CheckRecord(**values)
