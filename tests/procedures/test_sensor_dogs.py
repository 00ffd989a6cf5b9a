"""The sensor-dog wizard: edges found, moves past the movable range refused, the test run judged."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fha_studio.logic.procedures.sensor_dogs import MoveRefused, SensorDogWizard

OFF = {"limit_switch_1": False, "limit_switch_2": False, "origin_sensor": False}


def test_edges_are_recorded_where_a_sensor_switches_on(context):
    wizard = SensorDogWizard.for_context(context)
    assert wizard.observe(0.0, OFF) == []
    assert wizard.observe(10.0, {**OFF, "origin_sensor": True}) == ["origin_sensor"]
    wizard.observe(11.0, OFF)
    wizard.observe(140.0, {**OFF, "limit_switch_2": True})
    assert wizard.found("origin_sensor") == 10.0 and wizard.found("limit_switch_2") == 140.0
    assert wizard.edge_direction["limit_switch_2"] == 1
    assert wizard.edge_intervals_deg["limit_switch_2"] == (11.0, 140.0)
    assert wizard.found("limit_switch_1") is None


def test_moves_past_the_movable_range_are_refused(context):
    wizard = SensorDogWizard.for_context(context)
    with pytest.raises(MoveRefused, match="not known yet"):
        wizard.check_jog(+1)
    wizard.check_move(174.0)
    with pytest.raises(MoveRefused, match="movable range"):
        wizard.check_move(176.0)
    with pytest.raises(MoveRefused, match="movable range"):
        wizard.check_move(-180.0)
    wizard.observe(174.5, OFF)
    with pytest.raises(MoveRefused, match="CW jog"):
        wizard.check_jog(+1)
    wizard.check_jog(-1)


@settings(max_examples=50, deadline=None)
@given(st.floats(-1000, 1000, allow_nan=False))
def test_a_clamped_target_is_always_allowed(target):
    wizard = SensorDogWizard(ccw_limit_deg=-175.0, cw_limit_deg=175.0)
    wizard.check_move(wizard.clamp_target(target))


def test_test_run_is_judged_against_the_recorded_angles(context):
    wizard = SensorDogWizard.for_context(context)
    recorded = {"limit_switch_1": -140.0, "limit_switch_2": 140.0, "origin_sensor": 0.0}
    assert wizard.test_run_plan(recorded) == [142.0, -142.0]
    ok, detail = wizard.test_run_result(
        recorded, {"limit_switch_1": [-139.5], "limit_switch_2": [140.4], "origin_sensor": [0.3, -0.6]}
    )
    assert ok and "limit switch 1 (CCW end) at -139.50°" in detail
    ok, detail = wizard.test_run_result(recorded, {"limit_switch_1": [-130.0], "limit_switch_2": [140.0]})
    assert not ok and "never switched on" in detail and "more than 2° apart" in detail
    # polled slowly: the switch happened between two samples 5° apart, and that interval holds it
    ok, _ = wizard.test_run_result(
        recorded,
        {"limit_switch_1": [(-144.0, -139.0)], "limit_switch_2": [(137.0, 142.0)], "origin_sensor": [0.0]},
    )
    assert ok
    with pytest.raises(MoveRefused, match="no test run before"):
        wizard.test_run_plan({"limit_switch_1": -140.0})
