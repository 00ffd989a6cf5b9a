"""Training scenarios as data: ``resources/training/*.toml`` (format in docs/training.md).

A scenario says what the trainee is told (actuator, driver, declared load, a briefing), the
drive as it really is with its hidden faults (options of the simulated drive, docs/sim.md), what
counts as finding each fault (evidence), the expected order of steps and a time guide.
:func:`load_scenario` checks a file whole; a mistake is one line naming the file, the line, the
field and what is allowed (:class:`ScenarioError`).
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import Any
from urllib.parse import quote

from fha_studio import fileio, names
from fha_studio.catalog import ModelCodeError, parse_model_code
from fha_studio.hardware.sim import EepromError, SimDrive
from fha_studio.hardware.sim.options import SimConfigError, config_from_url
from fha_studio.paths import resources_dir

#: Bound on a scenario file's size (a long one is a few kB).
MAX_FILE_BYTES = 256 * 1024
LEVELS = ("first day", "intermediate", "advanced")

#: Fault kinds, in plain words, with the simulated-drive options each may set (docs/training.md).
FAULT_KINDS: dict[str, tuple[str, tuple[str, ...]]] = {
    "rotary_direction": ("Rotary direction set opposite to the machine's need", ("preset",)),
    "motor_wiring": ("Motor leads swapped or open", ("wiring",)),
    "encoder_wiring": ("Encoder leads swapped or open", ("wiring",)),
    "brake_supply": ("Brake supply missing", ("brake_supply",)),
    "sensor_dog": ("A sensor dog outside the 4-7-3 range", ("origin_deg", "ls1_deg", "ls2_deg")),
    "position_error_allowance": ("Position error allowance (parameter 6) far too low", ("preset",)),
    "battery": ("Absolute encoder battery low, multi-turn data lost", ("battery",)),
    "mechanical_effect": ("A mechanical effect not in the declared model", ("effects", "load_inertia_kgm2")),
    "documented_profile": (
        "A drive of the manual's commands only, servo-ON from the controller",
        ("profile",),
    ),
}


class EvidenceKind(StrEnum):
    """What a piece of evidence is (the ``kind`` of a scenario file; docs/training.md)."""

    PROCEDURE = "procedure"
    PARAMETER_READ = "parameter_read"
    PARAMETER_WRITTEN = "parameter_written"
    ALARM_SEEN = "alarm_seen"
    ALARM_CLEARED = "alarm_cleared"
    MULTI_TURN_CLEARED = "multi_turn_cleared"
    JOG = "jog"
    MODEL_CHECK = "model_check"
    SAID = "said"


#: The fields each evidence kind takes (besides ``kind``); docs/training.md says what each means.
EVIDENCE_FIELDS: dict[EvidenceKind, tuple[str, ...]] = {
    EvidenceKind.PROCEDURE: ("procedure", "step", "passed", "value", "completed"),
    EvidenceKind.PARAMETER_READ: ("item",),
    EvidenceKind.PARAMETER_WRITTEN: ("item", "value", "minimum", "maximum"),
    EvidenceKind.ALARM_SEEN: ("code",),
    EvidenceKind.ALARM_CLEARED: ("code",),
    EvidenceKind.MULTI_TURN_CLEARED: (),
    EvidenceKind.JOG: ("direction",),
    EvidenceKind.MODEL_CHECK: ("effect",),
    EvidenceKind.SAID: ("words",),
}
_ITEM = re.compile(r"(tune|system|test)\.([0-9]+)")
_ID = re.compile(r"[a-z0-9][a-z0-9-]*")


class ScenarioError(ValueError):
    """A scenario file is wrong: one line naming the file, the line, the field and what is allowed."""


@dataclass(frozen=True)
class Evidence:
    """One thing the trainee can do or record that counts (see docs/training.md)."""

    kind: EvidenceKind
    procedure: str = ""
    step: str = ""
    passed: bool | None = None
    value: str | int | None = None
    completed: bool | None = None
    item: tuple[str, int] | None = None
    minimum: int | None = None
    maximum: int | None = None
    code: int | None = None
    direction: str = ""
    effect: str = ""
    words: tuple[str, ...] = ()

    def describe(self) -> str:
        """What counts, in plain words."""
        k = self.kind
        if k is EvidenceKind.PROCEDURE:
            what = f"in the procedure {procedure_title(self.procedure)}"
            if self.step:
                what += f", the step {self.step.replace('-', ' ')}"
            if self.passed is not None:
                what += " recorded as passed" if self.passed else " recorded as failed"
            if self.value is not None:
                what += f" with the value {self.value}"
            if self.completed:
                what += " completed"
            return what
        if k in (EvidenceKind.PARAMETER_READ, EvidenceKind.PARAMETER_WRITTEN) and self.item is not None:
            mode, number = self.item
            what = f"{'read' if k is EvidenceKind.PARAMETER_READ else 'wrote'} {mode} item {number}"
            if self.value is not None:
                what += f" = {self.value}"
            if self.minimum is not None:
                what += f" >= {self.minimum}"
            if self.maximum is not None:
                what += f" <= {self.maximum}"
            return what
        if k is EvidenceKind.ALARM_SEEN:
            return f"alarm {self.code} came up"
        if k is EvidenceKind.ALARM_CLEARED:
            return f"alarm {self.code} cleared"
        if k is EvidenceKind.MULTI_TURN_CLEARED:
            return "cleared the multi-turn data (OWW)"
        if k is EvidenceKind.JOG:
            return f"jogged {self.direction.upper() or 'the axis'}".strip()
        if k is EvidenceKind.MODEL_CHECK:
            return f"model check named {self.effect.replace('_', ' ')}"
        return "wrote in the findings: " + " or ".join(f"“{w}”" for w in self.words)


@dataclass(frozen=True)
class Fault:
    """One hidden fault: its kind, what it is (shown only on the score sheet), the simulated
    drive's options that make it, and what counts as finding it (any one of ``found_by``)."""

    id: str
    kind: str
    title: str
    explanation: str
    sim: dict[str, str]
    found_by: tuple[Evidence, ...]

    @property
    def kind_text(self) -> str:
        return FAULT_KINDS[self.kind][0]


@dataclass(frozen=True)
class ExpectedStep:
    """One expected step, in the scenario's order; done when any of ``done_by`` is seen."""

    id: str
    title: str
    done_by: tuple[Evidence, ...]


@dataclass(frozen=True)
class Scenario:
    """A training scenario (see the module docstring)."""

    id: str
    title: str
    level: str
    actuator: str
    driver: str
    load_inertia_kgm2: float  # what the trainee is told (declared)
    briefing: str
    time_guide_min: float
    drive: dict[str, str]  # the drive as it is, without the faults: sim:// options
    faults: tuple[Fault, ...]
    steps: tuple[ExpectedStep, ...]
    order: int = 100  # where the list shows it within its level
    path: Path | None = field(default=None, compare=False)

    def sim_options(self, faults: tuple[Fault, ...] | None = None) -> str:
        """The simulated drive's options (a URL query) with ``faults`` (default: all of them)."""
        options = dict(self.drive)
        if self.driver:
            options.setdefault("driver", self.driver)
        for fault in self.faults if faults is None else faults:
            options.update(fault.sim)
        return "&".join(f"{k}={quote(str(v), safe=':;,=.-_')}" for k, v in options.items())

    def sim_url(self, faults: tuple[Fault, ...] | None = None, **extra: str) -> str:
        """A plain ``sim://`` address of the drive with ``faults`` (checks and tests; a trainee's
        drive gets its faults through a training registration instead)."""
        query = "&".join(p for p in (self.sim_options(faults), *(f"{k}={v}" for k, v in extra.items())) if p)
        return f"sim://{self.actuator}?{query}"


def procedure_title(procedure_id: str) -> str:
    """The title of a procedure of resources/procedures (its id when there is no such file)."""
    path = resources_dir() / "procedures" / f"{procedure_id}.toml"
    try:
        with path.open("rb") as f:
            return str(tomllib.load(f)["procedure"]["title"])
    except (OSError, KeyError, tomllib.TOMLDecodeError):
        return procedure_id.replace("-", " ")


def scenarios_dir() -> Path:
    return resources_dir() / "training"


def list_scenarios(directory: Path | None = None) -> list[Scenario]:
    """Every scenario shipped (or in ``directory``), first-day ones first, then by title.
    Raises ScenarioError for the first file that is wrong."""
    folder = directory or scenarios_dir()
    found = [load_scenario(p) for p in sorted(folder.glob("*.toml"))]
    return sorted(found, key=lambda s: (LEVELS.index(s.level), s.order, s.title))


def find_scenario(name: str, directory: Path | None = None) -> Scenario:
    """A scenario by its id or by a file path; ScenarioError listing the ids otherwise."""
    folder = directory or scenarios_dir()
    ids = ", ".join(p.stem for p in sorted(folder.glob("*.toml")))
    if len(name) > names.TEXT_MAX or not names.printable(name):  # before it is used as a path
        raise ScenarioError(f"no training scenario {names.quoted(name)}; scenarios: {ids}")
    path = Path(name)
    if path.suffix == ".toml" and path.exists():
        return load_scenario(path)
    candidate = folder / f"{name}.toml"
    try:
        if candidate.exists():
            return load_scenario(candidate)
    except OSError:  # a name the file system cannot take is no scenario's
        pass
    raise ScenarioError(f"no training scenario {names.quoted(name)}; scenarios: {ids}")


class _Reader:
    """Field access with errors that name the file, the line and the field."""

    def __init__(self, path: Path, text: str):
        self.path = path
        self.lines = text.splitlines()

    def line_of(self, header: str, index: int, key: str | None) -> int:
        """The line of ``key`` in the ``index``-th table ``header`` (its header line when ``key``
        is None or not found; 0 when the table is not there)."""
        starts = [n for n, line in enumerate(self.lines, start=1) if line.strip() == header]
        if index >= len(starts):
            return 0
        start = starts[index]
        if key is None:
            return start
        name = header.strip("[]")
        for number in range(start + 1, len(self.lines) + 1):
            stripped = self.lines[number - 1].strip()
            if stripped.startswith("[") and not stripped.strip("[]").startswith(name + "."):
                break  # the next table: the key is not in this one
            if re.match(rf"{re.escape(key)}\s*=", stripped):
                return number
        return start

    def fail(self, where: str, line: int, what: str) -> ScenarioError:
        at = f"{self.path}:{line}" if line else str(self.path)
        return ScenarioError(f"{at}: {where}: {what}")


def _text(
    r: _Reader, table: dict[str, Any], key: str, where: str, line: int, *, required: bool = True
) -> str:
    value = table.get(key)
    if value is None:
        if required:
            raise r.fail(where, line, f"{key} is missing (a text)")
        return ""
    if not isinstance(value, str) or (required and not value.strip()):
        raise r.fail(where, line, f"{key} must be a non-empty text")
    return value.strip()


def _unknown(r: _Reader, table: dict[str, Any], allowed: tuple[str, ...], where: str, line: int) -> None:
    extra = sorted(set(table) - set(allowed))
    if extra:
        raise r.fail(where, line, f"unknown field {extra[0]}; allowed: {', '.join(allowed)}")


def _evidence(r: _Reader, data: Any, where: str, line: int) -> Evidence:
    if not isinstance(data, dict):
        raise r.fail(where, line, "must be a table with kind = ...")
    text = data.get("kind")
    if text not in EVIDENCE_FIELDS:
        raise r.fail(where, line, f"kind {text!r} is not one of {', '.join(EVIDENCE_FIELDS)}")
    kind = EvidenceKind(text)
    _unknown(r, data, ("kind", *EVIDENCE_FIELDS[kind]), where, line)
    values: dict[str, Any] = {"kind": kind}
    if kind is EvidenceKind.PROCEDURE:
        values["procedure"] = _text(r, data, "procedure", where, line)
        values["step"] = _text(r, data, "step", where, line, required=False)
        for key in ("passed", "completed"):
            if key in data:
                if not isinstance(data[key], bool):
                    raise r.fail(where, line, f"{key} must be true or false")
                values[key] = data[key]
        if "value" in data:
            values["value"] = str(data["value"])
    elif kind in (EvidenceKind.PARAMETER_READ, EvidenceKind.PARAMETER_WRITTEN):
        item = data.get("item")
        m = _ITEM.fullmatch(item) if isinstance(item, str) else None
        if m is None:
            raise r.fail(
                where, line, f"item {item!r} must be MODE.NUMBER (MODE: tune, system or test), e.g. system.6"
            )
        values["item"] = (m.group(1), int(m.group(2)))
        for key in ("value", "minimum", "maximum"):
            if key in data:
                number = isinstance(data[key], int) and not isinstance(data[key], bool)
                if kind is EvidenceKind.PARAMETER_READ or not number:
                    raise r.fail(where, line, f"{key} must be a whole number (parameter_written only)")
                values[key] = data[key]
    elif kind in (EvidenceKind.ALARM_SEEN, EvidenceKind.ALARM_CLEARED):
        code = data.get("code")
        if isinstance(code, bool) or not isinstance(code, int) or not 1 <= code <= 99:
            raise r.fail(where, line, f"code {code!r} must be an alarm code (a whole number 1 ... 99)")
        values["code"] = code
    elif kind is EvidenceKind.JOG:
        direction = data.get("direction", "")
        if direction not in ("", "fwd", "rev"):
            raise r.fail(where, line, f"direction {direction!r} must be fwd or rev (or left out: either)")
        values["direction"] = direction
    elif kind is EvidenceKind.MODEL_CHECK:
        values["effect"] = _text(r, data, "effect", where, line)
    elif kind is EvidenceKind.SAID:
        words = data.get("words")
        if (
            not isinstance(words, list)
            or not words
            or not all(isinstance(w, str) and w.strip() for w in words)
        ):
            raise r.fail(where, line, 'words must be a list of texts, e.g. ["battery", "56"]')
        values["words"] = tuple(w.strip().lower() for w in words)
    return Evidence(**values)


def _evidence_list(r: _Reader, data: Any, where: str, line: int, key: str) -> tuple[Evidence, ...]:
    if not isinstance(data, list) or not data:
        raise r.fail(where, line, f"{key} must list at least one piece of evidence ([[...{key}]] tables)")
    return tuple(_evidence(r, e, f"{where}, {key} {i + 1}", line) for i, e in enumerate(data))


#: Simulated-drive options that name a file the drive would write: not taken from a scenario.
FILE_OPTIONS = ("eeprom",)


def _sim_values(r: _Reader, data: Any, where: str, line: int) -> dict[str, str]:
    if not isinstance(data, dict):
        raise r.fail(where, line, "must be a table of simulated-drive options (docs/sim.md)")
    out: dict[str, str] = {}
    for key, value in data.items():
        if key in FILE_OPTIONS:  # checking or walking a scenario must write no file
            raise r.fail(where, line, f"{key}: a scenario names no file for the simulated drive "
                         "(the training drive keeps its EEPROM in memory)")
        if isinstance(value, bool):
            out[key] = "1" if value else "0"
        elif isinstance(value, int | float | str):
            out[key] = str(value)
        else:
            raise r.fail(where, line, f"{key} must be a text or a number")
    return out


def load_scenario(source: str | Path) -> Scenario:
    """Read and check one scenario file; ScenarioError names the file, line and field."""
    path = Path(source)
    try:
        text = fileio.read_text(path, limit_bytes=MAX_FILE_BYTES)
    except fileio.FileProblem as exc:
        raise ScenarioError(str(exc)) from None
    r = _Reader(path, text)
    try:
        data = fileio.parse_toml(text)  # bounded in depth
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path}: not a TOML file: {exc}") from None
    _unknown(r, data, ("scenario", "drive", "fault", "step"), "top level", 0)
    head = data.get("scenario")
    line = r.line_of("[scenario]", 0, None)
    if not isinstance(head, dict):
        raise r.fail("[scenario]", line, "the [scenario] table is missing")
    fields_ = (
        "id",
        "title",
        "level",
        "order",
        "actuator",
        "driver",
        "load_inertia_kgm2",
        "briefing",
        "time_guide_min",
    )
    _unknown(r, head, fields_, "[scenario]", line)
    sid = _text(r, head, "id", "[scenario]", r.line_of("[scenario]", 0, "id"))
    if sid != path.stem or not _ID.fullmatch(sid):
        raise r.fail(
            "[scenario]",
            r.line_of("[scenario]", 0, "id"),
            f"id {sid!r} must equal the file name ({path.stem}): lower-case letters, digits, dashes",
        )
    level = _text(r, head, "level", "[scenario]", r.line_of("[scenario]", 0, "level"))
    if level not in LEVELS:
        raise r.fail(
            "[scenario]",
            r.line_of("[scenario]", 0, "level"),
            f"level {level!r} is not one of {', '.join(LEVELS)}",
        )
    actuator = _text(r, head, "actuator", "[scenario]", r.line_of("[scenario]", 0, "actuator"))
    try:
        parse_model_code(actuator)
    except ModelCodeError as exc:
        raise r.fail("[scenario]", r.line_of("[scenario]", 0, "actuator"), f"actuator: {exc}") from None
    numbers: dict[str, float] = {}
    for key, low, high in (("load_inertia_kgm2", 0.0, 1500.0), ("time_guide_min", 1.0, 600.0)):
        value = head.get(key)
        if isinstance(value, bool) or not isinstance(value, int | float) or not low <= value <= high:
            raise r.fail(
                "[scenario]",
                r.line_of("[scenario]", 0, key),
                f"{key} {value!r} must be a number {low:g} ... {high:g}",
            )
        numbers[key] = float(value)
    order = head.get("order", 100)
    if isinstance(order, bool) or not isinstance(order, int):
        raise r.fail(
            "[scenario]", r.line_of("[scenario]", 0, "order"), f"order {order!r} must be a whole number"
        )
    drive = _sim_values(r, data.get("drive", {}), "[drive]", r.line_of("[drive]", 0, None))

    raw_faults = data.get("fault")
    if not isinstance(raw_faults, list) or not raw_faults:
        raise r.fail("[[fault]]", 0, "a scenario needs at least one [[fault]]")
    faults: list[Fault] = []
    for i, f in enumerate(raw_faults):
        fline = r.line_of("[[fault]]", i, None)
        where = f"[[fault]] {i + 1}"
        _unknown(r, f, ("id", "kind", "title", "explanation", "sim", "found_by"), where, fline)
        fid = _text(r, f, "id", where, fline)
        where = f"[[fault]] {fid}"
        kind = f.get("kind")
        if kind not in FAULT_KINDS:
            raise r.fail(
                where,
                r.line_of("[[fault]]", i, "kind"),
                f"kind {kind!r} is not one of {', '.join(FAULT_KINDS)}",
            )
        sim = _sim_values(r, f.get("sim"), f"{where}, sim", r.line_of("[[fault]]", i, "sim"))
        allowed = FAULT_KINDS[kind][1]
        stray = sorted(set(sim) - set(allowed))
        if not sim or stray:
            raise r.fail(
                f"{where}, sim",
                r.line_of("[[fault]]", i, "sim"),
                f"a {kind} fault sets {', '.join(allowed)} (got {', '.join(stray) or 'nothing'})",
            )
        if any(x.id == fid for x in faults):
            raise r.fail(where, fline, f"a second fault with the id {fid}")
        faults.append(
            Fault(
                id=fid,
                kind=kind,
                title=_text(r, f, "title", where, r.line_of("[[fault]]", i, "title")),
                explanation=_text(r, f, "explanation", where, r.line_of("[[fault]]", i, "explanation")),
                sim=sim,
                found_by=_evidence_list(
                    r, f.get("found_by"), where, r.line_of("[[fault]]", i, "found_by") or fline, "found_by"
                ),
            )
        )

    raw_steps = data.get("step")
    if not isinstance(raw_steps, list) or not raw_steps:
        raise r.fail("[[step]]", 0, "a scenario needs its expected steps ([[step]] tables, in order)")
    steps: list[ExpectedStep] = []
    for i, s in enumerate(raw_steps):
        sline = r.line_of("[[step]]", i, None)
        where = f"[[step]] {i + 1}"
        _unknown(r, s, ("id", "title", "done_by"), where, sline)
        stid = _text(r, s, "id", where, sline)
        steps.append(
            ExpectedStep(
                stid,
                _text(r, s, "title", where, sline),
                _evidence_list(r, s.get("done_by"), f"[[step]] {stid}", sline, "done_by"),
            )
        )

    scenario = Scenario(
        id=sid,
        title=_text(r, head, "title", "[scenario]", line),
        level=level,
        actuator=actuator,
        driver=_text(r, head, "driver", "[scenario]", line, required=False),
        load_inertia_kgm2=numbers["load_inertia_kgm2"],
        briefing=_text(r, head, "briefing", "[scenario]", r.line_of("[scenario]", 0, "briefing")),
        time_guide_min=numbers["time_guide_min"],
        drive=drive,
        faults=tuple(faults),
        steps=tuple(steps),
        order=order,
        path=path,
    )
    try:  # the whole drive, faults and all, must be one the simulated drive builds
        SimDrive(config=config_from_url(scenario.sim_url())).close()
    except (SimConfigError, EepromError, ValueError) as exc:
        raise r.fail(
            "[scenario] actuator and driver, [drive] and the faults' sim",
            r.line_of("[drive]", 0, None),
            str(exc),
        ) from None
    return scenario


__all__ = [
    "EVIDENCE_FIELDS",
    "FAULT_KINDS",
    "LEVELS",
    "Evidence",
    "EvidenceKind",
    "ExpectedStep",
    "Fault",
    "Scenario",
    "ScenarioError",
    "find_scenario",
    "list_scenarios",
    "load_scenario",
    "scenarios_dir",
]
