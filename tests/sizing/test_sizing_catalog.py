"""The calculator on the catalogue: size_axis, the ratings it reads, the suggestions."""

from __future__ import annotations

import pytest

from fha_studio.logic.sizing import DutyCycle, SizingError, actuator_ratings, size_axis, suggest_actuators
from fha_studio.logic.sizing.axis import size_all

EXAMPLE = DutyCycle(1.5, 60, 120, 2.0, duty_factors=(7, 1, 7))


def test_ratings_of_the_examples_actuator():
    r = actuator_ratings("FHA-25C-50-US250")
    assert (r.max_torque_nm, r.inertia_kgm2, r.max_speed_rpm) == (150, 0.81, 90)
    assert r.friction_torque_nm == pytest.approx(10.6)
    assert (r.continuous_torque_nm, r.continuous_speed_rpm, r.allowable_inertia_kgm2) == (35, 70, 2.4)
    b = r.bearing  # 2-3 Table 1, FHA-25C
    assert b.pitch_circle_m == pytest.approx(0.0962) and b.offset_m == pytest.approx(0.018)
    assert (b.dynamic_load_rating_n, b.static_load_rating_n) == (18000, 33300)
    assert (b.allowable_radial_load_n, b.allowable_axial_load_n, b.allowable_moment_nm) == (4900, 14700, 370)


def test_size_axis_reproduces_the_examples():
    r = size_axis("FHA-25C-50-US250", EXAMPLE)
    assert round(r.accel_time_s, 3) == 0.097 and round(r.decel_time_s, 3) == 0.085
    assert round(r.percent_ed) == 76 and round(r.effective_torque_nm) == 45
    assert {c.name for c in r.failed} == {"effective torque", "cycle time"}


def test_unknown_actuator():
    with pytest.raises(SizingError, match="unknown actuator 'FHA-25C-55-US250'"):
        size_axis("FHA-25C-55-US250", EXAMPLE)


def test_suggestions_pass_every_check_smallest_first():
    duty = DutyCycle(0.2, 20, 90, 5.0)
    everything = size_all(duty)
    assert len(everything) == 12 and all(r.actuator_code.endswith("US250") for r in everything)
    passing = suggest_actuators(duty)
    assert passing and all(r.ok for r in passing)
    assert [r.actuator_code for r in passing] == [r.actuator_code for r in everything if r.ok]
    assert passing[0].actuator_code == "FHA-17C-50-US250"
    # the examples' duty passes nowhere: Tm at maximum torque beats every continuous rating
    assert suggest_actuators(EXAMPLE) == []
    assert suggest_actuators(duty, encoder_code="S248")[0].actuator_code == "FHA-17C-50-S248"
