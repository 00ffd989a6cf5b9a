"""Self-consistency before anything is named: the model check never gives a confident wrong answer.

Each test is a way the check used to fail where a user could not see it (the old answer, on
commit 0df0e73, is in each docstring): on the public EMPS runs (tests/modelcheck/real/, judged
against the paper's published fit, never against an earlier output of this tool) and on
recordings of the simulated axis.
"""

from __future__ import annotations

import pytest
from modelcheck_gen import record, standard_moves, trapezoid_moves
from real_data import EMPS_REFERENCE, real_recording

from fha_studio.logic.modelcheck import run_modelcheck
from fha_studio.physics import AxisModel, Effects

CODE = "FHA-25C-50-US250"
FRICTION_TOL = 0.25  # the tolerance against the published fit


@pytest.fixture(scope="module")
def emps():
    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = run_modelcheck(real_recording(name))
        return cache[name]

    return get


def _named(result) -> dict[str, dict[str, float]]:
    return {e.id: e.params for e in result.effects}


def _check_emps_friction(result):
    found = _named(result)
    assert set(found) == {"coulomb_friction", "viscous_friction"}, result.summary_lines()
    coulomb = found["coulomb_friction"]["torque_nm"]  # N (1 N m written for 1 N)
    viscous = found["viscous_friction"]["coefficient_nm_s_per_rad"]  # N s/m
    assert coulomb == pytest.approx(EMPS_REFERENCE["coulomb_n"], rel=FRICTION_TOL)
    assert viscous == pytest.approx(EMPS_REFERENCE["viscous_n_s_per_m"], rel=FRICTION_TOL)


@pytest.mark.slow
def test_emps_pulses_cancelling_pair_is_one_unexplained_structure(emps):
    """The EMPS validation run with unmeasured force pulses. Old answer: Coulomb 21.1 N and viscous
    208 N s/m (right), then "load torque offset 410" and "gravity load 415 (phase -96.6 deg)", two
    effects of 400 N on an axis whose whole residual is 38 N rms, which cancel each other to a few N."""
    result = emps("emps_pulses")
    _check_emps_friction(result)
    cancelled = [s for s in result.structures if s.cancelled]
    assert len(cancelled) == 1, result.summary_lines()
    pair = cancelled[0]
    assert set(pair.cancelled) == {"load_torque_offset", "gravity_load"}
    assert min(pair.sizes) > 5 * pair.rms  # each far larger than what they explain together
    assert pair.variable in ("position", "speed") and pair.at is not None and pair.spans
    text = "\n".join(result.summary_lines())
    assert "cancel each other: not named" in text
    # the report still says there is structure left that nothing named explains
    assert [s for s in result.structures if not s.cancelled], text
    report = result.to_json()
    assert {e["id"] for e in report["effects"]} == {"coulomb_friction", "viscous_friction"}
    assert any(s["cancelling_effects"] for s in report["structured_residual"])
    # what is named re-simulates better than the nominal model (old: torque 38.8 -> 274 N m rms)
    resim = result.resimulation
    assert resim.rms_updated_nm < resim.rms_nominal_nm, text


@pytest.mark.slow
def test_emps_estimation_run_refuses_a_torque_beyond_the_axis(emps):
    """The EMPS estimation run. Old answer: "load torque offset 369" and "gravity load 373" beside
    the friction: a constant push of 369 N on an axis whose controller never asked for more than
    152 N."""
    result = emps("emps")
    _check_emps_friction(result)
    reasons = {r.id: r.reason for r in result.refused}
    assert "could not produce it" in reasons.get("load_torque_offset", ""), result.summary_lines()
    assert "Not named: load torque offset" in "\n".join(result.summary_lines())
    assert result.to_json()["not_named"]


@pytest.mark.slow
def test_one_way_motion_names_no_friction_by_direction():
    """Moves in one direction only (CW), Coulomb friction 5 N m hidden. Old answer: "friction that
    differs by direction: 5.01 N m turning CW and 1.30 N m turning CCW", a CCW level from a
    recording that never turned CCW."""
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    moves = [(120, 30, 40, 0.25), (60, 10, 20, 0.25), (200, 60, 60, 0.25), (150, 45, 30, 0.25),
             (90, 20, 80, 0.25), (200, 5, 50, 0.25), (60, 3, 15, 0.25), (40, 15, 60, 0.3)]
    t, cmd = trapezoid_moves(moves, 1000.0)
    gen = record(model, Effects().with_effect("coulomb_friction", torque_nm=5.0), t, cmd, actuator_code=CODE)
    result = run_modelcheck(gen.recording, resimulate=False)
    found = _named(result)
    assert "asymmetric_friction" not in found, result.summary_lines()
    assert "asymmetric_friction" not in {a.alternative for a in result.ambiguities}
    text = "\n".join(result.summary_lines())
    assert "Friction by direction cannot be seen: the axis slid one way only (CW)" in text
    assert "Record moves in both directions" in text
    level = found.get("coulomb_friction", found.get("load_torque_offset", {}))
    assert abs(next(iter(level.values()))) == pytest.approx(5.0, rel=0.1), text


@pytest.mark.slow
def test_an_inertia_re_fit_below_its_floor_is_not_named():
    """Gravity 20 N m and an inertia error of 0.01 kg m^2 (0.16 N m at this motion, under the 0.75 N m
    floor). Old answer: "Inertia error 0.0098 kg m^2" (size 0.157 N m) beside the gravity load: the
    inertia, re-fitted first while the gravity was not yet in the model, looked like 4.2 N m there
    and was kept after the joint re-fit shrank it below the floor."""
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    t, cmd = trapezoid_moves(standard_moves(), 1000.0)
    effects = Effects().with_effect("gravity_load", amplitude_nm=20.0, phase_deg=30.0)
    gen = record(model, effects.with_effect("inertia_error", inertia_kgm2=0.01), t, cmd, actuator_code=CODE)
    result = run_modelcheck(gen.recording, resimulate=False)
    floor = result.channels["torque"].floor
    assert set(_named(result)) == {"gravity_load"}, result.summary_lines()
    assert all(e.size >= floor for e in result.effects)
    assert _named(result)["gravity_load"]["amplitude_nm"] == pytest.approx(20.0, rel=0.05)


def test_a_set_that_makes_the_re_simulation_worse_or_the_gap_wider_is_not_found():
    from fha_studio.logic.modelcheck.consistency import set_verdict

    assert set_verdict(resim_nominal=38.8, resim_updated=274.0, floor=1.0, gaps=[]).startswith(
        "its re-simulation is worse"
    )
    assert set_verdict(resim_nominal=38.8, resim_updated=5.2, floor=1.0, gaps=[]) == ""
    assert "does not shrink the torque gap" in set_verdict(
        resim_nominal=None, resim_updated=None, floor=1.0, gaps=[("torque", 1.0, 1.2, "N m")]
    )
