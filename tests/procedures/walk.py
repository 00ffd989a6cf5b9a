"""Helpers: the passing answer to a step, and walking a whole procedure with them."""

from __future__ import annotations

from fha_studio.logic.procedures import Observation, ProcedureRun, Step

SENSOR_ANGLES = {"limit_switch_2": 120.0, "limit_switch_1": -120.0, "origin_sensor": 0.0}


def good_answer(step: Step):
    if step.kind == "confirm":
        return True
    if step.kind == "measure":
        low = step.minimum if step.minimum is not None else (step.maximum or 0) - 10
        high = step.maximum if step.maximum is not None else low + 10
        return (low + high) / 2
    if step.kind == "text":
        return step.expect_any[0] if step.expect_any else step.expect
    if step.kind == "choose":
        return step.expect if step.expect is not None else step.choices[0]
    if step.kind == "live":
        return Observation(step.expect if step.expect is not None else True, True, "seen")
    if step.kind == "sensor_angle":
        return SENSOR_ANGLES[step.sensor]
    raise AssertionError(step.kind)


def walk(run: ProcedureRun, who: str = "T. Trainee", limit: int = 200) -> list[str]:
    """Answer every step with its passing answer; returns the step ids answered."""
    answered = []
    while (step := run.current()) is not None and len(answered) < limit:
        record = run.submit(good_answer(step), who=who)
        assert record.passed, (step.id, record)
        answered.append(step.id)
    return answered
