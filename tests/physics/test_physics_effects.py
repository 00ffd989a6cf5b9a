"""Each effect switched on changes what it should, by the amount its parameters say."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fha_studio.physics import ARCSEC_PER_RAD, Effects, ServoAxis, ServoSettings, simulate

RPM = 2 * math.pi / 60
CODE = "FHA-25C-50-US250"  # Kt 22 N m/A, ratio 50


def _jog_current(model, speed_rad_s: float, settle_s: float = 1.0, average_s: float = 0.5) -> np.ndarray:
    axis = ServoAxis(model)
    axis.servo_on()
    axis.jog(speed_rad_s)
    axis.advance(settle_s)
    axis.start_trace()
    axis.advance(average_s)
    return axis.read_trace()


def test_nominal_axis_needs_no_current_at_constant_speed(make_model):
    trace = _jog_current(make_model(CODE, 0.5), 30 * RPM)
    assert np.max(np.abs(trace["current"])) < 1e-6


def test_coulomb_friction(make_model):
    model = make_model(CODE, 0.5, Effects().with_effect("coulomb_friction", torque_nm=8.0))
    for speed in (30 * RPM, -10 * RPM):
        trace = _jog_current(model, speed)
        assert np.mean(trace["current"]) * 22 == pytest.approx(math.copysign(8.0, speed), rel=1e-3)


def test_coulomb_friction_sticks_below_breakaway(make_model):
    # servo off, a load torque below the friction: the axis stays put (no creep, no chatter)
    effects = Effects().with_effect("coulomb_friction", torque_nm=8.0).with_effect("load_torque_offset",
                                                                                    torque_nm=7.0)
    axis = ServoAxis(make_model(CODE, 0.5, effects))
    axis.advance(2.0)
    assert axis.output_pos_rad == 0.0
    # above it, the load drives the axis backwards: motor supplies +offset, so the load pushes -
    axis.set_model(make_model(CODE, 0.5, effects.with_effect("load_torque_offset", torque_nm=9.0)))
    axis.advance(0.5)
    assert axis.output_speed_rad_s == pytest.approx(-1.0 / (0.81 + 0.5) * 0.5, rel=0.01)


def test_viscous_friction(make_model):
    model = make_model(CODE, 0.5, Effects().with_effect("viscous_friction", coefficient_nm_s_per_rad=2.0))
    trace = _jog_current(model, 45 * RPM)
    assert np.mean(trace["current"]) * 22 == pytest.approx(2.0 * 45 * RPM, rel=1e-3)


@pytest.mark.parametrize("pos_deg", [0.0, 30.0, 135.0, -100.0])
def test_gravity_load_held(make_model, pos_deg):
    model = make_model(CODE, 0.5, Effects().with_effect("gravity_load", amplitude_nm=40.0, phase_deg=20.0))
    t = np.linspace(0, 1.0, 101)
    r = simulate(model, None, t, np.full_like(t, math.radians(pos_deg)))
    expected = 40.0 * math.sin(math.radians(pos_deg + 20.0))
    assert r["torque"][-1] == pytest.approx(expected, abs=1e-6)
    assert r["pos"][-1] == pytest.approx(math.radians(pos_deg), abs=1e-9)


def test_gravity_load_moving(make_model):
    model = make_model(CODE, 0.5, Effects().with_effect("gravity_load", amplitude_nm=40.0, phase_deg=-60.0))
    trace = _jog_current(model, 20 * RPM, settle_s=0.5, average_s=2.0)
    expected = 40.0 * np.sin(trace["pos"] - math.radians(60)) / 22
    assert np.max(np.abs(trace["current"] - expected)) < 0.02 * 40 / 22


def test_load_torque_offset(make_model):
    model = make_model(CODE, 0.5, Effects().with_effect("load_torque_offset", torque_nm=-12.0))
    t = np.linspace(0, 0.5, 51)
    r = simulate(model, None, t, np.zeros_like(t))
    assert np.allclose(r["torque"], -12.0)


def test_inertia_error(make_model):
    # the motor supplies the missing inertia x acceleration on top of the declared one
    base = make_model(CODE, 0.5)
    more = make_model(CODE, 0.5, Effects().with_effect("inertia_error", inertia_kgm2=0.4))
    assert more.total_inertia_kgm2 == pytest.approx(base.total_inertia_kgm2 + 0.4)
    t = np.linspace(0, 0.6, 601)
    accel = 20.0
    cmd = 0.5 * accel * np.minimum(t, 0.3) ** 2
    r0 = simulate(base, ServoSettings.tuned_for(base, feed_forward_gain=1.0), t, cmd)
    r1 = simulate(more, ServoSettings.tuned_for(base, feed_forward_gain=1.0), t, cmd)
    mid = (t > 0.15) & (t < 0.25)
    diff = np.mean(r1["torque"][mid] - r0["torque"][mid])
    assert diff == pytest.approx(0.4 * accel, rel=0.03)


def test_torque_ripple_per_motor_turn(make_model):
    # at 1 r/min output the motor turns 50 r/min: 2 cycles/motor rev = 1.67 Hz, well inside the
    # servo bandwidth, so the current carries the ripple (motor supplies + A sin(2 x motor angle))
    effects = Effects().with_effect("torque_ripple", amplitude_nm=3.0, cycles_per_motor_rev=2)
    trace = _jog_current(make_model(CODE, 0.5, effects), 1 * RPM, settle_s=0.5, average_s=1.2)
    expected = 3.0 * np.sin(2 * 50 * trace["pos"]) / 22
    assert np.max(np.abs(trace["current"] - expected)) < 0.05 * 3.0 / 22
    assert np.ptp(trace["current"]) * 22 == pytest.approx(6.0, rel=0.05)


def test_kinematic_error(make_model):
    effects = Effects().with_effect("kinematic_error", amplitude_arcsec=30.0, cycles_per_motor_rev=2,
                                    phase_deg=45.0)
    model = make_model(CODE, 0.5, effects)
    t = np.linspace(0, 4.0, 4001)
    cmd = np.radians(10.0) * t / 4.0
    r = simulate(model, None, t, cmd)
    err_arcsec = (r["load_pos"] - r["pos"]) * ARCSEC_PER_RAD
    expected = 30.0 * np.sin(2 * 50 * r["pos"] + math.radians(45.0))
    assert np.max(np.abs(err_arcsec - expected)) < 1e-6
    # 10 degrees at the output = 500 motor degrees = 1.39 motor turns = 2.8 cycles
    assert np.ptp(err_arcsec) == pytest.approx(60.0, rel=1e-3)


def test_torsional_compliance_winds_up_under_load(make_model):
    effects = Effects().with_effect("torsional_compliance").with_effect("load_torque_offset", torque_nm=50.0)
    model = make_model(CODE, 0.5, effects)
    t = np.linspace(0, 1.0, 1001)
    r = simulate(model, None, t, np.zeros_like(t))
    # the load side lags: load_pos - pos = -wind-up(50 N m) = -(T1/K1 + (50 - T1)/K2)
    expected = -(29 / 4.7e4 + 21 / 6.1e4)
    assert np.allclose(r["load_pos"] - r["pos"], expected, rtol=1e-4)
    assert r["torque"][-1] == pytest.approx(50.0, rel=1e-6)


def test_torsional_compliance_override_scales_the_curve(make_model):
    model = make_model(CODE, 0.5, Effects().with_effect("torsional_compliance", stiffness_nm_per_rad=2.35e4))
    g = model.gear_stiffness
    assert (g.k1_nm_per_rad, g.k2_nm_per_rad, g.k3_nm_per_rad) == pytest.approx((2.35e4, 3.05e4, 4.2e4))


@pytest.mark.parametrize("compliance", [False, True])
def test_lost_motion_seen_at_reversals(make_model, compliance):
    effects = Effects().with_effect("lost_motion", width_arcsec=60.0)
    if compliance:
        effects = effects.with_effect("torsional_compliance")
    model = make_model(CODE, 0.5, effects)
    t = np.linspace(0, 4.0, 4001)
    cmd = np.radians(2.0) * np.sin(2 * np.pi * 0.5 * t)
    r = simulate(model, None, t, cmd)
    gap_arcsec = (r["load_pos"] - r["pos"]) * ARCSEC_PER_RAD
    # at full speed (t = 2 s: forwards, t = 3 s: backwards) the load trails by half the dead band
    # (with the gear's spring the load also bounces after each reversal: the contact is an impact)
    assert gap_arcsec[t == 2.0][0] == pytest.approx(-30.0, rel=0.02)
    assert gap_arcsec[t == 3.0][0] == pytest.approx(30.0, rel=0.02)
    # the nominal axis has no gap
    r0 = simulate(make_model(CODE, 0.5), None, t, cmd)
    assert np.max(np.abs(r0["load_pos"] - r0["pos"])) == 0.0


def test_effects_are_named_as_the_model_check_contract():
    e = (Effects().with_effect("coulomb_friction", torque_nm=1.0)
         .with_effect("viscous_friction", coefficient_nm_s_per_rad=0.1)
         .with_effect("gravity_load", amplitude_nm=3.0, phase_deg=10.0)
         .with_effect("load_torque_offset", torque_nm=-2.0)
         .with_effect("inertia_error", inertia_kgm2=-0.1)
         .with_effect("torque_ripple", amplitude_nm=0.5, cycles_per_motor_rev=1)
         .with_effect("kinematic_error", amplitude_arcsec=20.0, cycles_per_motor_rev=2)
         .with_effect("torsional_compliance", stiffness_nm_per_rad=4e4)
         .with_effect("lost_motion", width_arcsec=30.0))
    listed = e.to_list()
    assert [x["id"] for x in listed] == [
        "coulomb_friction", "viscous_friction", "gravity_load", "load_torque_offset", "inertia_error",
        "torque_ripple", "kinematic_error", "torsional_compliance", "lost_motion",
    ]
    assert listed[2]["params"] == {"amplitude_nm": 3.0, "phase_deg": 10.0}
    assert listed[7] == {"id": "torsional_compliance", "params": {"stiffness_nm_per_rad": 4e4},
                         "channel": "position"}
    assert Effects.from_list(listed) == e
    assert e.without("gravity_load").gravity_load is None


@pytest.mark.parametrize(("effect_id", "params", "message"), [
    ("stribeck", {}, "unknown effect id 'stribeck'"),
    ("coulomb_friction", {"torque": 1.0}, "allowed: torque_nm"),
    ("coulomb_friction", {"torque_nm": -1.0}, "must not be negative"),
    ("gravity_load", {"amplitude_nm": float("nan")}, "finite"),
])
def test_bad_effects_are_refused_by_name(effect_id, params, message):
    with pytest.raises(ValueError, match=message):
        Effects().with_effect(effect_id, **params)
