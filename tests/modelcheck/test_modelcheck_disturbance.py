"""An external disturbance no candidate describes is reported where it sits in time, not spread over
candidates: a positioning axis with Coulomb friction and unmeasured load pulses at irregular times."""

from __future__ import annotations

import numpy as np
import pytest
from modelcheck_gen import moves_for, record, trapezoid_moves

from fha_studio.logic.modelcheck import run_modelcheck
from fha_studio.physics import AxisModel, Effects
from fha_studio.recording import Recording

CODE = "FHA-25C-50-US250"
FRICTION_NM = 5.0


def _pulses(t: np.ndarray, seed: int) -> tuple[np.ndarray, list[float]]:
    """Load pulses of 6-15 N m, 50-150 ms wide, about one a second (Poisson), either sign."""
    rng = np.random.default_rng(seed)
    torque = np.zeros_like(t)
    centres = []
    at = 0.3
    while True:
        at += rng.exponential(0.8)
        if at > t[-1] - 0.3:
            return torque, centres
        width = rng.uniform(0.05, 0.15)
        torque += (
            rng.uniform(6.0, 15.0) * rng.choice([-1.0, 1.0]) * np.exp(-0.5 * ((t - at) / (width / 2)) ** 2)
        )
        centres.append(at)


@pytest.mark.parametrize("seed", [0, 1])
def test_random_load_pulses_are_a_structured_residual_in_time_besides_the_friction(seed):
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    t, cmd = trapezoid_moves(moves_for(model), 1000.0)
    effects = Effects().with_effect("coulomb_friction", torque_nm=FRICTION_NM)
    rec = record(model, effects, t, cmd, actuator_code=CODE).recording
    # the servo holds the axis against the pulses: the motor current carries them, nothing measures them
    pulses, centres = _pulses(rec.t_s, seed)
    current = rec.current_a + pulses / model.torque_constant_nm_per_a
    result = run_modelcheck(
        Recording(rec.metadata, {**rec.channels, "current": current}, rec.source), resimulate=False
    )
    assert [e.id for e in result.effects] == ["coulomb_friction"], result.summary_lines()
    assert result.effects[0].params["torque_nm"] == pytest.approx(FRICTION_NM, rel=0.15)
    (burst,) = [s for s in result.structures if s.variable == "time"]
    assert burst.channel == "torque" and burst.fraction > 0.5
    # every reported span holds a pulse, and most pulses are found
    found = [c for c in centres if any(a - 0.1 <= c <= b + 0.1 for a, b, _ in burst.spans)]
    assert all(any(a - 0.1 <= c <= b + 0.1 for c in centres) for a, b, _ in burst.spans)
    assert len(found) >= 0.7 * len(centres)
    line = next(x for x in result.summary_lines() if "no candidate explains" in x)
    assert "bursts up to" in line and "t = " in line and "not forced onto a named effect" in line
    report = result.to_json()["structured_residual"]
    assert report[0]["variable"] == "time" and len(report[0]["spans_s"]) == len(burst.spans)
