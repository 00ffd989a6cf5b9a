"""Servo behaviour: step response, rotary direction, electronic gear, stability, energy, model file."""

from __future__ import annotations

import importlib
import math

import numpy as np
import pytest

from fha_studio.physics import (
    AxisModel,
    Effects,
    MonitorOptions,
    PanelGains,
    ServoAxis,
    ServoSettings,
    catalogue_effects,
    servo_settings,
    simulate,
)

RPM = 2 * math.pi / 60
CODE = "FHA-25C-50-US250"


def test_position_step_response_is_first_order_with_time_constant_one_over_kp(make_model):
    # A small step (no saturation) with a fast speed loop (150 Hz) and Kp = 20/s: the position
    # loop alone sets the response, x(t) = step x (1 - exp(-Kp t)); 63 % at t = 1/Kp = 50 ms.
    model = make_model(CODE, 0.5)
    settings = ServoSettings.tuned_for(model, speed_bandwidth_hz=150, position_loop_gain_per_s=20.0,
                                       speed_loop_integral_time_s=math.inf)
    axis = ServoAxis(model, settings)
    axis.servo_on()
    axis.add_command_pulses(1000)
    step = 1000 * model.output_pulse_rad
    axis.start_trace()
    axis.advance(0.3)
    tr = axis.read_trace()
    for t_check in (0.05, 0.1, 0.15):
        i = np.argmin(np.abs(tr["t"] - t_check))
        assert tr["pos"][i] / step == pytest.approx(1 - math.exp(-20 * t_check), abs=0.02)
    assert np.max(tr["pos"]) <= step * 1.001  # no overshoot
    assert axis.error_pulses == pytest.approx(1000 * math.exp(-20 * 0.3), abs=2)
    axis.advance(0.2)
    assert axis.in_position


@pytest.mark.parametrize(("direction", "sign"), [(0, 1.0), (1, -1.0)])
def test_rotary_direction(make_model, direction, sign):
    # parameter 8: 0 = a FWD command turns CW seen from the output flange (positive angle), 1 = CCW
    model = make_model(CODE, 0.5)
    axis = ServoAxis(model, ServoSettings.tuned_for(model, rotary_direction=direction))
    axis.servo_on()
    axis.jog(10 * RPM)
    axis.advance(0.5)
    assert math.copysign(1.0, axis.output_pos_rad) == sign
    assert math.copysign(1.0, axis.output_speed_rad_s) == sign
    assert math.copysign(1.0, axis.current_a) == sign  # accelerating: torque in the motion's sense
    # the drive's own counters are in the command frame: FWD counts up either way
    assert axis.feedback_pulses > 0
    assert axis.command_pos_rad == pytest.approx(sign * 10 * RPM * (0.5 - 0.5 * 10 * RPM /
                                                 model.max_acceleration_rad_s2()), rel=1e-3)


def test_electronic_gear(make_model):
    model = make_model(CODE, 0.5)
    settings = ServoSettings.tuned_for(model, electronic_gear_numerator=5, electronic_gear_denominator=2)
    axis = ServoAxis(model, settings)
    axis.servo_on()
    axis.add_command_pulses(400)
    axis.advance(1.0)
    assert axis.command_pulses == 1000
    assert abs(axis.feedback_pulses - 1000) <= settings.in_position_range_pulses
    axis.move_by_pulses(-400)
    axis.advance(1.0)
    assert axis.command_pulses == 0


def test_servo_off_clears_the_error_and_coasts(make_model):
    model = make_model(CODE, 0.5, Effects().with_effect("coulomb_friction", torque_nm=5.0))
    axis = ServoAxis(model)
    axis.servo_on()
    axis.jog(30 * RPM)
    axis.advance(0.5)
    v = axis.output_speed_rad_s
    axis.servo_off()
    axis.step(1)
    assert axis.current_a == 0.0
    axis.advance(0.2)
    # friction alone decelerates: 5 N m over J = 1.31 kg m^2
    assert axis.output_speed_rad_s == pytest.approx(v - 5.0 / 1.31 * 0.2, rel=0.01)
    assert axis.error_pulses == 0
    with pytest.raises(RuntimeError, match="servo is off"):
        axis.jog(1.0)


@pytest.mark.parametrize("code", ["FHA-40C-50-US250", "FHA-40C-100-US250", "FHA-17C-50-US250"])
def test_stiffest_gears_with_small_load_are_stable(make_model, code):
    # FHA-40C-100 has the stiffest gear (K3 = 37e4 N m/rad), FHA-40C-50 the stiffest for its inertia
    # and FHA-17C-50 unloaded the highest mode of the catalogue (flange alone, 2 % of J_A, on
    # K3): the integrator must stay stable there. Undamped and left to ring from a wind-up beyond
    # T2, the symplectic integrator keeps the energy bounded; under the servo the axis settles.
    model = make_model(code, 0.0, Effects().with_effect("torsional_compliance"), gear_damping_ratio=0.0)
    axis = ServoAxis(model)
    g = model.gear_stiffness
    twist0 = g.wind_up_rad(1.2 * g.t2_nm)  # all three regions take part
    axis._state.xl = -twist0  # a wound-up gear, released

    def energy() -> float:
        s = axis._state
        tw = np.linspace(0, abs(s.xm - s.xl), 2001)
        spring = float(np.trapezoid(g.torque_nm(tw), tw))
        kinetic = 0.5 * model.motor_side_inertia_kgm2 * s.vm**2 + 0.5 * model.load_side_inertia_kgm2 * s.vl**2
        return kinetic + spring

    e0 = energy()
    energies = np.array([energy() for _ in range(400) if axis.step(25) is None])
    # symplectic Euler: the sampled energy wobbles by about omega x h around a constant, no drift
    assert np.max(energies) < 1.25 * e0
    assert np.min(energies) > 0.75 * e0
    assert np.mean(energies[-100:]) == pytest.approx(np.mean(energies[:100]), rel=0.02)
    # with the gear's damping and the servo on it comes to rest
    damped = model.replace(gear_damping_ratio=0.05).with_effects(catalogue_effects(model))
    axis = ServoAxis(damped)
    axis.servo_on()
    axis.move_by(math.radians(30))
    axis.advance(2.0)
    assert abs(axis.twist_rad) < 1e-6
    assert axis.in_position


@pytest.mark.parametrize("frame", ["17C", "25C", "32C", "40C"])
def test_default_tuning_settles_every_actuator_up_to_three_times_the_allowable_inertia(frame):
    # tuned_for caps the speed loop below the load's anti-resonance: heavy loads on 160:1 gears
    # (anti-resonance ~4 Hz) settle instead of ringing.
    from fha_studio.catalog import get_actuator

    for ratio in (50, 100, 160):
        actuator = get_actuator(f"FHA-{frame}-{ratio}-US250")
        for load in (0.0, 3 * actuator.allowable_inertia_kgm2):
            model = AxisModel.from_actuator(actuator, load)
            model = model.with_effects(catalogue_effects(model))
            axis = ServoAxis(model)
            axis.servo_on()
            axis.move_by(math.radians(45))
            axis.advance(3.0)
            axis.start_trace()
            axis.advance(0.5)
            tail = axis.read_trace()
            assert axis.in_position, (actuator.model_code, load)
            assert np.ptp(tail["current"]) < 0.01 * model.max_current_a, (actuator.model_code, load)


def test_energy_balance_of_a_move(make_model):
    # Rest to rest with Coulomb friction only: the motor's work is all friction loss, Fc x distance.
    model = make_model(CODE, 1.5, Effects().with_effect("coulomb_friction", torque_nm=6.0))
    axis = ServoAxis(model)
    axis.servo_on()
    axis.move_by(math.radians(90), speed_rad_s=40 * RPM)
    axis.advance(1.5)
    assert axis.motor_work_j == pytest.approx(6.0 * math.radians(90), rel=0.01)


def test_regenerated_energy_of_a_stop(make_model):
    # From 40 r/min to rest without friction and without winding losses (R = 0): the kinetic
    # energy 1/2 J w^2 goes back to the bus. With the phase resistance, less comes back.
    model = make_model(CODE, 1.5, phase_resistance_ohm=0.0)
    axis = ServoAxis(model)
    axis.servo_on()
    axis.jog(40 * RPM)
    axis.advance(1.0)
    before = axis.regenerated_energy_j
    axis.stop()
    axis.advance(1.0)
    kinetic = 0.5 * model.total_inertia_kgm2 * (40 * RPM) ** 2
    assert axis.regenerated_energy_j - before == pytest.approx(kinetic, rel=0.02)
    lossy = ServoAxis(make_model(CODE, 1.5))
    lossy.servo_on()
    lossy.jog(40 * RPM)
    lossy.advance(1.0)
    lossy.stop()
    lossy.advance(1.0)
    assert 0 < lossy.regenerated_energy_j < kinetic
    assert lossy.current_squared_integral_a2s > 0
    assert lossy.peak_speed_rad_s == pytest.approx(40 * RPM, rel=0.05)


def test_model_file_round_trip(make_model, tmp_path):
    model = make_model(CODE, 1.5)
    model = model.with_effects(catalogue_effects(model).with_effect("gravity_load", amplitude_nm=12.5,
                                                                    phase_deg=-30.0))
    path = tmp_path / "axis.toml"
    model.save(path)
    again = AxisModel.load(path)
    assert again == model
    assert "[effects.gravity_load]" in path.read_text()


@pytest.mark.parametrize(("text", "message"), [
    ('format = "other"\n', "format must be 'fha-axis-model/1'"),
    ('format = "fha-axis-model/1"\n', r"missing \[plant\]"),
    ('format = "fha-axis-model/1"\n[plant]\ntorque_constant_nm_per_a = 22\nmax_current_a = 7.3\n'
     'actuator_inertia_kgm2 = 0.8\nwidth = 3\n', "unknown plant field"),
    ('format = "fha-axis-model/1"\n[plant]\ntorque_constant_nm_per_a = -22\nmax_current_a = 7.3\n'
     'actuator_inertia_kgm2 = 0.8\n', "torque_constant_nm_per_a = -22 is outside"),
    ('format = "fha-axis-model/1"\n[plant]\ntorque_constant_nm_per_a = 22\nmax_current_a = 7.3\n'
     'actuator_inertia_kgm2 = 0.8\n[effects.stribeck]\nspeed = 1\n', "unknown effect id"),
    ("format = \n", "not valid TOML"),
])
def test_bad_model_files_are_refused_by_name(text, message):
    with pytest.raises(ValueError, match=message):
        AxisModel.from_toml(text, where="axis.toml")


def test_simulate_returns_the_contract_and_follows(make_model):
    model = make_model(CODE, 1.5)
    model = model.with_effects(catalogue_effects(model))
    t = np.arange(0, 3.0, 1e-3)
    cmd = np.radians(60) * (1 - np.cos(np.pi * t / 3.0)) / 2
    r = simulate(model, None, t, cmd)
    assert set(r) >= {"t", "pos", "load_pos", "current", "cmd_pos", "vel", "torque"}
    assert all(v.shape == t.shape for v in r.values())
    # without feed-forward the axis lags by speed / Kp (peak command speed pi/3 x pi/3 / 2 rad/s)
    lag = (math.pi / 3) * (math.pi / 3) / 2 / ServoSettings.tuned_for(model).position_loop_gain_per_s
    assert np.max(np.abs(r["pos"] - cmd)) == pytest.approx(lag, rel=0.05)
    assert np.allclose(r["cmd_pos"], cmd)
    assert np.allclose(r["torque"], 22 * r["current"])
    # monitors: position in whole encoder pulses, current in steps
    q = simulate(model, None, t, cmd, monitor=MonitorOptions.typical(model, seed=3))
    pulses = q["pos"] / model.output_pulse_rad
    assert np.allclose(pulses, np.round(pulses))
    step = 2 * model.max_current_a / 1024
    assert np.allclose(q["current"] / step, np.round(q["current"] / step))
    assert 0 < np.std(q["current"] - r["current"]) < 2 * step


@pytest.mark.parametrize(("t", "cmd", "message"), [
    ([0.0, 1.0], [0.0], "equally long"),
    ([0.0, 1.0, 1.0], [0.0, 0.0, 0.0], "time must increase, it does not at sample 2"),
    ([0.0, float("nan")], [0.0, 0.0], "non-finite time or command at sample 1"),
])
def test_simulate_refuses_bad_input(make_model, t, cmd, message):
    with pytest.raises(ValueError, match=message):
        simulate(make_model(CODE), None, np.array(t), np.array(cmd))


def test_small_and_large_step_blocks_give_the_same_motion(make_model):
    model = make_model(CODE, 1.5)
    model = model.with_effects(catalogue_effects(model))
    a, b = ServoAxis(model), ServoAxis(model)
    for axis in (a, b):
        axis.servo_on()
        axis.move_by(math.radians(20))
    for _ in range(2500):
        a.step(1)
    b.step(2500)
    assert a.snapshot() == pytest.approx(b.snapshot(), rel=1e-9, abs=1e-12)


def test_speed_mode_follows_the_speed_command(make_model):
    model = make_model(CODE, 1.5, Effects().with_effect("coulomb_friction", torque_nm=5.0))
    axis = ServoAxis(model, ServoSettings.tuned_for(model, control_mode="speed"))
    axis.servo_on()
    axis.jog(-30 * RPM, accel_rad_s2=20.0)
    axis.advance(0.1)
    # ramping: the axis follows the ramp closely, no position loop lag
    assert axis.output_speed_rad_s == pytest.approx(-2.0, rel=0.05)
    axis.advance(1.0)
    assert axis.output_speed_rpm == pytest.approx(-30, rel=1e-3)
    assert axis.error_pulses == 0
    assert axis.snapshot()["current_a"] * 22 == pytest.approx(-5.0, rel=1e-3)


def test_custom_axis_without_current_limit_round_trips(tmp_path):
    model = AxisModel(torque_constant_nm_per_a=30.0, max_current_a=math.inf, actuator_inertia_kgm2=2.0,
                      load_inertia_kgm2=1.0)
    assert "max_current_a = inf" in model.to_toml()
    assert AxisModel.from_toml(model.to_toml()) == model
    t = np.linspace(0, 1, 1001)
    r = simulate(model, ServoSettings(speed_loop_gain_a_s_per_rad=5.0), t, 0.1 * t)
    assert np.isfinite(r["current"]).all()
    with pytest.raises(ValueError, match="ratio is unknown"):
        model.with_effects(Effects().with_effect("kinematic_error", amplitude_arcsec=10.0))


def test_simulate_can_average_the_current_over_each_sample(make_model):
    # with ripple in the current (32 Hz here), the averaged 1 kHz monitor equals the mean of the
    # 5 kHz servo current over each 1 ms interval
    effects = Effects().with_effect("torque_ripple", amplitude_nm=3.0, cycles_per_motor_rev=2)
    model = make_model(CODE, 0.5, effects)
    t = np.arange(0, 1.0, 1e-3)
    cmd = 2.0 * t
    fine_t = np.arange(0, 0.999 + 1e-9, 2e-4)
    fine = simulate(model, None, fine_t, 2.0 * fine_t)
    avg = simulate(model, None, t, cmd, current_average=True)
    expected = fine["current"][1:].reshape(-1, 5).mean(axis=1)
    assert np.allclose(avg["current"][1:], expected, atol=1e-9)
    assert np.allclose(avg["torque"], 22 * avg["current"])


def test_quantised_feedback_holds_within_a_pulse_and_makes_current_noise(make_model):
    model = make_model(CODE, 1.5, Effects().with_effect("viscous_friction", coefficient_nm_s_per_rad=1.0))
    ideal = ServoSettings.tuned_for(model)
    real = ideal.replace(quantised_feedback=True, speed_filter_hz=300.0)
    traces = {}
    for name, settings in (("ideal", ideal), ("real", real)):
        axis = ServoAxis(model, settings)
        axis.servo_on()
        axis.jog(10 * RPM)
        axis.advance(1.0)
        axis.start_trace()
        axis.advance(1.0)
        traces[name] = axis.read_trace()
        axis.stop()
        axis.advance(1.0)
        assert abs(axis.error_pulses) <= 1
    # same mean torque (viscous x speed), but the pulse-difference speed makes the current noisy
    for tr in traces.values():
        assert np.mean(tr["current"]) * 22 == pytest.approx(10 * RPM, rel=0.02)
    assert np.std(traces["ideal"]["current"]) < 1e-6
    assert 0.01 < np.std(traces["real"]["current"]) < 0.5


def test_brake_holds_below_its_holding_torque_and_slips_above(make_model):
    # servo off, an unbalanced load of 40 N m at 90 degrees: a 50 N m brake holds it, a 30 N m one
    # lets it fall with (40 - 30) N m over the axis inertia
    effects = Effects().with_effect("gravity_load", amplitude_nm=40.0, phase_deg=0.0)
    model = make_model(CODE, 0.5, effects)
    axis = ServoAxis(model, initial_pos_rad=math.pi / 2)
    axis.set_brake(True, holding_torque_nm=50.0)
    assert axis.brake_engaged
    axis.advance(1.0)
    assert axis.output_pos_rad == math.pi / 2
    axis.set_brake(True, holding_torque_nm=30.0)
    axis.advance(0.01)
    assert axis.output_speed_rad_s == pytest.approx(-10.0 / 1.31 * 0.01, rel=0.02)
    axis.set_brake(False)
    assert not axis.brake_engaged


def test_clear_error_and_direction_change_rebase_the_command(make_model):
    model = make_model(CODE, 0.5)
    axis = ServoAxis(model)
    axis.servo_on()
    axis.add_command_pulses(5000)
    axis.step(10)
    assert axis.error_pulses > 4000
    axis.clear_error()
    assert axis.error_pulses == 0
    axis.advance(0.5)
    assert axis.output_speed_rad_s == pytest.approx(0.0, abs=1e-3)
    pos = axis.output_pos_rad
    axis.set_settings(axis.settings.replace(rotary_direction=1))
    axis.advance(0.2)
    assert axis.output_pos_rad == pytest.approx(pos, abs=2 * model.output_pulse_rad)
    assert axis.feedback_pulses < 0  # the drive now counts CW as negative
    axis.jog(5 * RPM)
    axis.advance(0.5)
    assert axis.output_pos_rad < pos  # FWD turns CCW now


def test_the_direction_sign_follows_the_manuals_rotary_direction_table():
    from fha_studio.catalog.tables import rotary_direction
    from fha_studio.physics import ServoSettings

    for setting in rotary_direction():
        sign = ServoSettings(rotary_direction=setting.value).direction_sign
        assert sign == (1.0 if setting.fwd_turns_cw else -1.0)
    with pytest.raises(ValueError, match="rotary_direction"):
        ServoSettings(rotary_direction=2)


def _every_period_interpolated(model, servo, t, cmd):
    """simulate()'s samples the plain way: every servo period recorded, then interpolated."""
    from fha_studio.physics import _kernel
    simulate_module = importlib.import_module("fha_studio.physics.simulate")  # the name is the function
    from fha_studio.physics.servo import kernel_params

    p = kernel_params(model, servo)
    n = math.ceil((t[-1] - t[0]) / p.dt - 1e-9) + 1
    state = _kernel.KernelState()
    simulate_module._initialise_at_rest(state, p, float(cmd[0]), True)
    first = [p.direction * state.cprev, state.xm, state.xl, state.vm, state.current, state.vref,
             state.flange_torque]
    t_servo = p.dt * np.arange(1, n + 1)
    rec: tuple[list, ...] = ([], [], [], [], [], [], [], [])
    _kernel.run(p, state, (p.direction * np.interp(t[0] + t_servo, t, cmd)).tolist(), n, True, rec, 1)
    ts = np.concatenate(([0.0], t_servo))
    keys = ("cmd_pos", "pos", "load_pos", "vel", "current", "speed_cmd", "flange_torque")
    return {k: np.interp(t - t[0], ts, np.concatenate(([first[j]], rec[j + 1]))) for j, k in enumerate(keys)}


@pytest.mark.parametrize("case", ["rigid", "compliant", "quantised", "uneven"])
def test_simulate_keeps_only_the_periods_its_samples_need_bit_for_bit(make_model, monkeypatch, case):
    # simulate() records only the servo periods each sample falls between (and runs in chunks):
    # the samples are exactly those of the whole per-period trace interpolated
    simulate_module = importlib.import_module("fha_studio.physics.simulate")  # the name is the function

    monkeypatch.setattr(simulate_module, "SIMULATION_CHUNK", 997)  # several chunks in 1.5 s
    effects = Effects().with_effect("coulomb_friction", torque_nm=3.0).with_effect(
        "gravity_load", amplitude_nm=8.0, phase_deg=20.0).with_effect(
        "torque_ripple", amplitude_nm=0.5, cycles_per_motor_rev=2)
    if case == "compliant":
        effects = effects.with_effect("torsional_compliance").with_effect("lost_motion", width_arcsec=40.0)
    model = make_model(CODE, 1.5, effects)
    servo = ServoSettings.tuned_for(model, quantised_feedback=case == "quantised")
    if case == "uneven":
        t = np.cumsum(np.random.default_rng(4).uniform(3e-4, 2.1e-3, 1200))
    else:
        t = np.arange(0.0, 1.5, 1e-3)
    cmd = 1.5 * np.sin(2.0 * t) + 0.3 * np.sin(9.0 * t)
    got = simulate(model, servo, t, cmd)
    expected = _every_period_interpolated(model, servo, t, cmd)
    for key, values in expected.items():
        assert np.array_equal(got[key], values), key


def test_the_kernels_accounting_does_not_change_the_motion(make_model):
    from fha_studio.physics import _kernel
    from fha_studio.physics.servo import kernel_params

    model = make_model(CODE, 1.5, Effects().with_effect("coulomb_friction", torque_nm=3.0))
    p = kernel_params(model, ServoSettings.tuned_for(model))
    cmd = (0.5 * np.sin(np.arange(3000) * 1e-3)).tolist()
    states = [_kernel.KernelState(), _kernel.KernelState()]
    for state, accounting in zip(states, (True, False), strict=True):
        _kernel.run(p, state, cmd, len(cmd), True, accounting=accounting)
    with_, without = states
    assert (with_.xm, with_.vm, with_.integ, with_.current) == (without.xm, without.vm, without.integ,
                                                                 without.current)
    assert with_.i2_integral > 0 and without.i2_integral == 0.0


@pytest.mark.parametrize("load_ratio", [0.0, 1.0, 3.0, 10.0])
def test_the_panels_speed_loop_gain_is_read_on_the_actuators_own_inertia(load_ratio):
    """Tune 0 (Hz) sets Kv = 2 pi f J_A / Kt whatever the load (resources' note on tune 0: a drive
    does not know its load), so a load J_L lowers the crossover to f J_A / (J_A + J_L); the
    simulated drive's loops are that mapping's."""
    from fha_studio.hardware.parameters import Mode, load_parameter_model
    from fha_studio.hardware.sim.drive import SimDrive

    parameters = load_parameter_model("HA-655")
    items = {it.key: it.default for it in parameters if it.mode in (Mode.TUNE, Mode.SYSTEM)
             and it.default is not None}
    code = "FHA-25C-50-US250"
    own = AxisModel.from_code(code).actuator_inertia_kgm2
    model = AxisModel.from_code(code, load_inertia_kgm2=load_ratio * own)
    settings = servo_settings(model, items, 5000.0)
    kv = 2.0 * math.pi * items["speed_loop_gain"] * own / model.torque_constant_nm_per_a
    assert settings.speed_loop_gain_a_s_per_rad == pytest.approx(kv, rel=1e-12)
    assert PanelGains.of_settings(model, settings) == PanelGains.from_items(items)
    # the rigid body's proportional loop Kt Kv / (J s) crosses 1 where PanelGains says
    crossover = PanelGains.crossover_hz(model, items["speed_loop_gain"])
    w = 2.0 * math.pi * crossover
    assert model.torque_constant_nm_per_a * kv / (model.total_inertia_kgm2 * w) == pytest.approx(1.0)
    assert crossover == pytest.approx(items["speed_loop_gain"] / (1.0 + load_ratio))
    with SimDrive(code, stepped=True, load_inertia_kgm2=load_ratio * own) as drive:
        assert drive.axis.settings.speed_loop_gain_a_s_per_rad == pytest.approx(kv, rel=1e-12)
