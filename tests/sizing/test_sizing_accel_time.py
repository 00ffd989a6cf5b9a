"""The manual accelerates each actuator at its own maximum torque (2-4-4), so a larger frame can
fail the effective-torque check that a smaller one passes. A given acceleration time sizes for
the move the machine needs, and the result says which assumption decided."""

from __future__ import annotations

import math

import pytest

from fha_studio.logic.sizing import DutyCycle, size_axis
from fha_studio.logic.sizing.axis import SizingError

DUTY = {"load_inertia_kgm2": 1.2, "speed_rpm": 40.0, "angle_deg": 120.0, "cycle_time_s": 1.5}


def check(result, name):
    return next(c for c in result.checks if c.name == name)


def test_at_the_maximum_torque_the_larger_frame_fails_and_the_result_says_why():
    big = size_axis("FHA-25C-50-US250", DutyCycle(**DUTY))
    assert not check(big, "effective torque").ok
    assert "maximum torque TM = 150 N·m" in big.assumption and "acceleration time" in big.assumption
    assert big.as_dict()["assumption"] == big.assumption


def test_a_given_acceleration_time_sizes_for_that_move():
    duty = DutyCycle(**DUTY, accel_time_s=0.15)
    big = size_axis("FHA-25C-50-US250", duty)
    assert big.accel_time_s == big.decel_time_s == 0.15
    # Ta = (JA + JL) 2π/60 N / ta: the torque the move takes, well below TM = 150 N m
    ta_torque = (big.ratings.inertia_kgm2 + 1.2) * 2 * math.pi / 60 * 40 / 0.15
    assert check(big, "acceleration torque").value == pytest.approx(ta_torque)
    assert check(big, "effective torque").ok and big.ok
    assert "in the given 0.15 s" in big.assumption
    points = {p.phase: p.torque_nm for p in big.operating_points()}
    assert points["acceleration"] == pytest.approx(ta_torque)


def test_an_acceleration_time_the_actuator_cannot_reach_fails_the_acceleration_torque():
    result = size_axis("FHA-17C-50-US250", DutyCycle(**DUTY, accel_time_s=0.01))
    torque = check(result, "acceleration torque")
    assert not torque.ok and torque.limit == result.ratings.max_torque_nm


@pytest.mark.parametrize("bad", [0.0, -1.0, math.inf, math.nan])
def test_a_bad_acceleration_time_is_refused(bad):
    with pytest.raises(SizingError, match="accel_time_s must be a number > 0"):
        DutyCycle(**DUTY, accel_time_s=bad)
