"""The model check's entry point: a recording with the motor current goes through the torque channel
(workflow.py); one without it, a bench capture, through the closed loop (without_current.py)."""

from __future__ import annotations

from fha_studio.logic.modelcheck.axis import check_plausible, declared_axis
from fha_studio.logic.modelcheck.result import ModelCheckResult
from fha_studio.logic.modelcheck.without_current import run_without_current
from fha_studio.logic.modelcheck.workflow import run_modelcheck as run_with_current
from fha_studio.physics import ServoSettings
from fha_studio.recording import Recording


def run_modelcheck(
    rec: Recording, *, window: int | None = None, resimulate: bool = True, servo: ServoSettings | None = None
) -> ModelCheckResult:
    """Run the whole model check on a recording (see workflow.run_modelcheck for the arguments).
    Without a current column the loop is identified from the recording; ``servo`` (the panel's
    values, when known) is then compared with it, never taken for it, and ``window`` is not used."""
    if rec.has_current:
        return run_with_current(rec, window=window, resimulate=resimulate, servo=servo)
    axis = declared_axis(rec)
    notes = check_plausible(rec, axis)
    return run_without_current(rec, axis, notes, servo=servo, resimulate=resimulate)
