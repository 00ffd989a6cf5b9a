"""Golden tests: the worked Examples 1-3 of FHA-C manual 2-4 (FHA-25C-50), within its rounding.

The manual rounds every intermediate figure to three decimals and carries the rounded value on;
where that (or a slip) moves a printed figure, the test states the correct value and the printed one.
"""

from __future__ import annotations

import math

import pytest

from fha_studio.logic.sizing import ActuatorRatings, DutyCycle, evaluate
from fha_studio.logic.sizing import duty as f

# FHA-25C-50 as Examples 1-3 read it from 1-4 and 2-1 / 2-4-6.
JA, TM, KT, IM = 0.81, 150.0, 22.0, 7.3
JL, N, THETA, T = 1.5, 60.0, 120.0, 2.0
RATINGS = ActuatorRatings(
    code="FHA-25C-50-US250",
    max_torque_nm=TM,
    max_speed_rpm=90.0,
    friction_torque_nm=KT * IM - TM,
    inertia_kgm2=JA,
    continuous_torque_nm=35.0,
    continuous_speed_rpm=70.0,
    allowable_inertia_kgm2=2.4,
)


def example(cycle_time_s: float = T):
    return evaluate(RATINGS, DutyCycle(JL, N, THETA, cycle_time_s, duty_factors=(7.0, 1.0, 7.0)))


def test_example_1_friction_torque():
    # (3) TF = 22 x 7.3 - 150 = 10.6 N m
    assert f.friction_torque_nm(KT, IM, TM) == pytest.approx(10.6, abs=1e-9)
    assert example().friction_torque_nm == pytest.approx(10.6, abs=1e-9)


def test_example_1_accel_and_decel_times():
    r = example()
    assert round(r.accel_time_s, 3) == 0.097  # 0.09676
    assert round(r.decel_time_s, 3) == 0.085  # 0.08478
    assert f.accel_time_s(JA, JL, N, TM) == r.accel_time_s
    assert f.decel_time_s(JA, JL, N, TM, 10.6) == pytest.approx(r.decel_time_s)


def test_example_2_run_time():
    # Printed tr = (0.333 - 0.091) / 1 = 0.242 s from rounded 0.333 and 0.091; unrounded it is
    # 1/3 - 0.18154/2 = 0.2426 s, which Example 3 prints as 0.243.
    r = example()
    assert r.run_time_s == pytest.approx(0.2426, abs=5e-5)
    assert abs(r.run_time_s - 0.242) <= 0.001
    assert f.run_time_s(THETA, N, 0.097, 0.085) == pytest.approx(0.242, abs=5e-4)  # the manual's own inputs
    # the trapezoid's area is the angle: θ = (N/60) (tr + (ta + td)/2) x 360
    assert N / 60 * (r.run_time_s + (r.accel_time_s + r.decel_time_s) / 2) * 360 == pytest.approx(THETA)


def test_example_2_percent_ed():
    # %ED = (7 x 0.097 + 1 x 0.242 + 7 x 0.085) / 2 x 100 = 76 % (75.8 from rounded inputs, 75.7 unrounded)
    r = example()
    assert round(r.percent_ed) == 76
    assert f.percent_ed(7, 1, 7, 0.097, 0.242, 0.085, 2.0) == pytest.approx(75.8)
    ed = next(c for c in r.checks if c.name == "%ED")
    assert ed.ok and ed.limit == 100 and ed.section == "2-4-5"


def test_example_3_effective_torque_and_cycle_limit():
    r = example()
    assert round(r.effective_torque_nm) == 45  # 45.19
    tm = next(c for c in r.checks if c.name == "effective torque")
    assert not tm.ok and tm.limit == 35.0  # "impossible to drive the actuator continuously"
    # T = 150^2 x (0.097 + 0.085) / 35^2 = 3.34 s: 3.343 from the rounded times, 3.334 unrounded
    assert f.min_cycle_time_s(150, 0, 0.097, 0.243, 0.085, 35) == pytest.approx(3.343, abs=5e-4)
    assert abs(r.min_cycle_time_s - 3.34) <= 0.01
    cycle = next(c for c in r.checks if c.name == "cycle time")
    assert not cycle.ok and cycle.limit == pytest.approx(r.min_cycle_time_s)


def test_example_3_at_the_longer_cycle():
    # "when the time for one duty cycle is set more than 3.4 s, the effective torque becomes less
    # than 34.0 N m": at 3.4 s Tm is 34.7 N m (below the 35 N m that matters, not below 34.0).
    r = example(3.4)
    assert r.effective_torque_nm == pytest.approx(34.66, abs=0.01)
    assert r.ok


def test_example_3_average_speed():
    # The parameter list says t = 3.5 s but the formula divides by 3.4: Nav = 5.88 r/min at 3.4 s
    # (5.71 r/min at 3.5 s). Unrounded, N/2 ta + N tr + N/2 td = θ/6 exactly.
    assert round(example(3.4).average_speed_rpm, 2) == 5.88
    assert round(example(3.5).average_speed_rpm, 2) == 5.71
    assert f.average_speed_rpm(60, 0.097, 0.242, 0.085, 3.4) == pytest.approx(5.876, abs=5e-4)
    assert example(3.4).average_speed_rpm == pytest.approx(THETA / 6 / 3.4)


def test_example_regeneration_uses_kinetic_energy():
    r = example()
    # 1/2 (0.81 + 1.5) (2π)^2 = 45.6 J per cycle, 22.8 W at 2 s: within the 40 W built-in resistor
    assert r.regeneration_energy_j == pytest.approx(0.5 * 2.31 * (2 * math.pi) ** 2)
    assert r.regeneration_power_w == pytest.approx(22.80, abs=0.01)
    regen = next(c for c in r.checks if c.name == "regeneration power")
    assert regen.ok and regen.limit == 40.0 and "squaring the inertia" in regen.note
    # the printed formula, 1/2 (JA + JL)^2 (2πN/60) / t - 40, would say 8.4 - 40 W
    assert f.printed_external_resistor_w(2.31, 60, 2.0, 40.0) + 40 == pytest.approx(8.38, abs=0.01)


def test_examples_checks_that_pass():
    r = example()
    by_name = {c.name: c for c in r.checks}
    for name in (
        "load inertia",
        "speed",
        "load torque",
        "move reaches speed",
        "move time within cycle",
        "%ED",
        "average speed",
        "regeneration power",
    ):
        assert by_name[name].ok, name
    assert {c.name for c in r.failed} == {"effective torque", "cycle time"}
