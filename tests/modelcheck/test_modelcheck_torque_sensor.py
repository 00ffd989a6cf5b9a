"""An output torque sensor (the optional ``torque`` column, N m on the output flange): with the current
it tells what happens in the gear (Kt x current minus the flange's torque) from what the load does;
without the current the load is judged on the sensor alone and the gear through the closed loop.

The ``torque`` column is the simulated axis's own: the physics' flange torque (what a sensor between
the actuator's flange and the load reads), averaged over each sample as the current monitor is, with
0.05 N m of sensor noise."""

from __future__ import annotations

import pytest
from modelcheck_gen import moves_for, record, trapezoid_moves

from fha_studio.logic.modelcheck import run_modelcheck
from fha_studio.physics import AxisModel, Effects
from fha_studio.recording import Recording

CODE = "FHA-25C-50-US250"
SENSOR_NOISE_NM = 0.05


@pytest.fixture(scope="module")
def with_sensor():
    """Coulomb friction 5 N m in the gear, a 20 N m unbalance at the load; the simulated axis's
    flange torque sensor (the load's inertia times its acceleration plus the unbalance)."""
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    t, cmd = trapezoid_moves(moves_for(model), 1000.0)
    effects = Effects().with_effect("coulomb_friction", torque_nm=5.0)
    effects = effects.with_effect("gravity_load", amplitude_nm=20.0, phase_deg=30.0)
    gen = record(model, effects, t, cmd, actuator_code=CODE, torque_sensor_noise_nm=SENSOR_NOISE_NM)
    channels = dict(gen.recording.channels)
    assert "torque" in channels  # the drive's own column, not built here
    return gen.recording.metadata, channels


def _found(result) -> dict[str, tuple[str, dict[str, float]]]:
    return {e.id: (e.label, e.params) for e in result.effects}


@pytest.mark.slow
def test_with_the_current_the_gear_and_the_load_are_told_apart(with_sensor):
    meta, channels = with_sensor
    result = run_modelcheck(Recording(meta, channels, "sensor"), resimulate=False)
    found = _found(result)
    assert set(found) == {"coulomb_friction", "gravity_load"}, result.summary_lines()
    assert found["coulomb_friction"][0].endswith("in the gear")
    assert found["gravity_load"][0].endswith("at the load")
    assert found["coulomb_friction"][1]["torque_nm"] == pytest.approx(5.0, rel=0.05)
    assert found["gravity_load"][1]["amplitude_nm"] == pytest.approx(20.0, rel=0.05)
    assert {"gear torque", "load torque"} <= set(result.channel_status)


@pytest.mark.slow
def test_without_the_current_the_load_is_judged_on_the_sensor_alone(with_sensor):
    meta, channels = with_sensor
    channels = {k: v for k, v in channels.items() if k != "current"}
    result = run_modelcheck(Recording(meta, channels, "sensor"), resimulate=False)
    found = _found(result)
    assert set(found) == {"coulomb_friction", "gravity_load"}, result.summary_lines()
    assert found["gravity_load"][0].endswith("at the load")
    assert found["gravity_load"][1]["amplitude_nm"] == pytest.approx(20.0, rel=0.05)  # measured
    assert found["coulomb_friction"][1]["torque_nm"] == pytest.approx(5.0, rel=0.35)  # through the loop
    text = "\n".join(result.summary_lines())
    assert "the load on the torque sensor" in text and "the load's are measured" in text


@pytest.mark.slow
@pytest.mark.parametrize("current", [True, False], ids=["with-current", "without-current"])
def test_a_compliant_gear_keeps_its_friction_and_wind_up_apart_from_the_load(current):
    """The gear winds up (the catalogue's curve), with Coulomb friction 5 N m in it, and a 20 N m
    unbalance at the load; an encoder on the load, and the simulated axis's sensor on the flange
    reads what the gear passes on to the load. The friction is named in the gear, the unbalance at
    the load, the wind-up between the encoders."""
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    t, cmd = trapezoid_moves(moves_for(model), 1000.0)
    effects = Effects().with_effect("coulomb_friction", torque_nm=5.0)
    effects = effects.with_effect("gravity_load", amplitude_nm=20.0, phase_deg=30.0)
    effects = effects.with_effect("torsional_compliance")
    gen = record(model, effects, t, cmd, actuator_code=CODE, with_load_pos=True,
                 torque_sensor_noise_nm=SENSOR_NOISE_NM)
    channels = dict(gen.recording.channels)
    if not current:
        del channels["current"]
    result = run_modelcheck(Recording(gen.recording.metadata, channels, "sensor"), resimulate=False)
    found = _found(result)
    assert set(found) == {"coulomb_friction", "gravity_load", "torsional_compliance"}, result.summary_lines()
    assert found["coulomb_friction"][0].endswith("in the gear")
    assert found["gravity_load"][0].endswith("at the load")
    assert found["gravity_load"][1]["amplitude_nm"] == pytest.approx(20.0, rel=0.05)  # measured
    # through the loop without the current: the tolerance for what the loop shows
    tol = 0.05 if current else 0.35
    assert found["coulomb_friction"][1]["torque_nm"] == pytest.approx(5.0, rel=tol)
    stiffness = found["torsional_compliance"][1]["stiffness_nm_per_rad"]
    assert model.stiffness is not None
    assert stiffness == pytest.approx(model.stiffness.k1_nm_per_rad, rel=0.1 if current else 0.35)
