"""Hidden-effect cases for friction that differs by direction, breakaway (Stribeck) friction and a
torque-constant error: each alone and in pairs, including pairs the data cannot separate.

Recordings of at most 9 s at 1 kHz, made with the shared physics in closed loop (the monitors'
quantisation and noise included); the workflow sees only the recording.
"""

from __future__ import annotations

import pytest
from modelcheck_gen import moves_for, record, trapezoid_moves

from fha_studio.logic.modelcheck import run_modelcheck
from fha_studio.physics import AxisModel, Effects

CODE = "FHA-25C-50-US250"
LOAD_KGM2 = 1.5
MAX_SECONDS = 9.0
# constant-speed runs of about 0.8 s from 0.3 to 40 r/min, alternating direction (Stribeck shows there)
LOW_SPEED_RUNS = [
    (sign * rpm * 6.0 * 0.8, rpm, 10.0, 0.25)
    for sign, rpm in zip([1, -1] * 4, [0.3, 0.6, 1.2, 2.5, 5.0, 15.0, 40.0, 0.45], strict=True)
]
# slow runs only, far below a Stribeck speed of 1 rad/s (~10 r/min): breakaway friction stays flat
SLOW_RUNS = [
    (sign * rpm * 6.0 * 1.2, rpm, 5.0, 0.25)
    for sign, rpm in zip([1, -1] * 3, [0.5, 0.8, 1.0] * 2, strict=True)
]


def _run(effects: dict, moves=None, dwell_s: float = 0.2):
    model = AxisModel.from_code(CODE, load_inertia_kgm2=LOAD_KGM2)
    t, cmd = trapezoid_moves(moves or moves_for(model), 1000.0, start_dwell_s=dwell_s)
    keep = t <= MAX_SECONDS
    rec = record(model, Effects.from_dict(effects), t[keep], cmd[keep], actuator_code=CODE).recording
    return run_modelcheck(rec, resimulate=False)


def _named(result) -> dict[str, dict[str, float]]:
    return {e.id: e.params for e in result.effects}


def _pairs(result) -> list[set[str]]:
    return [{a.chosen, a.alternative} for a in result.ambiguities]


ASYMMETRIC = {"asymmetric_friction": {"torque_pos_nm": 8.0, "torque_neg_nm": 4.0}}


@pytest.mark.slow
def test_friction_that_differs_by_direction_is_named_when_a_standstill_shows_no_offset():
    # 1 s at standstill with the servo on before the first move: an offset would need current there
    result = _run(ASYMMETRIC, dwell_s=1.0)
    found = _named(result)
    assert set(found) == {"asymmetric_friction"} and not result.ambiguities, result.summary_lines()
    assert found["asymmetric_friction"]["torque_pos_nm"] == pytest.approx(8.0, rel=0.05)
    assert found["asymmetric_friction"]["torque_neg_nm"] == pytest.approx(4.0, rel=0.05)
    effect = result.effects[0]
    assert "turning CW" in effect.advice and "turning CCW" in effect.advice
    assert result.updated_model.effects.asymmetric_friction.torque_pos_nm == pytest.approx(8.0, rel=0.05)


@pytest.mark.slow
def test_friction_by_direction_and_coulomb_plus_offset_are_not_separable_without_that_standstill():
    result = _run(ASYMMETRIC, dwell_s=0.2)
    assert {"asymmetric_friction", "coulomb_friction + load_torque_offset"} in _pairs(result), (
        result.summary_lines()
    )
    text = "\n".join(result.summary_lines())
    assert "Coulomb friction + Load torque offset" in text and "standstill with the servo on" in text
    # and the look-alike itself, with its standstill, is named as what it is
    offset = _run(
        {"coulomb_friction": {"torque_nm": 6.0}, "load_torque_offset": {"torque_nm": 2.0}}, dwell_s=1.0
    )
    assert set(_named(offset)) == {"coulomb_friction", "load_torque_offset"}, offset.summary_lines()
    assert not offset.ambiguities


@pytest.mark.slow
def test_friction_by_direction_beside_gravity_is_separated():
    effects = {**ASYMMETRIC, "gravity_load": {"amplitude_nm": 15.0, "phase_deg": 30.0}}
    result = _run(effects, dwell_s=1.0)
    found = _named(result)
    assert set(found) == {"asymmetric_friction", "gravity_load"} and not result.ambiguities, (
        result.summary_lines()
    )
    assert found["gravity_load"]["amplitude_nm"] == pytest.approx(15.0, rel=0.05)
    assert found["asymmetric_friction"]["torque_neg_nm"] == pytest.approx(4.0, rel=0.05)


@pytest.mark.slow
def test_breakaway_friction_beside_coulomb_friction_from_low_speed_runs():
    effects = {
        "coulomb_friction": {"torque_nm": 5.0},
        "stribeck_friction": {"static_torque_nm": 4.0, "velocity_rad_s": 0.1},
    }
    result = _run(effects, moves=LOW_SPEED_RUNS)
    found = _named(result)
    assert set(found) == {"coulomb_friction", "stribeck_friction"}, result.summary_lines()
    # within 25 %: the closed loop sticks and slips at each breakaway, which no rigid model follows
    assert found["coulomb_friction"]["torque_nm"] == pytest.approx(5.0, rel=0.1)
    assert found["stribeck_friction"]["static_torque_nm"] == pytest.approx(4.0, rel=0.25)
    assert found["stribeck_friction"]["velocity_rad_s"] == pytest.approx(0.1, rel=0.3)
    # breakaway at each start is the rigid model's limit, not an unmeasured disturbance
    assert not [s for s in result.structures if s.variable == "time"], result.summary_lines()


@pytest.mark.slow
def test_breakaway_friction_alone():
    result = _run(
        {"stribeck_friction": {"static_torque_nm": 6.0, "velocity_rad_s": 0.2}}, moves=LOW_SPEED_RUNS
    )
    found = _named(result)
    assert "stribeck_friction" in found, result.summary_lines()
    assert found["stribeck_friction"]["static_torque_nm"] == pytest.approx(6.0, rel=0.2)
    # whatever Coulomb friction is fitted beside it stays small against the breakaway
    assert found.get("coulomb_friction", {"torque_nm": 0.0})["torque_nm"] < 0.25 * 6.0


@pytest.mark.slow
def test_breakaway_friction_far_above_every_speed_is_not_separable_from_coulomb_friction():
    result = _run({"stribeck_friction": {"static_torque_nm": 6.0, "velocity_rad_s": 1.0}}, moves=SLOW_RUNS)
    assert {"coulomb_friction", "stribeck_friction"} in _pairs(result), result.summary_lines()
    assert "several low speeds" in "\n".join(result.summary_lines())


@pytest.mark.slow
def test_a_torque_constant_error_is_reported_against_an_inertia_error_with_the_separating_test():
    result = _run({"torque_constant_error": {"ratio": 0.8}})
    assert set(_named(result)) == {"inertia_error"}, result.summary_lines()
    (amb,) = [
        a
        for a in result.ambiguities
        if {a.chosen, a.alternative} == {"inertia_error", "torque_constant_error"}
    ]
    assert amb.alternative_params["ratio"] == pytest.approx(0.8, rel=0.03)
    assert "known load torque" in amb.separating_test
    effect = result.effects[0]
    assert effect.alternatives == ["torque_constant_error"] and "known load torque" in effect.advice
    # read as an inertia error: J (1/ratio - 1)
    total = AxisModel.from_code(CODE, load_inertia_kgm2=LOAD_KGM2).total_inertia_kgm2
    assert effect.params["inertia_kgm2"] == pytest.approx(total * (1 / 0.8 - 1), rel=0.05)


@pytest.mark.slow
def test_a_torque_constant_error_beside_coulomb_friction_scales_the_friction_it_reports():
    result = _run({"torque_constant_error": {"ratio": 1.25}, "coulomb_friction": {"torque_nm": 5.0}})
    found = _named(result)
    assert set(found) == {"inertia_error", "coulomb_friction"}, result.summary_lines()
    # the catalogue Kt reads the friction 1.25 times too small
    assert found["coulomb_friction"]["torque_nm"] == pytest.approx(5.0 / 1.25, rel=0.05)
    assert {"inertia_error", "torque_constant_error"} in _pairs(result)
    report = result.to_json()
    pair = next(x for x in report["not_separable"] if "torque_constant_error" in x["ids"])
    assert pair["alternative_params"]["ratio"] == pytest.approx(1.25, rel=0.03)


def test_the_new_effects_run_in_the_simulated_drive_and_the_model_file():
    from fha_studio.hardware.sim import SimDrive

    url = (
        f"sim://{CODE}?paced=0&effects=asymmetric_friction:torque_pos_nm=3,torque_neg_nm=1;"
        "stribeck_friction:static_torque_nm=2,velocity_rad_s=0.05;torque_constant_error:ratio=0.9"
    )
    with SimDrive.from_url(url) as drive:
        effects = drive.model.effects
        assert effects.asymmetric_friction.torque_neg_nm == 1.0
        assert effects.stribeck_friction.velocity_rad_s == 0.05
        assert effects.torque_constant_error.ratio == 0.9
    model = AxisModel.from_code(CODE, effects=effects)
    again = AxisModel.from_toml(model.to_toml())
    assert again.effects == effects
    with pytest.raises(ValueError, match="ratio must be between"):
        Effects().with_effect("torque_constant_error", ratio=0.0)
