"""Procedure steps answered by a move seen on the bench (no Qt).

A real HA-655 answers CN3 with ``s`` while its servo is on, so a step that needs the axis to move
under the controller cannot ask the drive. A bench instrument on CN2 sees the move all the same:
the command pulses the controller sent and the encoder outputs. A step marked ``bench = KIND`` in
its procedure file is answered by the checks the Scope's Bench tab takes of such a move
(:func:`fha_studio.logic.bench.checks.bench_checks`, the same checks the DGR checks page records):

- ``direction`` (a live step: the axis turns FWD): a FWD command, and the encoder outputs counted
  the same way (``bench_direction``);
- ``flange`` (a CW/CCW choice: which way did the output turn on a FWD command): from the encoder
  outputs and parameter 8 (FHA-C manual 1-10), in the manual's words;
- ``encoder`` (a live step: the feedback follows a move): the encoder outputs counted what the
  command asked for (``bench_encoder``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from fha_studio.logic.bench.checks import BenchCheck, flange_direction, in_command_sense
from fha_studio.logic.procedures.definitions import Procedure, Step
from fha_studio.logic.procedures.engine import Observation
from fha_studio.logic.procedures.session import RunState

KINDS = ("direction", "flange", "encoder")

#: What a step of each kind asks of the technician while the bench watches.
PROMPTS = {
    "direction": "have the controller give servo-ON and a short FWD command: this step is taken from the "
                 "encoder outputs once the move has settled",
    "flange": "a FWD command's move answers this step from the encoder outputs and parameter 8 (1-10)",
    "encoder": "have the controller give servo-ON and a short move: this step is taken from the encoder "
               "outputs (they must count what the command asked for) once the move has settled",
}


def bench_kind(step: Step | None) -> str:
    """The step's ``bench`` kind ("" when a bench move does not answer it)."""
    if step is None:
        return ""
    kind = str(step.params.get("bench", ""))
    return kind if kind in KINDS else ""


@dataclass(frozen=True)
class BenchAnswer:
    """What a bench move gives a step: ``value`` (an Observation for a live step, "CW" or "CCW"
    for a choice) and ``detail`` for the record; ``value`` None: it does not answer the step, and
    ``detail`` says why."""

    value: Any
    detail: str

    @property
    def answers(self) -> bool:
        return self.value is not None


def answer_from_bench(step: Step, checks: Sequence[BenchCheck], parameter_8: int | None) -> BenchAnswer:
    """The answer a move's checks give ``step`` (see the module's text)."""
    by = {c.check: c for c in checks}
    kind = bench_kind(step)
    if not kind:
        return BenchAnswer(None, f"step '{step.id}' is not taken from the bench")
    if kind == "encoder":
        encoder = by.get("bench_encoder")
        if encoder is None or encoder.passed is None:
            return BenchAnswer(None, encoder.detail if encoder else "the move gave no encoder check")
        values = encoder.values
        value = f"{values['encoder_counts']:+.0f} counts for {values['command_counts']:+.0f} commanded"
        return BenchAnswer(Observation(value, bool(encoder.passed), f"from CN2: {encoder.detail}"), "")
    direction = by.get("bench_direction")
    if direction is None:  # no command pulses came, or the outputs' sense needs parameter 8
        why = next((c.detail for c in checks), "the move gave no checks")
        return BenchAnswer(None, f"not taken from the bench: {why}")
    values = direction.values
    if values["command"] != "FWD":
        return BenchAnswer(None, f"a REV command came ({values['command_counts']:+.0f} counts): this step "
                           "wants a FWD command from the controller; if it gave FWD, its FWD and REV lines "
                           "into CN2 (or the command channels on the bench) are swapped")
    if kind == "direction":
        value = (f"{values['counted']} ({values['encoder_counts']:+.0f} counts for "
                 f"{values['command_counts']:+.0f} commanded)")
        return BenchAnswer(Observation(value, bool(direction.passed), f"from CN2: {direction.detail}"), "")
    moved = in_command_sense(float(values["encoder_counts"]), parameter_8)
    turned = flange_direction(moved, parameter_8) if moved is not None else None
    if turned is None:
        why = "the axis did not turn" if not values["encoder_counts"] else \
            "which way the output flange turned needs parameter 8: record it first (from the drive's panel)"
        return BenchAnswer(None, f"not taken from the bench: {why}")
    rotation, flange = turned
    return BenchAnswer(flange, f"from the encoder outputs on the bench: a FWD command turned the axis "
                       f"{values['counted']} ({values['encoder_counts']:+.0f} counts), with parameter 8 = "
                       f"{parameter_8}: {rotation}, {flange} viewing the output flange (1-10), on "
                       f"{values['source']}")


def parameter_8_of_run(procedure: Procedure, state: RunState) -> int | None:
    """Parameter 8 as the run's rotary-direction check recorded it last (read from the drive or
    entered from its panel), None when it has none or the value is not 0 or 1."""
    for record in reversed(state.records):
        try:
            check = procedure.step(record.step_id).raw.get("check")
        except KeyError:
            continue
        if check == "rotary_direction" and record.passed:
            try:
                value = int(str(record.value).strip())
            except ValueError:
                return None
            return value if value in (0, 1) else None
    return None
