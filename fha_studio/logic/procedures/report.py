"""The commissioning report of one axis: a model built from the session file, rendered to HTML.

Everything in the report comes from the saved session (plus the procedure files and the
parameter model it refers to), so the same session file renders the same report later. The HTML
is plain (no scripts, inline CSS) so that Qt's QTextDocument can print it to PDF.
"""

from __future__ import annotations

import html
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fha_studio.hardware.parameters import MODE_WORDS, Mode
from fha_studio.logic.procedures.definitions import Procedure, load_all
from fha_studio.logic.procedures.sensor_dogs import SENSOR_NAMES
from fha_studio.logic.procedures.session import COMPLETED, STOPPED, CheckRecord, ProcedureSession, utc_now


class SignError(ValueError):
    """The report cannot be signed yet (says what is still open)."""


@dataclass(frozen=True)
class ProcedureResult:
    """One procedure in the report: its status and the records (every attempt, in order)."""

    id: str
    title: str
    section: str
    status: str
    records: tuple[CheckRecord, ...]
    applies: bool
    not_applicable_reason: str = ""

    @property
    def passed(self) -> int:
        return sum(1 for r in self.records if r.passed)

    @property
    def failed(self) -> int:
        return sum(1 for r in self.records if not r.passed)


@dataclass(frozen=True)
class ParameterRow:
    mode: str
    number: int
    key: str
    name: str
    value: str
    default: str
    changed: bool
    certain: bool


@dataclass(frozen=True)
class CommissioningReport:
    """What the report shows, in the order it shows it."""

    title: str
    axis: str
    site: str
    operator: str
    created_utc: str
    actuator: Mapping[str, Any]
    driver: Mapping[str, str]
    procedures: tuple[ProcedureResult, ...]
    sensor_angles_deg: Mapping[str, float]
    sensor_range_note: str
    parameter_file: str
    parameters: tuple[ParameterRow, ...]
    plots: tuple[Mapping[str, str], ...]
    notes: tuple[Mapping[str, str], ...]
    warnings: tuple[str, ...]
    signature: Mapping[str, str] = field(default_factory=dict)

    @property
    def changed_parameters(self) -> tuple[ParameterRow, ...]:
        return tuple(p for p in self.parameters if p.changed)


def _context_for(session: ProcedureSession) -> Mapping[str, Any]:
    from fha_studio.logic.procedures.context import build_context

    return build_context(session.actuator_code)


def open_warnings(session: ProcedureSession, procedures: list[Procedure]) -> list[str]:
    """What stands between this session and a signed report, one line each."""
    warnings = []
    for procedure in procedures:
        if not procedure.applies:
            continue
        state = session.runs.get(procedure.id)
        if state is None or not state.records:
            warnings.append(f"{procedure.title} ({procedure.section}): not done")
            continue
        last = {}
        for record in state.records:
            last[record.step_id] = record
        # a step as the checklist words it (its id is for files)
        stopped = last[state.stop_step_id].text if state.stop_step_id in last else state.stop_step_id
        if state.status == STOPPED:
            warnings.append(f"{procedure.title}: stopped at '{stopped}': {state.stop_warning}")
        elif state.status != COMPLETED:
            status = str(state.status).replace("_", " ")
            warnings.append(f"{procedure.title} ({procedure.section}): not finished ({status})")
        for record in last.values():
            if not record.passed and not (state.status == STOPPED and record.step_id == state.stop_step_id):
                warnings.append(f"{procedure.title}: '{record.text}' failed and was not checked again")
    return warnings


def _parameter_rows(session: ProcedureSession) -> tuple[str, tuple[ParameterRow, ...], list[str]]:
    params = session.parameters or {}
    values: Mapping[str, Any] = params.get("values", {})
    if not values:
        return str(params.get("file", "")), (), []
    from fha_studio.hardware.parameters import driver_family, load_parameter_model

    model = load_parameter_model(driver_family(session.driver.get("model", "")))
    rows, problems = [], []
    for key, wire in values.items():
        try:
            item = model.by_key(key)
        except KeyError as exc:
            problems.append(f"parameter file: {exc.args[0]}")
            continue
        wire = int(wire)
        default = item.default
        panel = params.get("front_panel", {}).get(key)
        shown = item.format(wire)
        if panel:
            shown += f" (entered from the front panel by {panel.get('who', '?')}, {panel.get('time', '')})"
        rows.append(
            ParameterRow(
                mode=item.mode.value,
                number=item.number,
                key=item.key,
                name=item.name,
                value=shown,
                default="" if default is None else item.format(default),
                changed=default is not None and wire != default,
                certain=item.certain,
            )
        )
    rows.sort(key=lambda r: (r.mode, r.number))
    return str(params.get("file", "")), tuple(rows), problems


def report_title(axis: str, actuator_code: str) -> str:
    """The report's title: the axis and the actuator, the code once (an axis nobody named is
    called by its actuator's code, and a title saying it twice reads as two actuators)."""
    parts = [part for part in (axis.strip(), actuator_code.strip()) if part]
    if len(parts) == 2 and parts[1].upper() in parts[0].upper():
        parts.pop()
    return " — ".join(["Commissioning report", *parts])


def build_report(session: ProcedureSession, context: Mapping[str, Any] | None = None) -> CommissioningReport:
    """The report of ``session``; ``context`` defaults to the catalogue's for its actuator."""
    context = context if context is not None else _context_for(session)
    procedures = load_all(context)
    results = []
    for procedure in procedures:
        state = session.runs.get(procedure.id)
        results.append(
            ProcedureResult(
                id=procedure.id,
                title=procedure.title,
                section=procedure.section,
                status=(state.status if state else "not_started") if procedure.applies else "not applicable",
                records=tuple(state.records) if state else (),
                applies=procedure.applies,
                not_applicable_reason=procedure.not_applicable_reason,
            )
        )
    warnings = open_warnings(session, procedures)
    parameter_file, parameter_rows, parameter_problems = _parameter_rows(session)
    warnings.extend(parameter_problems)
    sensor_set = context.get("sensor_set", {})
    range_note = ""
    if context.get("flags", {}).get("sensor_set"):
        range_note = (
            f"movable range {sensor_set['ccw_limit_deg']:+g}° … {sensor_set['cw_limit_deg']:+g}° "
            f"({sensor_set.get('section', '4-7-3')})"
        )
        if sensor_set.get("certain") is False:
            range_note += " — assumed: the manual gives it only as a figure; check against the printed manual"
    for plot in session.plots:
        if not Path(plot["path"]).is_file():
            warnings.append(f"plot '{plot['title']}': file {plot['path']} is missing")
    return CommissioningReport(
        title=report_title(session.axis, session.actuator_code),
        axis=session.axis,
        site=session.site,
        operator=session.operator,
        created_utc=session.created_utc,
        actuator=dict(context.get("actuator", {})),
        driver=dict(session.driver),
        procedures=tuple(results),
        sensor_angles_deg=dict(session.sensor_angles_deg),
        sensor_range_note=range_note,
        parameter_file=parameter_file,
        parameters=parameter_rows,
        plots=tuple(session.plots),
        notes=tuple(session.notes),
        warnings=tuple(warnings),
        signature=dict(session.signature),
    )


def sign(
    session: ProcedureSession, who: str, context: Mapping[str, Any] | None = None, key_id: str = "",
    save: bool = True,
) -> None:
    """Sign the session's report; refused (SignError listing what is open) while anything is open.
    ``key_id``: the signer's key the report file is signed with (the register's
    ``sign_report_file`` signs it); without one the report is signed by name only. ``save``:
    the session file is saved (False: the caller saves it once the signed file is written)."""
    if not who.strip():
        raise SignError("a report is signed with a name")
    report = build_report(session, context)
    if report.warnings:
        raise SignError("cannot sign while these are open: " + "; ".join(report.warnings))
    session.signature = {"who": who.strip(), "at_utc": utc_now()}
    if key_id:
        session.signature["key_id"] = key_id
    if save and session.path is not None:
        session.save()


# -- HTML -----------------------------------------------------------------------------------------

_CSS = """
body { font-family: sans-serif; font-size: 10pt; }
h1 { font-size: 16pt; } h2 { font-size: 13pt; margin-top: 14pt; } h3 { font-size: 11pt; }
table { border-collapse: collapse; margin-bottom: 8pt; }
th, td { border: 1px solid #888; padding: 2pt 4pt; vertical-align: top; }
th { background: #e4e4e4; text-align: left; white-space: nowrap; }
.note { color: #444; font-size: 9pt; }
.pass { color: #176b1d; font-weight: bold; } .fail { color: #b00000; font-weight: bold; }
.warn { color: #b00000; }
"""


def _e(value: Any) -> str:
    return html.escape("" if value is None else str(value))


def value_text(record: CheckRecord) -> str:
    """A check's value as a person reads it: yes / no, or the value with its unit."""
    if record.kind == "confirm" or isinstance(record.value, bool):
        return "yes" if record.value else "no"
    if isinstance(record.value, float):
        return f"{record.value:g} {record.unit}".strip()
    return f"{record.value} {record.unit}".strip() if record.value is not None else ""


def _item(mode: str, number: int) -> str:
    """"parameter 8", "tune 2": an item as the driver's front panel names its mode and number."""
    try:
        return f"{MODE_WORDS[Mode(mode)]} {number}"
    except ValueError:
        return f"{mode} {number}"


def when_minutes(at_utc: str) -> str:
    """An ISO time as a person reads it on paper: '2026-11-30 03:56' (the column says UTC)."""
    text = str(at_utc or "")
    return text[:16].replace("T", " ") if len(text) >= 16 and text[10:11] == "T" else text


def _table(headers: list[str], rows: list[list[str]], widths: list[int] | None = None) -> str:
    """An HTML table; ``widths`` in per cent of the page, one per column."""
    if widths is None:
        head = "".join(f"<th>{h}</th>" for h in headers)
    else:
        head = "".join(f"<th width='{w}%'>{h}</th>" for h, w in zip(headers, widths, strict=True))
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows)
    return f'<table width="100%"><tr>{head}</tr>{body}</table>'


def render_html(report: CommissioningReport) -> str:
    """The report as one self-contained HTML document (images by file path)."""
    head = f"<meta charset='utf-8'><title>{_e(report.title)}</title><style>{_CSS}</style>"
    out = [f"<html><head>{head}</head><body>"]
    out.append(f"<h1>{_e(report.title)}</h1>")
    a, d = report.actuator, report.driver
    identity = [
        ["Axis", _e(report.axis)],
        ["Site", _e(report.site)],
        ["Actuator", _e(a.get("model_code", ""))],
        [
            "Frame / ratio / encoder",
            _e(f"{a.get('frame_name', '')} / 1:{a.get('ratio', '')} / {a.get('encoder', '')}"),
        ],
        ["Supply voltage", _e(f"{a.get('supply_voltage', '')} V")],
        ["Driver", _e(d.get("model", ""))],
        ["Driver adjusted for", _e(d.get("adjusted_for", ""))],
        ["Driver version", _e(d.get("version", ""))],
        ["Commissioned by", _e(report.operator)],
        ["Session started (UTC)", _e(when_minutes(report.created_utc))],
    ]
    out.append("<h2>Actuator and driver</h2>" + _table(["Item", "Value"], identity))

    out.append("<h2>Open warnings</h2>")
    if report.warnings:
        out.append("<ul>" + "".join(f"<li class='warn'>{_e(w)}</li>" for w in report.warnings) + "</ul>")
    else:
        out.append("<p class='pass'>No open warnings.</p>")

    out.append("<h2>Checklists</h2>")
    for result in report.procedures:
        status = _e(result.status.replace("_", " "))
        out.append(f"<h3>{_e(result.title)} ({_e(result.section)}) — {status}</h3>")
        if not result.applies:
            why = f": {_e(result.not_applicable_reason)}" if result.not_applicable_reason else ""
            out.append(f"<p>Does not apply to this actuator{why}.</p>")
            continue
        if not result.records:
            out.append("<p>Not done.</p>")
            continue
        rows = [
            [
                _e(r.section),
                _e(r.text),
                _e(value_text(r)),
                _e(r.expected),
                "<span class='pass'>pass</span>" if r.passed else "<span class='fail'>FAIL</span>",
                _e(r.who),
                _e(when_minutes(r.at_utc)),
                _e(r.detail),
            ]
            for r in result.records
        ]
        out.append(
            _table(
                ["§", "Check", "Value", "Expected", "Result", "Who", "When (UTC)", "Detail"],
                rows,
                [6, 33, 9, 9, 6, 10, 11, 16],
            )
        )

    out.append("<h2>Rotary position sensors (option L)</h2>")
    if report.sensor_angles_deg:
        rows = [
            [_e(SENSOR_NAMES.get(k, k)), _e(f"{v:+.2f}°")]
            for k, v in sorted(report.sensor_angles_deg.items())
        ]
        out.append(_table(["Sensor", "Output angle where it switches"], rows))
    else:
        out.append("<p>No sensor angles recorded.</p>")
    if report.sensor_range_note:
        out.append(f"<p>{_e(report.sensor_range_note)}</p>")

    out.append("<h2>Parameters</h2>")
    if report.parameter_file:
        out.append(f"<p>Parameter file: {_e(report.parameter_file)}</p>")
    if report.parameters:
        changed = report.changed_parameters
        out.append(f"<p>{len(changed)} of {len(report.parameters)} items differ from the defaults.</p>")
        if changed:
            rows = [[_e(_item(p.mode, p.number)), _e(p.name), _e(p.default), _e(p.value)] for p in changed]
            out.append(
                "<h3>Changed from the defaults</h3>" + _table(["Item", "Name", "Default", "Value"], rows)
            )
        rows = [
            [
                _e(_item(p.mode, p.number)),
                _e(p.name),
                _e(p.value),
                _e(p.default),
                "" if p.certain else "assumed *",
            ]
            for p in report.parameters
        ]
        out.append("<h3>All values</h3>" + _table(["Item", "Name", "Value", "Default", "Note"], rows))
        if any(not p.certain for p in report.parameters):
            out.append(
                "<p class='note'>* assumed: the public HA-655 manual does not state this item's range "
                "or default; the default shown is FHA Studio's assumption. The value itself is what "
                "the drive reported or the technician entered. Check assumed items against the "
                "driver's own manual or front panel.</p>"
            )
    else:
        out.append("<p>No parameters were read from the drive.</p>")

    out.append("<h2>Plots</h2>")
    if report.plots:
        for plot in report.plots:
            out.append(f"<p><b>{_e(plot['title'])}</b><br/><img src='{_e(plot['path'])}' width='900'/></p>")
    else:
        out.append("<p>No plots captured.</p>")

    if report.notes:
        out.append("<h2>Notes</h2>")
        rows = [
            [_e(when_minutes(n.get("at_utc", ""))), _e(n.get("who", "")), _e(n.get("text", ""))]
            for n in report.notes
        ]
        out.append(_table(["When (UTC)", "Who", "Note"], rows))

    out.append("<h2>Signature</h2>")
    if report.signature:
        out.append(f"<p>Signed by {_e(report.signature['who'])} at {_e(report.signature['at_utc'])} UTC.</p>")
        key_id = report.signature.get("key_id", "")
        if key_id:
            out.append(
                f"<p>Signed with {_e(report.signature['who'])}'s own key (Ed25519, key {_e(key_id)}): the "
                "signature covers every byte of the HTML report file and says who signed it and when. "
                "To check that a copy is the one that was signed, and by whom, run "
                "<b>fha-studio register verify REPORT</b> (REPORT: the HTML file, or its PDF) where the "
                "plant's register is; a changed byte fails it.</p>"
            )
        else:
            out.append(
                "<p class='note'>Signed by name only: there is no key behind this signature, so nothing "
                "shows whether this file is the one that was signed (a key of one's own: "
                "fha-studio register keys add --name NAME).</p>"
            )
    else:
        out.append("<p class='warn'>Not signed.</p>")
    out.append("</body></html>")
    return "\n".join(out)
