"""The procedure engine: walk a procedure's steps for one axis, record every check, stop on a failure.

Usage (no Qt; the GUI and the CLI drive the same object)::

    run = ProcedureRun(session, load_procedure("wiring", context))
    while (step := run.current()) is not None:
        run.submit(answer_for(step), who="A. Trainee")      # raises StepInputError on bad input
        if run.stopped:
            show(run.state.stop_warning); run.retry(who)    # or leave it stopped

A failed check stops the run with the manual's warning; :meth:`ProcedureRun.retry` reopens the
step (the failed record stays in the history and in the report). Every submit saves the session
when it has a file, so a run can be resumed after a restart by building a new ``ProcedureRun``
on the loaded session.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from fha_studio.logic.procedures import sensor_dogs
from fha_studio.logic.procedures.definitions import Procedure, ProcedureError, Step
from fha_studio.logic.procedures.session import (
    COMPLETED,
    NOT_STARTED,
    PAUSED,
    RUNNING,
    STOPPED,
    CheckRecord,
    ProcedureSession,
    RunState,
    utc_now,
)


class StepInputError(ValueError):
    """An answer that is not an answer to this step (nothing is recorded)."""


@dataclass(frozen=True)
class Observation:
    """What a live check saw on the drive: the value, whether it passes, and a line for the record."""

    value: Any
    passed: bool
    detail: str = ""
    available: bool = True  # False: the drive cannot tell; the step is confirmed by hand instead


def normalise_label(text: str) -> str:
    """Label text compared without case, spaces, dashes or underscores (``fha-25c-50`` = ``FHA 25C 50``)."""
    return re.sub(r"[\s\-_]+", "", str(text)).upper()


class ProcedureRun:
    """One procedure walked in one session. State lives in ``session.runs[procedure.id]``."""

    def __init__(self, session: ProcedureSession, procedure: Procedure, autosave: bool = True):
        if not procedure.applies:
            raise ProcedureError(f"procedure '{procedure.id}' does not apply to {session.actuator_code}")
        self.session = session
        self.procedure = procedure
        self.autosave = autosave
        state = session.run(procedure.id)
        ids = procedure.step_ids()
        if state.status == NOT_STARTED and not state.records:
            state.step_ids = ids
        elif state.step_ids != ids:
            raise ProcedureError(
                f"procedure '{procedure.id}' has changed since this session was saved "
                f"(steps {len(state.step_ids)} then, {len(ids)} now): start it again in a new session"
            )
        self.state: RunState = state
        if state.status == PAUSED:
            state.status = RUNNING  # resumed

    # -- where we are ---------------------------------------------------------------------------

    @property
    def stopped(self) -> bool:
        return self.state.status == STOPPED

    @property
    def completed(self) -> bool:
        return self.state.status == COMPLETED

    @property
    def context(self) -> Mapping[str, Any]:
        return self.procedure.context

    def _skip_inapplicable(self) -> None:
        steps = self.procedure.steps
        while self.state.position < len(steps) and not steps[self.state.position].applies(
            self.context, self.state.answers
        ):
            self.state.position += 1
        if self.state.position >= len(steps) and self.state.status in (RUNNING, NOT_STARTED):
            self.state.status = COMPLETED
            self.state.finished_utc = self.state.finished_utc or utc_now()

    def current(self) -> Step | None:
        """The step waiting for an answer (filled in), or None when the run is complete."""
        if self.state.status == COMPLETED:
            return None
        self._skip_inapplicable()
        if self.state.status == COMPLETED:
            return None
        definition = self.procedure.steps[self.state.position]
        return definition.resolve(self.context, self.state.answers)

    def progress(self) -> tuple[int, int]:
        """(steps answered, steps that apply so far) for a progress bar."""
        applicable = [s for s in self.procedure.steps if s.applies(self.context, self.state.answers)]
        done = sum(1 for s in applicable if self.procedure.step_ids().index(s.id) < self.state.position)
        return done, len(applicable)

    # -- answering ------------------------------------------------------------------------------

    def submit(self, value: Any, who: str = "", detail: str = "") -> CheckRecord:
        """Answer the current step. Returns the record; a failed check stops the run.

        ``value`` by kind: confirm -> bool; measure -> number; text -> str; choose -> one of the
        choices; live -> an :class:`Observation`; sensor_angle -> angle in degrees (number) or an
        :class:`Observation` whose value is the angle.
        """
        if self.state.status == STOPPED:
            raise StepInputError(
                f"'{self.procedure.title}' is stopped at '{self.state.stop_step_id}': "
                f"{self.state.stop_warning}"
            )
        step = self.current()
        if step is None:
            raise StepInputError(f"'{self.procedure.title}' is complete: nothing to answer")
        if self.state.status == NOT_STARTED:
            self.state.started_utc = utc_now()
        self.state.status = RUNNING
        recorded_value, passed, more = self._evaluate(step, value)
        record = CheckRecord(
            procedure_id=self.procedure.id,
            step_id=step.id,
            kind=step.kind,
            section=step.section,
            text=step.text,
            value=recorded_value,
            expected=step.expected_text(),
            unit=step.unit,
            passed=passed,
            who=who or self.session.operator,
            at_utc=utc_now(),
            detail="; ".join(d for d in (more, detail) if d),
        )
        self.state.records.append(record)
        if passed or not step.stop_on_fail:
            self.state.answers[step.id] = recorded_value
            if step.kind == "sensor_angle":
                self.session.sensor_angles_deg[step.sensor] = float(recorded_value)
            self.state.position += 1
            self._skip_inapplicable()
        else:
            self.state.status = STOPPED
            self.state.stop_step_id = step.id
            self.state.stop_warning = step.warning or "The check failed: do not go on before it is put right."
        self._save()
        return record

    def _evaluate(self, step: Step, value: Any) -> tuple[Any, bool, str]:
        kind = step.kind
        if kind == "confirm":
            if not isinstance(value, bool):
                raise StepInputError(f"step '{step.id}' needs yes or no, not {value!r}")
            return value, value, ""
        if kind == "measure":
            number = _number(value, step)
            low_ok = step.minimum is None or number >= step.minimum
            high_ok = step.maximum is None or number <= step.maximum
            return number, low_ok and high_ok, ""
        if kind == "text":
            text = str(value).strip()
            if not text:
                raise StepInputError(f"step '{step.id}' needs the text read off the label")
            wanted = (
                [step.expect] if step.expect is not None and not step.expect_any else list(step.expect_any)
            )
            passed = normalise_label(text) in {normalise_label(w) for w in wanted}
            return text, passed, ""
        if kind == "choose":
            choice = str(value)
            if choice not in step.choices:
                raise StepInputError(f"step '{step.id}': {choice!r} is not one of {', '.join(step.choices)}")
            if step.expect is None:
                return choice, True, ""
            wanted = step.expect if isinstance(step.expect, list) else [step.expect]
            return choice, choice in [str(w) for w in wanted], ""
        if kind == "live":
            if isinstance(value, bool):  # the drive cannot tell: a person checked it
                return value, value, "confirmed by hand"
            if not isinstance(value, Observation):
                raise StepInputError(f"live step '{step.id}' takes what the drive showed, or yes/no by hand")
            if not value.available:
                raise StepInputError(f"live step '{step.id}': {value.detail}")
            return _plain(value.value), bool(value.passed), value.detail
        if kind == "sensor_angle":
            seen = value if isinstance(value, Observation) else None
            angle = _number(seen.value if seen else value, step)
            problem = sensor_dogs.angle_problem(
                step.sensor, angle, self.context, self.session.sensor_angles_deg
            )
            passed = problem == "" and (seen is None or seen.passed)
            detail = problem or (seen.detail if seen else "")
            return angle, passed, detail
        raise ProcedureError(f"step '{step.id}' has unknown kind '{kind}'")

    # -- stop, retry, pause ---------------------------------------------------------------------

    def retry(self, who: str = "", note: str = "") -> None:
        """After a stop: the cause was put right, answer the stopped step again."""
        if self.state.status != STOPPED:
            return
        self.session.add_note(
            f"{self.procedure.title}: step '{self.state.stop_step_id}' retried"
            + (f": {note}" if note else ""),
            who,
        )
        self.state.status = RUNNING
        self.state.stop_step_id = ""
        self.state.stop_warning = ""
        self._save()

    def pause(self) -> None:
        """Leave the run where it is; the session file keeps the place."""
        if self.state.status == RUNNING:
            self.state.status = PAUSED
        self._save()

    def _save(self) -> None:
        if self.autosave and self.session.path is not None:
            self.session.save()


def _plain(value: Any) -> Any:
    # What JSON can hold: the session file must take every recorded value.
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if value is None or isinstance(value, bool | int | float | str):
        return value
    return str(value)


def _number(value: Any, step: Step) -> float:
    try:
        number = float(str(value).replace(",", ".")) if not isinstance(value, int | float) else float(value)
    except ValueError:
        raise StepInputError(
            f"step '{step.id}' needs a number{f' in {step.unit}' if step.unit else ''}, not {value!r}"
        ) from None
    if not math.isfinite(number) or isinstance(value, bool):
        raise StepInputError(f"step '{step.id}' needs a finite number, not {value!r}")
    return number
