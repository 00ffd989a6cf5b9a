"""The rotary-direction check (FHA-C manual 1-10) done on the Rotary direction page counts as the
procedure: the report must not say "not started" for a check the technician confirmed there."""

from __future__ import annotations

from dataclasses import dataclass

from fha_studio.logic.procedures.session import (
    COMPLETED,
    STOPPED,
    CheckRecord,
    ProcedureSession,
    RunState,
    utc_now,
)

PROCEDURE_ID = "rotary-direction"
SECTION = "1-10"


@dataclass(frozen=True)
class DirectionCheck:
    """What the page saw: parameter 8 on the drive, the direction it means ("CW"/"CCW", seen from
    the output flange), the direction the technician saw on a FWD jog, who and when (UTC)."""

    parameter_value: int
    expected: str
    seen: str
    who: str
    at_utc: str = ""

    @property
    def passed(self) -> bool:
        return self.seen == self.expected


def record_direction_check(session: ProcedureSession, check: DirectionCheck) -> bool:
    """Write ``check`` into ``session`` as the 1-10 procedure's run, unless that procedure was
    walked on the Procedures page already (its own answers win). True when written."""
    current = session.runs.get(PROCEDURE_ID)
    if current is not None and current.status == COMPLETED and not _from_page(current):
        return False
    at = check.at_utc or utc_now()
    where = "on the Rotary direction page"

    def record(
        step_id: str, kind: str, text: str, value: object, expected: str, passed: bool, detail: str
    ) -> CheckRecord:
        return CheckRecord(PROCEDURE_ID, step_id, kind, SECTION, text, value, expected, "", passed,
                           check.who, at, detail)

    records = [
        record("fwd_direction", "choose", "Which way must a FWD command turn the output?", check.expected,
               "CW or CCW", True, f"as parameter 8 = {check.parameter_value} says ({where})"),
        record("parameter", "live", "Parameter 8 (rotary direction) on the drive", check.parameter_value,
               str(check.parameter_value), True, f"read from the drive ({where})"),
        record("jog-fwd", "live", "The axis turns in the FWD direction at low speed", True, "yes", True,
               f"Jog FWD briefly ({where})"),
        record("seen-direction", "choose", "Viewing the output flange, which way did the output turn?",
               check.seen, check.expected, check.passed, where),
    ]
    run = RunState(PROCEDURE_ID, step_ids=[r.step_id for r in records], position=len(records),
                   answers={"fwd_direction": check.expected, "seen-direction": check.seen}, records=records,
                   started_utc=at, finished_utc=at)
    run.status = COMPLETED if check.passed else STOPPED
    if not check.passed:
        run.stop_step_id = "seen-direction"
        run.stop_warning = (
            f"The output turned {check.seen} on a FWD command, but parameter 8 = {check.parameter_value} "
            f"means {check.expected}. Change parameter 8 (or the wiring), power-cycle and check again."
        )
    session.runs[PROCEDURE_ID] = run
    return True


def _from_page(run: RunState) -> bool:
    where = "on the Rotary direction page"
    return any(r.detail == where or r.detail.endswith(f"{where})") for r in run.records)


__all__ = ["DirectionCheck", "record_direction_check"]
