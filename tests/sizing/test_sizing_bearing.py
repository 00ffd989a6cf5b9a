"""Cross-roller bearing checks of 2-3 against hand-worked figures."""

from __future__ import annotations

import math

import pytest

from fha_studio.logic.sizing import (
    ActuatorRatings,
    BearingLoads,
    BearingRatings,
    DutyCycle,
    LoadSegment,
    evaluate,
)
from fha_studio.logic.sizing import bearing as b

# FHA-25C, Table 1 of 2-3, in SI
FHA25 = BearingRatings(0.0962, 0.018, 18000, 33300, 4900, 14700, 370)


def test_worked_case():
    # Frmax 1000 N at Lr = 50 mm, Famax 2000 N at La = 30 mm, Nav 10 r/min, fw 1.5
    loads = BearingLoads(
        max_radial_load_n=1000, max_axial_load_n=2000, radial_offset_m=0.05, axial_offset_m=0.03
    )
    r = b.check_bearing(FHA25, loads, average_speed_rpm=10)
    assert r.max_moment_nm == pytest.approx(1000 * 0.068 + 2000 * 0.03)  # 128 N m
    assert r.load_factor_ratio == pytest.approx(2000 / (1000 + 2 * 128 / 0.0962))  # 0.546
    assert (r.x, r.y) == (1.0, 0.45)
    pc = 1000 + 2 * 128 / 0.0962 + 0.45 * 2000  # 4561 N
    assert r.dynamic_load_n == pytest.approx(pc)
    assert r.life_h == pytest.approx(1e6 / 600 * (18000 / (1.5 * pc)) ** (10 / 3))  # about 41 900 h
    assert r.life_h == pytest.approx(41_900, rel=0.005)
    assert r.static_load_n == pytest.approx(1000 + 2 * 128 / 0.0962 + 0.44 * 2000)
    assert r.static_safety_factor == pytest.approx(7.333, abs=1e-3)
    assert all(c.ok for c in r.checks)
    assert {c.name for c in r.checks} == {
        "maximum radial load", "maximum axial load", "maximum torsional moment", "static safety factor",
    }  # fmt: skip


def test_axial_ratio_uses_the_axial_load():
    # Mostly axial: Faav / (Frav + 2 (...)/dp) = 18 > 1.5 gives X = Y = 0.67; the printed (5), with
    # Frav on top, would give 0.73 and X = 1, Y = 0.45, and a load 30 % lower.
    ratio = b.load_factor_ratio(200, 5000, 0, 0, 0.018, 0.0962)
    assert ratio == pytest.approx(5000 / (200 + 2 * 200 * 0.018 / 0.0962))
    assert b.load_factors(ratio) == (0.67, 0.67)
    assert b.load_factors(1.5) == (1.0, 0.45)


def test_limits_over_allowable_and_static_safety_by_use():
    loads = BearingLoads(max_radial_load_n=5000, max_axial_load_n=0, radial_offset_m=0.1, use="precise")
    r = b.check_bearing(FHA25, loads, average_speed_rpm=10)
    by = {c.name: c for c in r.checks}
    assert not by["maximum radial load"].ok  # 5000 > 4900 N
    assert not by["maximum torsional moment"].ok  # 5000 x 0.118 = 590 > 370 N m
    assert by["static safety factor"].limit == 3.0
    assert b.static_safety_limit("shock") == 2.0 and b.static_safety_limit("normal") == 1.5
    with pytest.raises(ValueError, match="precise"):
        b.static_safety_limit("gentle")
    assert b.load_factor_range("normal") == (1.2, 1.5)


def test_average_loads_2_3_4():
    segments = [LoadSegment(30, 0.1, 1000, 0), LoadSegment(60, 0.24, 500, 100), LoadSegment(0, 3.0, 2000, 0)]
    frav, faav, nav = b.average_loads(segments)
    w = [3.0, 14.4]
    assert frav == pytest.approx(((w[0] * 1000 ** (10 / 3) + w[1] * 500 ** (10 / 3)) / sum(w)) ** 0.3)
    assert faav == pytest.approx((w[1] * 100 ** (10 / 3) / sum(w)) ** 0.3)
    assert nav == pytest.approx(17.4 / 3.34)
    # the standstill load does not count for life; a constant load averages to itself
    assert b.average_load_n([700, 700], [10, 50], [1, 2]) == pytest.approx(700)
    with pytest.raises(ValueError, match="no motion"):
        b.average_load_n([700], [0], [1])


def test_sway_life_and_fretting():
    pc = 4000.0
    # n1 in oscillations per minute: the sway life equals the rotating life at the same average
    # speed (an oscillation of ±θ covers 4θ/360 rev)
    nav, theta = 10.0, 30.0
    n1 = nav * 360 / (4 * theta)
    assert b.sway_life_h(n1, theta, 18000, 1.5, pc) == pytest.approx(b.life_h(nav, 18000, 1.5, pc))
    loads = BearingLoads(max_radial_load_n=1000, sway_angle_deg=4.0, required_life_h=20_000)
    r = b.check_bearing(FHA25, loads, average_speed_rpm=1.0, oscillations_per_min=10)
    by = {c.name: c for c in r.checks}
    assert not by["sway angle (fretting)"].ok and "fretting" in by["sway angle (fretting)"].note
    assert by["bearing sway life"].value == pytest.approx(r.sway_life_h)
    assert "oscillations per minute" in by["bearing sway life"].note


def test_bearing_in_the_whole_duty():
    ratings = ActuatorRatings("FHA-25C-50-US250", 150.0, 90.0, 10.6, 0.81, 35.0, 70.0, 2.4, FHA25)
    loads = BearingLoads(
        max_radial_load_n=1000,
        max_axial_load_n=2000,
        radial_offset_m=0.05,
        axial_offset_m=0.03,
        required_life_h=30_000,
    )
    r = evaluate(ratings, DutyCycle(1.5, 60, 120, 3.4, bearing_loads=loads))
    assert r.bearing.life_h == pytest.approx(
        b.life_h(r.average_speed_rpm, 18000, 1.5, r.bearing.dynamic_load_n)
    )
    life = next(c for c in r.checks if c.name == "bearing life L10")
    assert life.ok and life.section == "2-3 (7)"
    assert r.as_dict()["bearing"]["x"] == 1.0
    assert math.isfinite(r.as_dict()["bearing"]["life_h"])


def test_bad_loads_are_rejected():
    with pytest.raises(ValueError, match="max_radial_load_n"):
        BearingLoads(max_radial_load_n=-1)
    with pytest.raises(ValueError, match="load_factor_fw"):
        BearingLoads(load_factor_fw=0.5)
