"""The 2-4 formulas beyond the worked examples: load torque, load-torque sign, short moves."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fha_studio.logic.sizing import ActuatorRatings, DutyCycle, SizingError, evaluate
from fha_studio.logic.sizing import duty as f

RATINGS = ActuatorRatings("FHA-25C-50-US250", 150.0, 90.0, 10.6, 0.81, 35.0, 70.0, 2.4)


def test_load_torques_2_4_3():
    assert f.rotary_friction_torque_nm(0.1, 100, 0.2) == pytest.approx(19.6)
    assert f.horizontal_screw_torque_nm(0.1, 100, 0.01) == pytest.approx(0.98 / (2 * math.pi))
    assert f.vertical_screw_torque_nm(100, 0.01) == pytest.approx(9.8 / (2 * math.pi))
    assert f.speed_from_linear_rpm(6000, 10) == 600


def test_load_torque_opposing_rotation_slows_acceleration_and_helps_braking():
    ta0 = f.accel_time_s(0.81, 1.5, 60, 150, 0)
    td0 = f.decel_time_s(0.81, 1.5, 60, 150, 10.6, 0)
    assert f.accel_time_s(0.81, 1.5, 60, 150, 20) > ta0
    assert f.decel_time_s(0.81, 1.5, 60, 150, 10.6, 20) < td0
    # a load turning with the rotation (TL < 0, e.g. a falling mass) does the opposite
    assert f.accel_time_s(0.81, 1.5, 60, 150, -20) < ta0
    assert f.decel_time_s(0.81, 1.5, 60, 150, 10.6, -20) > td0
    assert f.decel_time_s(0.81, 1.5, 60, 150, 10.6, 20) == pytest.approx(
        2.31 * 2 * math.pi / (150 + 21.2 + 20)
    )


def test_load_torque_above_max_torque_fails_instead_of_a_negative_time():
    r = evaluate(RATINGS, DutyCycle(1.5, 60, 120, 2.0, load_torque_nm=160))
    assert math.isinf(r.accel_time_s)
    assert not next(c for c in r.checks if c.name == "load torque").ok
    assert r.as_dict()["accel_time_s"] is None  # JSON-safe


def test_overhauling_load_above_braking_torque_fails():
    r = evaluate(RATINGS, DutyCycle(1.5, 60, 120, 2.0, load_torque_nm=-200))
    check = next(c for c in r.checks if c.name == "load torque while braking")
    assert not check.ok and check.limit == pytest.approx(150 + 2 * 10.6)
    assert math.isinf(r.decel_time_s) and not r.ok
    ok = evaluate(RATINGS, DutyCycle(1.5, 60, 120, 2.0, load_torque_nm=-20))
    assert next(c for c in ok.checks if c.name == "load torque while braking").ok


def test_move_too_short_to_reach_speed_is_a_failed_check():
    r = evaluate(RATINGS, DutyCycle(1.5, 60, 10, 2.0))  # needs ~32.7 deg to reach 60 r/min
    assert r.run_time_s == 0.0
    check = next(c for c in r.checks if c.name == "move reaches speed")
    assert not check.ok
    assert check.limit == pytest.approx(6 * 60 * (r.accel_time_s + r.decel_time_s) / 2)
    assert "too short" in check.note


def test_move_longer_than_cycle_fails():
    r = evaluate(RATINGS, DutyCycle(1.5, 60, 720, 1.0))
    assert not next(c for c in r.checks if c.name == "move time within cycle").ok


def test_allowable_inertia_and_speed_checks():
    r = evaluate(RATINGS, DutyCycle(3.0, 95, 360, 20))
    by_name = {c.name: c for c in r.checks}
    assert not by_name["load inertia"].ok and by_name["load inertia"].section == "2-1"
    assert not by_name["speed"].ok


def test_regeneration_over_builtin_resistor_names_the_external_resistor():
    r = evaluate(RATINGS, DutyCycle(2.4, 90, 360, 0.5))
    regen = next(c for c in r.checks if c.name == "regeneration power")
    assert not regen.ok
    assert r.external_resistor_w == pytest.approx(r.regeneration_power_w - 40)
    assert "external regeneration resistor" in regen.note


@pytest.mark.parametrize(
    "kwargs",
    [
        {"load_inertia_kgm2": -1.0},
        {"speed_rpm": 0.0},
        {"angle_deg": -5.0},
        {"cycle_time_s": math.nan},
        {"duty_factors": (7.0, 1.0)},
        {"duty_factors": (7.0, -1.0, 7.0)},
    ],
)
def test_bad_duty_is_rejected_naming_the_field(kwargs):
    base = {"load_inertia_kgm2": 1.5, "speed_rpm": 60.0, "angle_deg": 120.0, "cycle_time_s": 2.0}
    base.update(kwargs)
    with pytest.raises(SizingError, match=next(iter(kwargs))):
        DutyCycle(**base)


def test_operating_points_and_envelope():
    r = evaluate(RATINGS, DutyCycle(1.5, 60, 120, 2.0))
    points = r.operating_points()
    assert points[0].phase == "acceleration"
    assert max(p.speed_rpm for p in points) == 60
    assert points[-1].torque_nm == pytest.approx(r.effective_torque_nm)
    assert r.envelope()["continuous_torque_nm"] == 35.0


@settings(max_examples=40, deadline=None)
@given(
    jl=st.floats(0.0, 2.4),
    n=st.floats(1.0, 90.0),
    angle=st.floats(1.0, 3600.0),
    t=st.floats(0.1, 100.0),
)
def test_figures_are_consistent(jl, n, angle, t):
    r = evaluate(RATINGS, DutyCycle(jl, n, angle, t))
    assert r.run_time_s >= 0
    assert r.accel_time_s > r.decel_time_s > 0  # friction helps braking
    reaches = next(c for c in r.checks if c.name == "move reaches speed").ok
    if reaches:  # the trapezoid covers the angle, so the average speed is θ/6/t
        assert r.average_speed_rpm == pytest.approx(angle / 6 / t, rel=1e-9)
    # at the minimum cycle time the effective torque is the continuous torque
    assert f.effective_torque_nm(
        150, 0, r.accel_time_s, r.run_time_s, r.decel_time_s, r.min_cycle_time_s
    ) == (pytest.approx(35.0))
    assert (
        next(c for c in r.checks if c.name == "effective torque").ok
        == next(c for c in r.checks if c.name == "cycle time").ok
    )
