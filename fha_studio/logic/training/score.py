"""The trainee's score sheet: each hidden fault found or missed with the evidence recorded, the
expected steps in order or not, unsafe acts, and the time taken (docs/training.md).

What the trainee did comes from three places: the training drive's journal (every command and
panel action with the drive's state, :mod:`fha_studio.hardware.sim.journal`), the procedure
session (recorded checks) and the model check's findings; plus what the trainee wrote as findings.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime

from fha_studio.hardware.parameters import Mode
from fha_studio.hardware.protocol import Command, Status
from fha_studio.hardware.sim.journal import JournalEntry, PanelAction
from fha_studio.logic.procedures.session import COMPLETED, ProcedureSession
from fha_studio.logic.training.scenario import Evidence, EvidenceKind, ExpectedStep, Fault, Scenario

MOTION_COMMANDS = frozenset({Command.JOG, Command.MOV, PanelAction.CN2_MOVE})
#: repeats of one act closer than this are one act (a held jog sends JOG every 50 ms) [s]
EPISODE_GAP_S = 2.0


@dataclass(frozen=True)
class Seen:
    """A piece of evidence the trainee produced: when (UNIX s) and what, in plain words."""

    at_s: float
    text: str


@dataclass
class TraineeRecord:
    """Everything the trainee did in one training session."""

    started_s: float
    ended_s: float
    journal: Sequence[JournalEntry] = ()
    session: ProcedureSession | None = None
    model_check_effects: Sequence[tuple[str, float]] = ()  # (effect id, when it was named)
    findings: str = ""
    trainee: str = ""


@dataclass(frozen=True)
class FaultResult:
    fault: Fault
    evidence: tuple[Seen, ...]

    @property
    def found(self) -> bool:
        return bool(self.evidence)


@dataclass(frozen=True)
class StepResult:
    step: ExpectedStep
    done_at_s: float | None
    in_order: bool
    note: str = ""


@dataclass(frozen=True)
class UnsafeAct:
    what: str
    at_s: float
    times: int


@dataclass
class ScoreSheet:
    scenario: Scenario
    record: TraineeRecord
    faults: list[FaultResult] = field(default_factory=list)
    steps: list[StepResult] = field(default_factory=list)
    unsafe: list[UnsafeAct] = field(default_factory=list)

    @property
    def time_taken_s(self) -> float:
        return max(0.0, self.record.ended_s - self.record.started_s)

    @property
    def within_time_guide(self) -> bool:
        return self.time_taken_s <= self.scenario.time_guide_min * 60.0

    @property
    def found_count(self) -> int:
        return sum(1 for f in self.faults if f.found)

    def elapsed(self, at_s: float) -> str:
        """``at_s`` as minutes:seconds since the session began."""
        seconds = max(0, round(at_s - self.record.started_s))
        return f"{seconds // 60}:{seconds % 60:02d}"


def _utc_s(text: str) -> float:
    try:
        stamp = datetime.fromisoformat(text)
    except (TypeError, ValueError):
        return 0.0
    if stamp.tzinfo is None:
        stamp = stamp.replace(tzinfo=UTC)
    return stamp.timestamp()


def _step_matches(record_step: str, wanted: str) -> bool:
    # a step done once per table row is recorded as STEP#N (or STEP[N]): it counts for STEP
    return record_step == wanted or re.fullmatch(rf"{re.escape(wanted)}\W.*", record_step) is not None


def _item_text(item: tuple[str, int] | None) -> str:
    if item is None:
        return "an item"
    mode, number = item
    return f"{'parameter' if mode == Mode.SYSTEM else mode} item {number}"


def _journal(
    record: TraineeRecord, test: Callable[[JournalEntry], bool], text: Callable[[JournalEntry], str]
) -> list[Seen]:
    return [Seen(e.at_s, text(e)) for e in record.journal if test(e)]


def evidence_seen(evidence: Evidence, record: TraineeRecord) -> list[Seen]:
    """Every time the trainee produced ``evidence``, oldest first."""
    k = evidence.kind
    seen: list[Seen] = []
    if k is EvidenceKind.PROCEDURE:
        run = record.session.runs.get(evidence.procedure) if record.session else None
        if run is None:
            return []
        if evidence.completed:
            if run.status == COMPLETED:
                seen.append(Seen(_utc_s(run.finished_utc), f"completed the {evidence.procedure} procedure"))
            return seen
        for r in run.records:
            if evidence.step and not _step_matches(r.step_id, evidence.step):
                continue
            if evidence.passed is not None and r.passed != evidence.passed:
                continue
            if (
                evidence.value is not None
                and str(r.value).strip().lower() != str(evidence.value).strip().lower()
            ):
                continue
            value = "" if r.value is None else f": {r.value} {r.unit}".rstrip()
            seen.append(
                Seen(_utc_s(r.at_utc), f"recorded {r.text[:80]}{value} ({'pass' if r.passed else 'fail'})")
            )
        return seen
    if k is EvidenceKind.PARAMETER_READ:
        return _journal(
            record,
            lambda e: e.command is Command.PRD and e.terminal is Status.DONE and e.item == evidence.item,
            lambda e: f"read {_item_text(e.item)}",
        )
    if k is EvidenceKind.PARAMETER_WRITTEN:

        def wrote(e: JournalEntry) -> bool:
            return (
                e.command is Command.PWR
                and e.terminal is Status.DONE
                and e.item == evidence.item
                and (evidence.value is None or e.value == evidence.value)
                and (evidence.minimum is None or e.value >= evidence.minimum)
                and (evidence.maximum is None or e.value <= evidence.maximum)
            )

        return _journal(record, wrote, lambda e: f"wrote {_item_text(e.item)} = {e.value}")
    if k is EvidenceKind.ALARM_SEEN:
        first = [
            e for e in record.journal if e.alarm_after == evidence.code or e.alarm_before == evidence.code
        ][:1]
        return [Seen(e.at_s, f"alarm {evidence.code} came up") for e in first]
    if k is EvidenceKind.ALARM_CLEARED:
        return _journal(
            record,
            lambda e: (
                e.command in (Command.ACL, Command.PWC)
                and e.alarm_before == evidence.code
                and e.terminal is Status.DONE
            ),
            lambda e: f"cleared alarm {evidence.code} "
            f"({'reset' if e.command is Command.ACL else 'power cycle'})",
        )
    if k is EvidenceKind.MULTI_TURN_CLEARED:
        return _journal(
            record,
            # None: the q comes 5 s later
            lambda e: e.command is Command.OWW and e.terminal in (Status.DONE, None),
            lambda e: "cleared the multi-turn data",
        )
    if k is EvidenceKind.JOG:

        def jogged(e: JournalEntry) -> bool:
            if e.command not in MOTION_COMMANDS or e.terminal is not Status.DONE or e.value == 0:
                return False
            return evidence.direction == "" or (e.value > 0) == (evidence.direction == "fwd")

        hits = _journal(record, jogged, lambda e: f"moved the axis {'FWD' if e.value > 0 else 'REV'}")
        return _episodes(hits)
    if k is EvidenceKind.MODEL_CHECK:
        return [
            Seen(at, f"the model check named {effect.replace('_', ' ')}")
            for effect, at in record.model_check_effects
            if effect == evidence.effect
        ]
    if k is EvidenceKind.SAID:
        text = record.findings.lower()
        words = [w for w in evidence.words if w.lower() in text]
        return [Seen(record.ended_s, f"wrote in the findings: {', '.join(words)}")] if words else []
    return []


def _episodes(seen: list[Seen]) -> list[Seen]:
    """The first of each run of repeats (entries closer than EPISODE_GAP_S)."""
    out: list[Seen] = []
    last = -float("inf")
    for s in seen:
        if s.at_s - last > EPISODE_GAP_S:
            out.append(s)
        last = s.at_s
    return out


def _any_seen(evidence: Sequence[Evidence], record: TraineeRecord) -> list[Seen]:
    seen = [s for e in evidence for s in evidence_seen(e, record)]
    return sorted(seen, key=lambda s: s.at_s)


def unsafe_acts(record: TraineeRecord) -> list[UnsafeAct]:
    """Writing parameters with the servo on, moving with the brake applied, jogging into an
    active limit switch or inhibit input; each run of repeats counted once."""
    kinds: list[tuple[str, Callable[[JournalEntry], bool]]] = [
        ("Wrote a parameter with the servo on", lambda e: e.command is Command.PWR and e.servo_on),
        (
            "Moved the axis with the brake applied",
            lambda e: e.command in MOTION_COMMANDS and e.value != 0 and e.servo_on and e.brake_holding,
        ),
        (
            "Jogged towards an active limit switch or inhibit input",
            lambda e: (
                e.command in MOTION_COMMANDS
                and e.servo_on
                and ((e.value > 0 and e.blocked_fwd) or (e.value < 0 and e.blocked_rev))
            ),
        ),
    ]
    acts = []
    for what, test in kinds:
        hits = [Seen(e.at_s, what) for e in record.journal if test(e)]
        episodes = _episodes(hits)
        if episodes:
            acts.append(UnsafeAct(what, episodes[0].at_s, len(episodes)))
    return sorted(acts, key=lambda a: a.at_s)


def score(scenario: Scenario, record: TraineeRecord) -> ScoreSheet:
    """The score sheet of ``record`` against ``scenario``."""
    sheet = ScoreSheet(scenario, record)
    for fault in scenario.faults:
        sheet.faults.append(FaultResult(fault, tuple(_any_seen(fault.found_by, record))))
    done: list[float | None] = []
    for step in scenario.steps:
        seen = _any_seen(step.done_by, record)
        done.append(seen[0].at_s if seen else None)
    for i, step in enumerate(scenario.steps):
        at = done[i]
        if at is None:
            sheet.steps.append(StepResult(step, None, False, "not done"))
            continue
        late = [scenario.steps[j].title for j in range(i) if done[j] is None or done[j] > at]  # type: ignore[operator]
        note = f"before: {', '.join(late)}" if late else ""
        sheet.steps.append(StepResult(step, at, not late, note))
    sheet.unsafe = unsafe_acts(record)
    return sheet


__all__ = [
    "FaultResult",
    "ScoreSheet",
    "Seen",
    "StepResult",
    "TraineeRecord",
    "UnsafeAct",
    "evidence_seen",
    "score",
    "unsafe_acts",
]
