"""The score sheet as HTML in the commissioning report's format, marked as training (the GUI
prints it to PDF with the report's printer)."""

from __future__ import annotations

from datetime import UTC, datetime

from fha_studio.logic.procedures.report import _CSS, _e, _table
from fha_studio.logic.training.score import ScoreSheet

TRAINING_MARK = "TRAINING — a simulated drive; not a commissioning record"


def sheet_title(sheet: ScoreSheet) -> str:
    return f"Training score sheet: {sheet.scenario.title}"


def _clock(seconds: float) -> str:
    minutes, secs = divmod(max(0, round(seconds)), 60)
    return f"{minutes} min {secs:02d} s"


def _utc(at_s: float) -> str:
    return datetime.fromtimestamp(at_s, UTC).strftime("%Y-%m-%d %H:%M")


def render_sheet_html(sheet: ScoreSheet) -> str:
    """The sheet as one self-contained HTML document."""
    s, rec = sheet.scenario, sheet.record
    title = sheet_title(sheet)
    style = f"{_CSS} .mark {{ color: #8a5a00; font-weight: bold; }}"
    head = f"<meta charset='utf-8'><title>{_e(title)}</title><style>{style}</style>"
    out = [
        f"<html><head>{head}</head><body>",
        f"<p class='mark'>{_e(TRAINING_MARK)}</p>",
        f"<h1>{_e(title)}</h1>",
    ]
    guide = f"{s.time_guide_min:g} min"
    taken = _clock(sheet.time_taken_s)
    identity = [
        ["Scenario", _e(f"{s.title} ({s.level})")],
        ["Actuator", _e(s.actuator)],
        ["Driver", _e(s.driver or "as the combination table gives")],
        ["Trainee", _e(rec.trainee or "not given")],
        ["Started (UTC)", _e(_utc(rec.started_s))],
        [
            "Time taken",
            f"{_e(taken)} (guide {_e(guide)}) "
            + (
                "<span class='pass'>within the guide</span>"
                if sheet.within_time_guide
                else "<span class='fail'>over the guide</span>"
            ),
        ],
        ["Faults found", _e(f"{sheet.found_count} of {len(sheet.faults)}")],
    ]
    out.append("<h2>Session</h2>" + _table(["Item", "Value"], identity, [30, 70]))

    out.append("<h2>Hidden faults</h2>")
    rows = []
    for f in sheet.faults:
        result = "<span class='pass'>found</span>" if f.found else "<span class='fail'>missed</span>"
        if f.found:
            evidence = "<br>".join(f"{_e(sheet.elapsed(x.at_s))} {_e(x.text)}" for x in f.evidence[:6])
        else:
            evidence = (
                "<span class='note'>Would have counted: "
                + _e("; ".join(e.describe() for e in f.fault.found_by))
                + "</span>"
            )
        rows.append(
            [
                f"<b>{_e(f.fault.title)}</b><br><span class='note'>{_e(f.fault.explanation)}</span>",
                result,
                evidence,
            ]
        )
    out.append(_table(["Fault", "Result", "Evidence the trainee recorded (min:s)"], rows, [42, 10, 48]))

    out.append("<h2>Steps in the expected order</h2>")
    rows = []
    for n, st in enumerate(sheet.steps, start=1):
        if st.done_at_s is None:
            when, order = "", "<span class='fail'>not done</span>"
        else:
            when = _e(sheet.elapsed(st.done_at_s))
            order = (
                "<span class='pass'>in order</span>"
                if st.in_order
                else f"<span class='warn'>out of order</span> <span class='note'>({_e(st.note)})</span>"
            )
        rows.append([str(n), _e(st.step.title), when, order])
    out.append(_table(["#", "Step", "Done at (min:s)", "Order"], rows, [5, 50, 15, 30]))

    out.append("<h2>Unsafe acts</h2>")
    if sheet.unsafe:
        rows = [[_e(a.what), _e(sheet.elapsed(a.at_s)), _e(str(a.times))] for a in sheet.unsafe]
        out.append(_table(["What", "First at (min:s)", "Times"], rows, [60, 20, 20]))
    else:
        out.append("<p class='pass'>None.</p>")

    out.append("<h2>The trainee's findings</h2>")
    text = rec.findings.strip()
    out.append(f"<p>{_e(text).replace(chr(10), '<br>')}</p>" if text else "<p class='note'>None written.</p>")
    out.append("<h2>What the trainee was told</h2>")
    out.append(f"<p>{_e(s.briefing).replace(chr(10), '<br>')}</p>")
    out.append("</body></html>")
    return "\n".join(out)


__all__ = ["TRAINING_MARK", "render_sheet_html", "sheet_title"]
