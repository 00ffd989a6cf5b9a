"""What the rest of the commissioning gives a report, brought into the session (no Qt).

Before a report is built or signed, the session takes what was done elsewhere: the drive's
identity, the parameter values known (read from the drive, else entered from its front panel, with
the parameter file of them written beside the session), the rotary-direction check confirmed on the
Rotary direction page (as the 1-10 procedure, unless it was walked as a procedure) and the checks
of the DGR checks page (as notes, each once). The GUI gathers these from its pages as
:class:`ReportInputs`, plain data; :func:`collect_for_report` decides what goes where.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol

from fha_studio import fileio
from fha_studio.hardware.parameters import ParameterModel
from fha_studio.logic.absolute import CHECK_TITLES, DgrCheckRecord
from fha_studio.logic.procedures.direction_check import DirectionCheck, record_direction_check
from fha_studio.logic.procedures.session import ProcedureSession

log = logging.getLogger(__name__)

#: A parameter by (mode, number), as the drive numbers it.
ItemNumber = tuple[str, int]


class PanelEntry(Protocol):
    """A value entered from the drive's front panel: who entered it and when."""

    @property
    def who(self) -> str: ...

    @property
    def time(self) -> str: ...


@dataclass(frozen=True)
class ReportInputs:
    """What the other pages know that the report shows.

    ``driver``: the drive's identity (``model``, ``adjusted_for``, ``version``, ``url``; empty
    without a link). ``values``: the items' wire values as known (read, else entered from the
    front panel); ``read``: which of them were read from the drive; ``front_panel``: who entered
    each value from the panel, and when. ``parameter_file_text``: the parameter file of those
    values. ``direction_check``: the last check of the Rotary direction page. ``dgr_checks``: the
    DGR checks page's records. ``tuning_notes``: the Tuning page's before / after (text, who).
    ``who``: the operator, for a direction check without a name."""

    who: str
    parameter_model: ParameterModel
    driver: Mapping[str, str] = field(default_factory=dict)
    values: Mapping[ItemNumber, int] = field(default_factory=dict)
    read: Collection[ItemNumber] = ()
    front_panel: Mapping[ItemNumber, PanelEntry] = field(default_factory=dict)
    parameter_file_text: str = ""
    direction_check: DirectionCheck | None = None
    dgr_checks: Sequence[DgrCheckRecord] = ()
    #: the Tuning page's measurements before and after, as notes (text, who)
    tuning_notes: Sequence[tuple[str, str]] = ()


def collect_for_report(session: ProcedureSession, inputs: ReportInputs) -> bool:
    """Brings ``inputs`` into ``session`` and saves it (when it has a file). True when the
    rotary-direction check became the 1-10 procedure's run (the procedures shown changed)."""
    direction = inputs.direction_check
    walked = direction is not None and record_direction_check(
        session, dataclasses.replace(direction, who=direction.who or inputs.who)
    )
    if inputs.driver:
        session.driver = dict(inputs.driver)
    if inputs.values:
        session.parameters = _parameters(session, inputs)
    for text, who in [*dgr_check_notes(inputs.dgr_checks), *inputs.tuning_notes]:
        if text not in {n.get("text", "") for n in session.notes}:
            session.add_note(text, who=who)
    if session.path:
        session.save()
    return walked


def dgr_check_notes(records: Sequence[DgrCheckRecord]) -> list[tuple[str, str]]:
    """The DGR checks page's records as the report's notes: (text, who), with the time, how the
    values came (with DGR or entered by hand) and the verdict."""
    notes = []
    for record in records:
        verdict = {True: "pass", False: "FAIL", None: "recorded"}[record.passed]
        how = ", entered by hand" if record.by_hand else (
            ", from CN2 on a bench instrument" if record.check.startswith("bench_") else ", with DGR")
        title = CHECK_TITLES.get(record.check, record.check)
        notes.append((f"{title} ({record.at}{how}): {verdict}: {record.detail}", record.who))
    return notes


def _parameters(session: ProcedureSession, inputs: ReportInputs) -> dict[str, object]:
    """The session's ``parameters``: the values by key, the parameter file written beside the
    session ("" when there is none or it could not be written: the report says it is missing), who
    entered from the front panel what was not read."""
    model = inputs.parameter_model
    by_key = {}
    for (mode, number), wire in inputs.values.items():
        try:
            by_key[model.item(mode, number).key] = int(wire)
        except (KeyError, ValueError, TypeError):
            continue
    path = session.path.with_suffix(".params") if session.path else None
    if path is not None:
        try:
            fileio.write_text(path, inputs.parameter_file_text)
        except (OSError, ValueError) as exc:  # the report still goes out, saying the file is missing
            log.warning("parameter file not written: %s", exc)
            path = None
    panel = {}
    for (mode, number), entry in inputs.front_panel.items():
        if (mode, number) in inputs.read:
            continue
        try:
            panel[model.item(mode, number).key] = {"who": entry.who, "time": entry.time}
        except (KeyError, ValueError):
            continue
    return {"file": str(path or ""), "values": by_key, "front_panel": panel}
