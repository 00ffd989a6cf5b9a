"""The command profiles: trapezoid, triangle, jog ramps, stop, checked against hand formulas."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fha_studio.physics import MotionGenerator


def test_trapezoid():
    # 2 rad at 1 rad/s with 4 rad/s^2: 0.25 s ramps (0.125 rad each), 1.75 rad cruise in 1.75 s
    g = MotionGenerator(1.0)
    g.move_by(0.5, 2.0, 1.0, 4.0)
    assert g.end_time_s() == pytest.approx(0.5 + 0.25 + 1.75 + 0.25)
    assert g.state_at(0.75) == pytest.approx((1.125, 1.0))
    assert g.state_at(2.5) == pytest.approx((1.0 + 2.0 - 0.125, 1.0))
    assert g.state_at(10.0) == pytest.approx((3.0, 0.0))
    assert g.target_rad == pytest.approx(3.0)
    t = np.linspace(0, 3.0, 3001)
    p = g.positions(t)
    assert p[0] == 1.0 and p[-1] == pytest.approx(3.0)
    assert np.all(np.diff(p) >= -1e-15)
    assert np.max(np.diff(p) / np.diff(t)) == pytest.approx(1.0, rel=1e-3)


def test_triangle_and_negative_move():
    # -0.1 rad at up to 1 rad/s with 4 rad/s^2 never reaches speed: peak sqrt(0.1 x 4) = 0.632 rad/s
    g = MotionGenerator()
    g.move_by(0.0, -0.1, 1.0, 4.0)
    t_peak = math.sqrt(0.1 * 4.0) / 4.0
    assert g.state_at(t_peak) == pytest.approx((-0.05, -math.sqrt(0.4)))
    assert g.state_at(2 * t_peak) == pytest.approx((-0.1, 0.0))


def test_jog_ramp_then_stop():
    g = MotionGenerator()
    g.jog(0.0, 2.0, 8.0)  # 0.25 s ramp, 0.25 rad
    assert g.state_at(0.25) == pytest.approx((0.25, 2.0))
    assert g.state_at(1.25) == pytest.approx((2.25, 2.0))
    assert math.isnan(g.target_rad)
    g.jog(1.25, -2.0, 8.0)  # reverse from +2 to -2 rad/s: 0.5 s, net 0 rad
    assert g.state_at(1.75) == pytest.approx((2.25, -2.0))
    g.stop(2.0, 4.0)  # at 2.0 s: 1.75 rad, -2 rad/s; to rest in 0.5 s, 0.5 rad further back
    assert g.state_at(3.0) == pytest.approx((1.25, 0.0))
    assert g.target_rad == pytest.approx(1.25)


def test_instant_jog_and_refusals():
    g = MotionGenerator()
    g.jog(0.0, 1.0, math.inf)
    assert g.state_at(0.5) == pytest.approx((0.5, 1.0))
    with pytest.raises(ValueError, match="standstill"):
        g.move_by(1.0, 1.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="accel_rad_s2 must be positive"):
        g.jog(1.0, 0.0, 0.0)
    g.shift(0.25)
    assert g.state_at(0.5) == pytest.approx((0.75, 1.0))
