"""Procedures as data: loading ``resources/procedures/*.toml`` and filling them in for an actuator.

A procedure file has a ``[procedure]`` table (``id``, ``title``, ``section``, ``order``, optional
``when``) and ``[[step]]`` tables. Every step has ``id``, ``kind``, ``section`` (the manual's
section), ``text`` and usually ``warning`` (what the manual says when the check fails: shown when
the procedure stops). Kinds and their fields:

- ``confirm``: the user answers yes (pass) or no (fail).
- ``measure``: a measured number in ``unit``, passing when ``minimum <= value <= maximum``
  (either may be absent).
- ``text``: a text read off a label, passing when it equals ``expect`` (or one of ``expect_any``),
  compared without case, spaces or dashes mattering.
- ``choose``: one of ``choices``; passes when it equals ``expect`` (or when there is no ``expect``).
- ``live``: a check against the drive: ``check`` names a function of
  :mod:`fha_studio.logic.procedures.live`; the other fields are its parameters.
- ``sensor_angle``: the output angle (deg) where ``sensor`` switched, taken by the sensor-dog
  wizard; passes inside the movable range of 4-7-3 and in the right order.

A step may also have ``bench`` (``direction``, ``flange``, ``encoder``): a move the controller
makes, seen on CN2 by a bench instrument, answers it (:mod:`.bench_steps`).

Text in ``{...}`` is a path into the actuator's context (:func:`context.build_context`), e.g.
``{tightening.output_flange.torque_nm}``, ``{row.color}`` inside a ``for_each`` step (one step
per row of a context table), or ``{answers.STEP_ID}`` (an earlier answer in the same run).
A field that is exactly one ``{path}`` keeps the value's type (a number, a list).
``when`` is a list of conditions that must all hold: ``flag``, ``!flag`` (flags of the context:
``brake``, ``absolute``, ``incremental``, ``sensor_set``, ...) or ``answer:STEP_ID=VALUE``.
"""

from __future__ import annotations

import re
import string
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fha_studio.logic.procedures.sensor_dogs import SENSORS, Sensor
from fha_studio.paths import resource

KINDS = ("confirm", "measure", "text", "choose", "live", "sensor_angle")
_WHOLE_FIELD = re.compile(r"^\{([A-Za-z0-9_.\-]+)\}$")
# Fields that are templates; everything else in a step is kept as written.
_TEMPLATED = ("text", "warning", "minimum", "maximum", "expect", "expect_any", "unit")


class ProcedureError(ValueError):
    """A procedure file is wrong, or cannot be filled in for this actuator (says which and where)."""


def _lookup(path: str, context: Mapping[str, Any], where: str) -> Any:
    value: Any = context
    for part in path.split("."):
        if isinstance(value, Mapping) and part in value:
            value = value[part]
        elif isinstance(value, list | tuple) and part.isdigit() and int(part) < len(value):
            value = value[int(part)]
        else:
            raise ProcedureError(f"{where}: '{{{path}}}' is not known for this actuator (no '{part}')")
    return value


class _Formatter(string.Formatter):
    def __init__(self, context: Mapping[str, Any], where: str):
        self.context = context
        self.where = where

    def get_field(self, field_name: str, args: Sequence[Any], kwargs: Mapping[str, Any]) -> tuple[Any, str]:
        return _lookup(field_name, self.context, self.where), field_name

    def format_field(self, value: Any, format_spec: str) -> str:
        # Numbers in text as people write them: 40, 24.5, not 40.0.
        if isinstance(value, float) and not format_spec:
            return f"{value:g}"
        return str(super().format_field(value, format_spec))


def render(template: Any, context: Mapping[str, Any], where: str) -> Any:
    """Fill ``{path}`` fields of ``template`` from ``context``; non-strings and lists pass through."""
    if isinstance(template, list):
        return [render(item, context, where) for item in template]
    if not isinstance(template, str):
        return template
    whole = _WHOLE_FIELD.match(template)
    if whole:
        return _lookup(whole.group(1), context, where)
    try:
        return _Formatter(context, where).vformat(template, (), {})
    except (ValueError, IndexError) as exc:
        raise ProcedureError(f"{where}: bad template {template!r}: {exc}") from None


def condition_holds(condition: str, context: Mapping[str, Any], answers: Mapping[str, Any]) -> bool:
    """One ``when`` condition: ``flag``, ``!flag`` or ``answer:STEP_ID=VALUE``."""
    if condition.startswith("answer:"):
        step_id, _, wanted = condition[len("answer:") :].partition("=")
        return step_id in answers and str(answers[step_id]) == wanted
    negate = condition.startswith("!")
    flag = condition.lstrip("!")
    value = bool(context.get("flags", {}).get(flag, False))
    return value != negate


def _static(conditions: list[str]) -> list[str]:
    return [c for c in conditions if not c.startswith("answer:")]


@dataclass(frozen=True)
class Step:
    """One step filled in for the actuator and the answers so far (see the module docstring)."""

    id: str
    kind: str
    section: str
    text: str
    warning: str = ""
    unit: str = ""
    minimum: float | None = None
    maximum: float | None = None
    expect: Any = None
    expect_any: tuple[str, ...] = ()
    choices: tuple[str, ...] = ()
    check: str = ""
    sensor: str = ""  # a sensor_angle step's Sensor (whose switching angle it takes)
    params: Mapping[str, Any] = field(default_factory=dict)
    stop_on_fail: bool = True

    def expected_text(self) -> str:
        """What passes, in words, for the record and the report."""
        if self.kind == "measure":
            low = "" if self.minimum is None else f"{self.minimum:g}"
            high = "" if self.maximum is None else f"{self.maximum:g}"
            if low and high:
                return f"{low} … {high} {self.unit}".strip()
            return (f">= {low}" if low else f"<= {high}") + (f" {self.unit}" if self.unit else "")
        if self.kind == "confirm":
            return "yes"
        if self.expect_any:
            return " or ".join(self.expect_any)
        if isinstance(self.expect, bool):
            return "yes" if self.expect else "no"
        if self.expect is not None:
            return str(self.expect)
        return ""


@dataclass(frozen=True)
class StepDef:
    """A step as written in the file (after ``for_each`` expansion), filled in per run."""

    id: str
    raw: Mapping[str, Any]
    row: Mapping[str, Any] | None
    when: tuple[str, ...]
    source: str

    def applies(self, context: Mapping[str, Any], answers: Mapping[str, Any]) -> bool:
        return all(condition_holds(c, context, answers) for c in self.when)

    def resolve(self, context: Mapping[str, Any], answers: Mapping[str, Any]) -> Step:
        """The step filled in with the context, its row and the answers given so far."""
        ctx = dict(context)
        ctx["answers"] = answers
        if self.row is not None:
            ctx["row"] = self.row
        where = f"{self.source}: step '{self.id}'"
        raw = self.raw
        values = {name: render(raw[name], ctx, where) for name in _TEMPLATED if name in raw}
        kind = raw["kind"]

        def number(name: str) -> float | None:
            if name not in values:
                return None
            try:
                return float(values[name])
            except (TypeError, ValueError):
                raise ProcedureError(f"{where}: {name} {values[name]!r} is not a number") from None

        expect_any = values.get("expect_any", ())
        if isinstance(expect_any, str):
            expect_any = [expect_any]
        expect = values.get("expect")
        if kind == "choose" and expect is not None and not isinstance(expect, list):
            expect = str(expect)
        params = {
            k: v
            for k, v in raw.items()
            if k
            not in (
                *_TEMPLATED,
                "id",
                "kind",
                "section",
                "when",
                "for_each",
                "choices",
                "check",
                "sensor",
                "stop_on_fail",
            )
        }
        return Step(
            id=self.id,
            kind=kind,
            section=str(raw.get("section", "")),
            text=str(values.get("text", "")),
            warning=str(values.get("warning", "")),
            unit=str(values.get("unit", "")),
            minimum=number("minimum"),
            maximum=number("maximum"),
            expect=expect,
            expect_any=tuple(str(v) for v in expect_any),
            choices=tuple(str(c) for c in raw.get("choices", ())),
            check=str(raw.get("check", "")),
            sensor=Sensor(raw["sensor"]) if raw.get("sensor") in SENSORS else str(raw.get("sensor", "")),
            params=params,
            stop_on_fail=bool(raw.get("stop_on_fail", True)),
        )


@dataclass(frozen=True)
class Procedure:
    """A procedure filled in for one actuator: its steps in order (``for_each`` expanded)."""

    id: str
    title: str
    section: str
    order: int
    summary: str
    steps: tuple[StepDef, ...]
    context: Mapping[str, Any]
    applies: bool
    source: str
    #: Why it does not apply to this actuator, in words ("" when it applies).
    not_applicable_reason: str = ""

    def step_ids(self) -> list[str]:
        return [s.id for s in self.steps]

    def step(self, step_id: str) -> StepDef:
        for s in self.steps:
            if s.id == step_id:
                return s
        raise KeyError(f"procedure '{self.id}' has no step '{step_id}'")


def procedures_dir() -> Path:
    return resource("procedures")


def _read(path: Path) -> dict[str, Any]:
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ProcedureError(f"{path.name}: not valid TOML: {exc}") from None


def _check_step(raw: Mapping[str, Any], where: str) -> None:
    for name in ("id", "kind", "section", "text"):
        if name not in raw:
            raise ProcedureError(f"{where}: step has no '{name}'")
    kind = raw["kind"]
    if kind not in KINDS:
        raise ProcedureError(
            f"{where}: step '{raw['id']}' has kind '{kind}'; known kinds: {', '.join(KINDS)}"
        )
    if kind == "choose" and not raw.get("choices"):
        raise ProcedureError(f"{where}: choose step '{raw['id']}' has no choices")
    if kind == "text" and "expect" not in raw and "expect_any" not in raw:
        raise ProcedureError(f"{where}: text step '{raw['id']}' has neither expect nor expect_any")
    if kind == "live" and not raw.get("check"):
        raise ProcedureError(f"{where}: live step '{raw['id']}' names no check")
    if kind == "sensor_angle" and raw.get("sensor") not in SENSORS:
        raise ProcedureError(
            f"{where}: sensor_angle step '{raw['id']}' needs sensor = one of {', '.join(SENSORS)}"
        )
    when = raw.get("when", [])
    if not isinstance(when, list) or not all(isinstance(c, str) for c in when):
        raise ProcedureError(f"{where}: step '{raw['id']}': when must be a list of strings")


def procedure_files() -> list[Path]:
    """The procedure files (TOML files with a [procedure] table) under resources/procedures."""
    return sorted(p for p in procedures_dir().glob("*.toml") if "procedure" in _read(p))


def load_procedure(source: str | Path, context: Mapping[str, Any]) -> Procedure:
    """Load one procedure (by id or file path) and fill it in for the actuator's ``context``.

    Raises :class:`ProcedureError` naming the file and step for anything wrong in the data or a
    value the actuator's context does not have.
    """
    path = Path(source) if isinstance(source, Path) or str(source).endswith(".toml") else None
    if path is None:
        matches = [p for p in procedure_files() if _read(p)["procedure"].get("id") == source]
        if not matches:
            known = ", ".join(_read(p)["procedure"]["id"] for p in procedure_files())
            raise ProcedureError(f"no procedure '{source}'; known: {known}")
        path = matches[0]
    data = _read(path)
    name = path.name
    head = data.get("procedure")
    if not isinstance(head, dict) or "id" not in head or "title" not in head:
        raise ProcedureError(f"{name}: needs a [procedure] table with id and title")
    applies = all(condition_holds(c, context, {}) for c in head.get("when", []))
    steps: list[StepDef] = []
    seen: set[str] = set()
    for raw in data.get("step", []):
        _check_step(raw, name)
        when = tuple(raw.get("when", []))
        if applies and not all(condition_holds(c, context, {}) for c in _static(list(when))):
            continue  # not for this actuator (e.g. brake steps without option B)
        rows: list[Mapping[str, Any] | None] = [None]
        if "for_each" in raw and applies:
            table = render("{" + raw["for_each"] + "}", context, f"{name}: step '{raw['id']}'")
            if not isinstance(table, list) or not table:
                raise ProcedureError(
                    f"{name}: step '{raw['id']}': for_each '{raw['for_each']}' is not a table"
                )
            rows = list(table)
        for index, row in enumerate(rows, start=1):
            step_id = raw["id"] if row is None else f"{raw['id']}.{index}"
            if step_id in seen:
                raise ProcedureError(f"{name}: step id '{step_id}' appears twice")
            seen.add(step_id)
            steps.append(StepDef(id=step_id, raw=raw, row=row, when=when, source=name))
    procedure = Procedure(
        id=str(head["id"]),
        title=str(head["title"]),
        section=str(head.get("section", "")),
        order=int(head.get("order", 100)),
        summary=str(head.get("summary", "")),
        steps=tuple(steps),
        context=context,
        applies=applies,
        source=name,
        not_applicable_reason="" if applies else _why_not(head.get("when", []), context),
    )
    if applies:
        # Fill every step in now with placeholder answers, so that a wrong path in the data shows
        # when the procedure is loaded, not halfway through a commissioning.
        placeholder = _Placeholders()
        for step in steps:
            step.resolve(context, placeholder)
    return procedure


#: What a procedure-level condition asks of the actuator, in words (the manual's option letters).
_NEEDS = {
    "sensor_set": "an actuator with the rotary position sensor set (option L, 4-7)",
    "brake": "an actuator with a brake (option B)",
    "absolute": "an actuator with an absolute encoder (S248)",
    "incremental": "an actuator with an incremental encoder (US250)",
}


def _why_not(conditions: list[str], context: Mapping[str, Any]) -> str:
    """Why a procedure whose ``when`` fails does not apply: "needs an actuator with ..."."""
    needs = [
        _NEEDS.get(c, f"the condition '{c}'") for c in conditions if not condition_holds(c, context, {})
    ]
    if not needs:
        return ""
    code = context.get("actuator", {}).get("model_code", "this actuator")
    return f"needs {' and '.join(needs)}; this one is {code}"


class _Placeholders(dict[str, Any]):
    def __contains__(self, key: object) -> bool:
        return True

    def __missing__(self, key: str) -> str:
        return "?"

    def copy(self) -> _Placeholders:
        return self


def load_all(context: Mapping[str, Any]) -> list[Procedure]:
    """Every procedure, filled in for the actuator, in their ``order`` (including ones that do not apply)."""
    procedures = [load_procedure(p, context) for p in procedure_files()]
    return sorted(procedures, key=lambda p: (p.order, p.id))
