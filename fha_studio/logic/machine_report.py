"""The machine report: a summary table of every axis, then each axis's commissioning report.

The summary says per axis: actuator, driver, rotary direction, origin, checks passed and failed
(the latest answer to each check), and whether its report is signed. Each axis's report is the
one :mod:`fha_studio.logic.procedures.report` renders from its session file, so the machine report
says nothing an axis report does not. Plain HTML (QTextDocument prints it to PDF).
"""

from __future__ import annotations

import contextlib
import html
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from fha_studio.catalog import DEFAULT_ACTUATOR
from fha_studio.logic.machine import MachineAxis, MachineProject
from fha_studio.logic.procedures.report import CommissioningReport, build_report, render_html
from fha_studio.logic.procedures.sensor_dogs import Sensor
from fha_studio.logic.procedures.session import ProcedureSession, SessionError, utc_now

#: (mode, number) of the rotary direction item (HA-655 manual, parameter mode 8; FHA-C manual 1-10).
ROTARY_DIRECTION = ("system", 8)


@dataclass(frozen=True)
class AxisSummary:
    """One row of the summary table."""

    axis: str
    actuator: str
    driver: str
    direction: str
    origin: str
    checks_passed: int
    checks_failed: int
    signed: str  # "signed by NAME (time UTC)" or "not signed"
    is_signed: bool
    open_warnings: int
    #: conflicts between registers not settled yet, one line each (what differs, each side's value)
    open_conflicts: tuple[str, ...] = ()


@dataclass(frozen=True)
class MachineReport:
    title: str
    machine: str
    site: str
    created_utc: str
    summaries: tuple[AxisSummary, ...]
    axis_reports: tuple[CommissioningReport | None, ...]  # None: the axis has no session yet
    problems: tuple[str, ...] = ()  # session files that could not be read, one line each


@dataclass(frozen=True)
class RegisterExcerpt:
    """What the machine report asks a register of each axis, asked all at once (by a thread of
    its own for a register on a server, so that the window never waits for it), answering as the
    register does: ValueError for an axis it does not have."""

    origins: Mapping[str, Any] = field(default_factory=dict)
    values: Mapping[str, Any] = field(default_factory=dict)
    checks: Mapping[str, tuple[int, int]] = field(default_factory=dict)
    open_conflicts: Mapping[str, list[Any]] = field(default_factory=dict)

    @classmethod
    def of(cls, register: Any, refs: Iterable[str]) -> RegisterExcerpt:
        """The answers of ``register`` for the axes ``refs`` (``MACHINE/AXIS``)."""
        origins, values, checks, conflicts = {}, {}, {}, {}
        for ref in refs:
            try:
                origins[ref] = register.latest_origin(ref)
                values[ref] = register.current_values(ref)
                checks[ref] = register.check_counts(ref)
                conflicts[ref] = register.conflicts(ref)
            except ValueError:  # an axis the register does not have
                for found in (origins, values, checks, conflicts):
                    found.pop(ref, None)
        return cls(origins, values, checks, conflicts)

    def _known(self, ref: str, answers: Mapping[str, Any]) -> Any:
        if ref not in answers:
            raise ValueError(f"the register has no axis {ref}")
        return answers[ref]

    def latest_origin(self, ref: str) -> Any:
        return self._known(ref, self.origins)

    def current_values(self, ref: str) -> Any:
        return self._known(ref, self.values)

    def check_counts(self, ref: str) -> tuple[int, int]:
        passed, failed = self._known(ref, self.checks)
        return int(passed), int(failed)

    def conflicts(self, ref: str) -> list[Any]:
        return list(self._known(ref, self.open_conflicts))


def direction_text(value: int | None) -> str:
    """The rotary direction in the manual's words (1-10 table): "0: FWD command -> FWD rotation
    (default)"; "not known" when nobody read or entered it."""
    if value is None:
        return "not known"
    from fha_studio.catalog.tables import rotary_direction

    for setting in rotary_direction():
        if setting.value == value:
            default = " (default)" if setting.default else ""
            return f"{value}: FWD command → {setting.fwd_command}{default}"
    return f"{value}: not a value of the 1-10 table"


def _checks(session: ProcedureSession | None) -> tuple[int, int]:
    if session is None:
        return 0, 0
    latest: dict[tuple[str, str], bool] = {}
    for state in session.runs.values():
        for record in state.records:
            latest[(record.procedure_id, record.step_id)] = bool(record.passed)
    passed = sum(1 for ok in latest.values() if ok)
    return passed, len(latest) - passed


def _origin(axis: MachineAxis, session: ProcedureSession | None, register: Any, axis_ref: str) -> str:
    angles = session.sensor_angles_deg if session is not None else {}
    if Sensor.ORIGIN_SENSOR in angles:
        return f"origin sensor at {float(angles[Sensor.ORIGIN_SENSOR]):+.2f}° (4-7-2)"
    if register is not None:
        try:
            origin = register.latest_origin(axis_ref)
        except ValueError:
            origin = None
        if origin is not None:
            return f"{origin['text']} ({origin['at_utc'][:16].replace('T', ' ')} UTC)"
    return "not recorded"


def _direction_value(
    axis: MachineAxis, session: ProcedureSession | None, register: Any, axis_ref: str
) -> int | None:
    # the register knows every read and verified write of the axis; the state what this program
    # read since it started; the session what was read for its report
    if register is not None:
        try:
            known = register.current_values(axis_ref).values.get("rotary_direction")
        except ValueError:
            known = None
        if known is not None:
            return int(known.value)
    value = axis.state.value_of(*ROTARY_DIRECTION)
    if value is not None:
        return value
    if session is not None:
        stored = (session.parameters or {}).get("values", {}).get("rotary_direction")
        if stored is not None:
            return int(stored)
    return None


def build_machine_report(
    project: MachineProject,
    sessions: Mapping[str, ProcedureSession | None] | None = None,
    register: Any = None,
    register_problem: str = "",
) -> MachineReport:
    """The report of ``project``. ``sessions`` maps axis names to their procedure sessions (an
    axis not in it: its ``session_file`` is read, when it has one); ``register`` (optional) gives
    values and origins recorded there (a :class:`Register`, or a :class:`RegisterExcerpt` of
    one); ``register_problem``: why the register was not asked (one line; the report says it)."""
    sessions = dict(sessions or {})
    summaries, reports, problems = [], [], []
    if register_problem:
        problems.append(f"what the register knows of the axes (values read, origins, checks, conflicts) is "
                        f"not in this report: {register_problem}")
    for axis in project:
        session = sessions.get(axis.name)
        if axis.name not in sessions and axis.session_file is not None:
            try:
                session = ProcedureSession.load(axis.session_file)
            except SessionError as exc:
                problems.append(f"axis {axis.name}: {exc}")
        ref = f"{project.name}/{axis.name}"
        report = build_report(session) if session is not None else None
        passed, failed = _checks(session)
        if register is not None:
            # the register also holds the checks done outside the procedures (DGR checks)
            with contextlib.suppress(ValueError):  # an axis the register does not have
                passed, failed = max((passed, failed), register.check_counts(ref), key=sum)
        signature = session.signature if session is not None else {}
        if signature:
            signed = f"signed by {signature['who']} ({signature['at_utc'][:16].replace('T', ' ')} UTC)"
        else:
            signed = "not signed"
        driver = axis.driver_model or (session.driver.get("model", "") if session is not None else "")
        conflicts: list[str] = []
        if register is not None:
            with contextlib.suppress(ValueError):  # an axis the register does not have
                conflicts = [f"conflict {c.short}: {c.summary()}: "
                             + "; ".join(line.strip() for line in c.lines()) for c in register.conflicts(ref)]
        summaries.append(
            AxisSummary(
                axis=axis.name,
                actuator=axis.actuator_code or (session.actuator_code if session is not None else ""),
                driver=driver,
                direction=direction_text(_direction_value(axis, session, register, ref)),
                origin=_origin(axis, session, register, ref),
                checks_passed=passed,
                checks_failed=failed,
                signed=signed,
                is_signed=bool(signature),
                open_warnings=len(report.warnings) if report is not None else 0,
                open_conflicts=tuple(conflicts),
            )
        )
        reports.append(report)
    return MachineReport(
        title=f"Machine report — {project.name}",
        machine=project.name,
        site=project.site,
        created_utc=utc_now(),
        summaries=tuple(summaries),
        axis_reports=tuple(reports),
        problems=tuple(problems),
    )


_STYLE = re.compile(r"<style>(.*?)</style>", re.S)
_BODY = re.compile(r"<body>(.*)</body>", re.S)


def _e(value: Any) -> str:
    return html.escape("" if value is None else str(value))


def render_machine_html(report: MachineReport) -> str:
    """The machine report as one HTML document: summary table, then every axis's report."""
    axis_html = [render_html(r) if r is not None else "" for r in report.axis_reports]
    style = next((m.group(1) for h in axis_html if (m := _STYLE.search(h))), "")
    if not style:
        style = _fallback_style()
    out = [
        f"<html><head><meta charset='utf-8'><title>{_e(report.title)}</title>",
        f"<style>{style}</style></head><body>",
        f"<h1>{_e(report.title)}</h1>",
        f"<p>Site: {_e(report.site) or 'not given'} — {len(report.summaries)} axes — "
        f"written {_e(report.created_utc[:16].replace('T', ' '))} UTC</p>",
        "<h2>Axes</h2>",
    ]
    head = [
        "Axis",
        "Actuator",
        "Driver",
        "Rotary direction",
        "Origin",
        "Checks passed",
        "Checks failed",
        "Report",
    ]
    widths = [10, 17, 12, 19, 18, 7, 7, 10]  # per cent of the page
    rows = []
    for s in report.summaries:
        failed = f"<span class='fail'>{s.checks_failed}</span>" if s.checks_failed else "0"
        signed = (
            f"<span class='pass'>{_e(s.signed)}</span>"
            if s.is_signed
            else f"<span class='warn'>{_e(s.signed)}</span>"
        )
        rows.append(
            [
                _e(s.axis),
                _e(s.actuator or "not given"),
                _e(s.driver or "not known"),
                _e(s.direction),
                _e(s.origin),
                str(s.checks_passed),
                failed,
                signed,
            ]
        )
    header = "".join(f"<th width='{w}%'>{h}</th>" for h, w in zip(head, widths, strict=True))
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows)
    out.append(f"<table width='100%'><tr>{header}</tr>{body}</table>")
    if report.problems:
        out.append("<ul>" + "".join(f"<li class='warn'>{_e(p)}</li>" for p in report.problems) + "</ul>")
    conflicts = [(s.axis, c) for s in report.summaries for c in s.open_conflicts]
    if conflicts:
        out.append("<h2>Open conflicts</h2><p>Registers synced after they were apart disagree on these; "
                   "a person settles each (fha-studio register conflicts, register resolve).</p>")
        out.append("<ul>" + "".join(f"<li class='warn'>Axis {_e(a)}: {_e(c)}</li>" for a, c in conflicts)
                   + "</ul>")
    for summary, axis_report, text in zip(report.summaries, report.axis_reports, axis_html, strict=True):
        out.append(f"<h1 style='page-break-before: always'>Axis {_e(summary.axis)}</h1>")
        if axis_report is None:
            out.append("<p class='warn'>No procedure session for this axis yet: nothing was checked.</p>")
            continue
        match = _BODY.search(text)
        out.append(match.group(1) if match else text)
    out.append("</body></html>")
    return "\n".join(out)


def _fallback_style() -> str:
    # no axis has a report: the axis report's style, taken from an empty session's report
    sample = render_html(build_report(ProcedureSession(actuator_code=DEFAULT_ACTUATOR)))
    match = _STYLE.search(sample)
    return match.group(1) if match else ""
