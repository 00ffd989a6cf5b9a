"""The output flange's torque (what a strain-gauge sensor between the gear and the load reads):
the load's own equation of motion, J_load x a_load = flange torque - the load's torques, holds on it,
rigid or compliant; Kt x current minus it is what the gear side takes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fha_studio.physics import TRACE_CHANNELS, Effects, MonitorOptions, ServoAxis, ServoSettings, simulate

CODE = "FHA-25C-50-US250"
GRAVITY_NM, GRAVITY_PHASE_DEG = 8.0, 20.0


def _effects(compliant: bool) -> Effects:
    effects = Effects().with_effect("coulomb_friction", torque_nm=3.0).with_effect(
        "gravity_load", amplitude_nm=GRAVITY_NM, phase_deg=GRAVITY_PHASE_DEG).with_effect(
        "load_torque_offset", torque_nm=-2.0)
    return effects.with_effect("torsional_compliance") if compliant else effects


def _own_torque(x: np.ndarray) -> np.ndarray:
    return GRAVITY_NM * np.sin(x + math.radians(GRAVITY_PHASE_DEG)) - 2.0


@pytest.mark.parametrize("compliant", [False, True], ids=["rigid", "compliant"])
def test_the_flange_torque_is_what_the_load_takes(make_model, compliant):
    model = make_model(CODE, 1.5, _effects(compliant))
    servo = ServoSettings.tuned_for(model)
    dt = 1.0 / servo.servo_rate_hz
    t = np.arange(0.0, 1.2, dt)  # every servo period
    cmd = 1.2 * (1.0 - np.cos(2.0 * math.pi * t / 1.2))
    r = simulate(model, servo, t, cmd)
    flange = r["flange_torque"]
    # at rest at the start the flange holds the static load
    assert flange[0] == pytest.approx(_own_torque(np.array([cmd[0]]))[0], rel=1e-9)
    # the semi-implicit integrator's own step: the load's speed changes by h x (flange - own) / J_L
    # with the load's torques taken where the period starts (the motor side on a rigid axis)
    x = r["load_pos"] if compliant else r["pos"]
    acc = np.diff(x, 2) / dt**2 if compliant else np.diff(r["vel"]) / dt
    start = x[1:-1] if compliant else x[:-1]
    expected = model.load_inertia_kgm2 * acc + _own_torque(start)
    got = flange[2:] if compliant else flange[1:]
    span = np.ptp(flange)
    assert span > 5.0  # the load's inertia and gravity both show
    # a compliant gear integrates in substeps; the flange torque is the last one's
    tol = 1e-6 * span if ServoAxis(model, servo).substeps == 1 else 0.02 * span
    assert np.max(np.abs(got - expected)) < tol
    # the gear side (Kt x current - flange) carries the friction: positive while turning CW
    gear = r["torque"] - flange
    moving_cw = r["vel"] > 0.3
    assert np.median(gear[moving_cw]) > 1.5


def test_the_axis_traces_the_flange_torque_and_the_sensor_noise_is_a_monitor(make_model):
    model = make_model(CODE, 1.5, _effects(False))
    axis = ServoAxis(model)
    axis.servo_on()
    axis.start_trace()
    axis.move_by(math.radians(30.0))
    axis.advance(0.5)
    trace = axis.read_trace()
    assert "flange_torque" in TRACE_CHANNELS
    assert trace["flange_torque"].shape == trace["t"].shape
    assert trace["flange_torque"][-1] == axis.flange_torque_nm == axis.snapshot()["flange_torque_nm"]
    t = np.arange(0.0, 0.5, 1e-3)
    clean = simulate(model, None, t, 0.2 * t)
    noisy = simulate(model, None, t, 0.2 * t, monitor=MonitorOptions(flange_torque_noise_nm=0.05, seed=1))
    assert np.std(noisy["flange_torque"] - clean["flange_torque"]) == pytest.approx(0.05, rel=0.15)
    assert np.array_equal(noisy["current"], clean["current"])  # the other monitors draw as before
