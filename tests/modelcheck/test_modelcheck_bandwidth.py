"""The analysis bandwidth is chosen from the recording: where the rigid model still explains it.

A gravity-loaded joint whose drive train has a compliance resonance at 12 Hz (a soft coupling: a
fifth of the catalogue stiffness), with Coulomb friction and a load inertia declared 25 % short.
At the short, noise-limited window the old fixed rule chose, the drive-train dynamics leak into the
rigid-model fit and bias friction and the missing inertia; the bandwidth chosen from the data does not.
A rigid drive train keeps the short window.
"""

from __future__ import annotations

import math

import pytest
from modelcheck_gen import moves_for, record, trapezoid_moves

from fha_studio.logic.modelcheck import run_modelcheck
from fha_studio.physics import AxisModel, Effects, ServoSettings

CODE = "FHA-32C-100-US250"
LOAD_KGM2 = 10.0
FRICTION_NM = 12.0
GRAVITY_NM = 50.0
MISSING_KGM2 = 0.25 * LOAD_KGM2
RESONANCE_HZ = 12.0
OLD_FIXED_WINDOW = 19  # what the noise-limited rule picked for this recording


@pytest.fixture(scope="module")
def joint():
    model = AxisModel.from_code(CODE, load_inertia_kgm2=LOAD_KGM2)
    stiffness = (2.0 * math.pi * RESONANCE_HZ) ** 2 * LOAD_KGM2
    effects = (
        Effects()
        .with_effect("coulomb_friction", torque_nm=FRICTION_NM)
        .with_effect("gravity_load", amplitude_nm=GRAVITY_NM, phase_deg=-70.0)
        .with_effect("torsional_compliance", stiffness_nm_per_rad=stiffness)
    )
    servo = ServoSettings.tuned_for(
        model.with_effects(effects), speed_bandwidth_hz=30.0, feed_forward_gain=0.8, quantised_feedback=True
    )
    t, cmd = trapezoid_moves(moves_for(model, n_moves=6), 1000.0)
    gen = record(
        model, effects, t, cmd, actuator_code=CODE, declared_load=LOAD_KGM2 - MISSING_KGM2, servo=servo
    )
    return gen.recording


def _params(result):
    return {e.id: e.params for e in result.effects}


def test_the_chosen_bandwidth_keeps_drive_train_dynamics_out_of_the_rigid_fit(joint):
    chosen = run_modelcheck(joint, resimulate=False)
    found = _params(chosen)
    assert set(found) == {"coulomb_friction", "gravity_load", "inertia_error"}, chosen.summary_lines()
    assert found["coulomb_friction"]["torque_nm"] == pytest.approx(FRICTION_NM, rel=0.05)
    assert found["inertia_error"]["inertia_kgm2"] == pytest.approx(MISSING_KGM2, rel=0.08)
    assert found["gravity_load"]["amplitude_nm"] == pytest.approx(GRAVITY_NM, rel=0.05)
    assert chosen.bandwidth_hz < RESONANCE_HZ / 3
    assert (
        "rigid model still explains" in chosen.window_reason
        and "drive-train dynamics" in chosen.window_reason
    )
    report = chosen.to_json()
    assert report["bandwidth_hz"] == pytest.approx(chosen.bandwidth_hz)
    assert report["bandwidth_reason"] == chosen.window_reason
    tried = report["analysis"]["bandwidths_tried"]
    assert len(tried) > 3 and tried[0]["unexplained_nm"] > 2 * tried[-1]["unexplained_nm"]

    # the short window lets the resonance in: friction and the missing inertia come out biased
    fixed = _params(run_modelcheck(joint, window=OLD_FIXED_WINDOW, resimulate=False))
    friction_error = abs(fixed["coulomb_friction"]["torque_nm"] / FRICTION_NM - 1.0)
    inertia_error = abs(fixed["inertia_error"]["inertia_kgm2"] / MISSING_KGM2 - 1.0)
    assert max(friction_error, inertia_error) > 0.15, fixed


def test_a_rigid_drive_train_keeps_the_short_noise_limited_window():
    model = AxisModel.from_code("FHA-25C-50-US250", load_inertia_kgm2=1.5)
    t, cmd = trapezoid_moves(moves_for(model, n_moves=5), 1000.0)
    rec = record(
        model,
        Effects().with_effect("coulomb_friction", torque_nm=5.0),
        t,
        cmd,
        actuator_code="FHA-25C-50-US250",
    ).recording
    result = run_modelcheck(rec, resimulate=False)
    assert result.window_samples == result.bandwidth_profile[0].window
    assert result.bandwidth_hz > 10.0
    assert "the rigid model explains the data up to there" in result.window_reason
