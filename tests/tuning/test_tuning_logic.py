"""The tuning logic on the physics model itself: the linearised loops against the simulated loop
excited at the speed command (PRBS, one period per record), the gear's resonance and the inertia
in the measured plant, and the proposed gains' margins."""

from __future__ import annotations

import math

import control
import numpy as np
import pytest

from fha_studio.hardware.parameters import Mode, load_parameter_model
from fha_studio.hardware.protocol import excitation_period_periods
from fha_studio.hardware.sim.excitation import SimExcitation, prbs_bits
from fha_studio.logic.tuning.excitation import RPM, plan_excitation
from fha_studio.logic.tuning.linear import LoopModel, two_mass_prediction
from fha_studio.logic.tuning.propose import AIMS, Tuner, screen_margins
from fha_studio.logic.tuning.response import estimate_response, fit_two_mass, loop_figures
from fha_studio.physics import AxisModel, Effects, ServoAxis, servo_settings

PARAMETERS = load_parameter_model("HA-655")
DEFAULTS = {it.key: it.default for it in PARAMETERS if it.mode in (Mode.TUNE, Mode.SYSTEM)
            and it.default is not None}
RATE = 5000.0


def _model(code: str, load_ratio: float) -> AxisModel:
    own = AxisModel.from_code(code).total_inertia_kgm2
    return AxisModel.from_code(code, load_inertia_kgm2=load_ratio * own,
                               effects=Effects().with_effect("torsional_compliance"))


def test_prbs_is_maximum_length() -> None:
    for bits in (4, 9, 11, 12):
        seq, _ = prbs_bits(2 * ((1 << bits) - 1), bits)
        period = (1 << bits) - 1
        assert seq[:period] == seq[period:]
        assert sum(seq[:period]) == (period + 1) // 2  # a maximum-length sequence's ones


@pytest.mark.parametrize(("code", "load_ratio"), [("FHA-25C-50-US250", 1.0), ("FHA-40C-160-S248", 3.0)])
def test_linearisation_matches_the_simulated_loop(code: str, load_ratio: float) -> None:
    model = _model(code, load_ratio)
    settings = servo_settings(model, DEFAULTS, RATE, quantised_feedback=False)
    lm = LoopModel(model, settings)
    plan = plan_excitation(lm)
    hold = plan.hold_periods
    axis = ServoAxis(model, settings)
    axis.servo_on()
    excitation = SimExcitation(amplitude_rad_s=plan.amplitude_rpm * RPM)
    excitation.start(hold, 0.0, math.inf, 0.0)
    period = excitation_period_periods(hold)
    assert period == plan.period_samples
    axis.step(5000, excitation.values(5000))
    closed, plant = [], []
    for _ in range(5):
        axis.start_trace(1)
        axis.step(period, excitation.values(period))
        trace = axis.read_trace()
        closed.append((trace["speed_cmd"], trace["vel"]))
        plant.append((trace["current"] * model.torque_constant_nm_per_a, trace["vel"]))
    assert np.abs(trace["current"]).max() <= plan.peak_current_a < model.max_current_a
    assert math.degrees(np.ptp(trace["pos"])) <= 2 * plan.travel_bound_deg
    f_max = plan.f_max_hz
    for which, records in (("closed", closed), ("plant", plant)):
        measured = estimate_response(records, RATE, f_max_hz=f_max)
        mag, phase = lm.response(which, measured.freq_hz)
        ok = measured.trusted()
        assert ok.sum() > 0.8 * len(ok)
        assert np.max(np.abs(measured.magnitude_db - mag)[ok]) <= 1.0
        assert np.max(np.abs((measured.phase_deg - phase + 180.0) % 360.0 - 180.0)[ok]) <= 5.0
    measured_plant = estimate_response(plant, RATE, f_max_hz=f_max)
    found = fit_two_mass(measured_plant, RATE)
    assert found is not None
    predicted = two_mass_prediction(model)
    assert found.resonance_hz == pytest.approx(predicted.resonance_hz, rel=0.1)
    assert found.antiresonance_hz == pytest.approx(predicted.antiresonance_hz, rel=0.1)
    assert found.total_inertia_kgm2 == pytest.approx(model.total_inertia_kgm2, rel=0.1)


@pytest.mark.parametrize(("code", "load_ratio", "quantised"),
                         [("FHA-25C-50-US250", 10.0, True), ("FHA-40C-160-S248", 1.0, False)])
def test_the_searchs_loops_are_the_linearisations(code: str, load_ratio: float, quantised: bool) -> None:
    """The numpy loops the proposal searches with (LoopPolynomials) are python-control's: the same
    margins, the same poles' verdict, the same response to the verification move."""
    model = _model(code, load_ratio)
    tuner = Tuner(model, DEFAULTS, PARAMETERS, RATE, quantised_feedback=quantised)
    command = tuner.move_profile().command_rad(RATE)
    t = np.arange(len(command)) / RATE
    for tune in ({}, {"speed_loop_gain": 20, "speed_loop_integral_compensation": 45, "position_loop_gain": 60,
                      "feed_forward_gain": 50}):
        lm = tuner.loop(tune)
        poly = lm.polynomials()
        official = loop_figures(lm.speed_open_loop(), lm.speed_closed_loop(), 0.49 * RATE)
        grid = np.logspace(-1.0, math.log10(0.49 * RATE), 400)
        gm, pm, _crossover = screen_margins(poly.speed_open_loop_at(grid), grid)
        # python-control says None where the phase never crosses -180 deg (the screen: inf)
        official_gm = math.inf if official.gain_margin_db is None else official.gain_margin_db
        assert gm == pytest.approx(official_gm, abs=0.05)
        assert pm == pytest.approx(official.phase_margin_deg, abs=0.5)
        assert poly.stable() == lm.stable()
        reference = control.forced_response(lm.position_closed_loop(), T=t, U=command)
        position, _current = poly.move(command)
        pulse = model.output_pulse_rad
        assert np.max(np.abs(position - np.asarray(reference.outputs).reshape(-1))) < 1e-3 * pulse


def test_beyond_2_1_the_proposal_is_softer_and_says_so() -> None:
    """10 x the actuator's own inertia: neither a stiff nor a standard aim is followed but the soft
    aim's margins, with a speed loop crossing over and a position loop gain no higher than the
    standard aim's proposal (shown beside it); the warning names FHA-C manual 2-1."""
    model = _model("FHA-25C-50-US250", 10.0)
    tuner = Tuner(model, DEFAULTS, PARAMETERS, RATE)
    proposal = tuner.propose("stiff")
    assert proposal.used_aim == "soft"
    assert "2-1" in (proposal.warning or "") and "softer" in (proposal.warning or "")
    assert proposal.proposed.meets(*AIMS["soft"])
    reference = proposal.reference
    assert reference is not None and reference.meets(*AIMS["standard"])
    grid = np.logspace(-1.0, math.log10(0.49 * RATE), 400)

    def crossover(items: dict[str, int]) -> float:
        return screen_margins(tuner.loop(items).polynomials().speed_open_loop_at(grid), grid)[2]

    assert crossover(proposal.proposed.items) <= crossover(reference.items)
    assert proposal.proposed.items["position_loop_gain"] <= reference.items["position_loop_gain"]
    assert proposal.proposed.overshoot_pct is not None and proposal.proposed.overshoot_pct <= 10.0
    assert proposal.proposed.settling_ms is not None


@pytest.mark.parametrize("load_ratio", [0.0, 3.0])
def test_inertia_from_a_move(load_ratio: float) -> None:
    from fha_studio.logic.tuning.response import inertia_from_move

    model = _model("FHA-25C-50-US250", load_ratio)
    axis = ServoAxis(model, servo_settings(model, DEFAULTS, RATE, quantised_feedback=False))
    axis.servo_on()
    axis.start_trace(5)
    axis.move_by(math.radians(90.0), speed_rad_s=0.5 * model.max_speed_rad_s,
                 accel_rad_s2=0.5 * model.max_acceleration_rad_s2())
    axis.advance(1.5)
    trace = axis.read_trace()
    estimate = inertia_from_move(trace["t"], trace["vel"], trace["current"] * model.torque_constant_nm_per_a)
    assert estimate == pytest.approx(model.total_inertia_kgm2, rel=0.1)
