"""The bias speed's direction (FWD, REV or in place) and the movable range: the plan states which
way and how far the axis turns, refuses in one line what does not fit the room to the limit, and
a REV jog measures as a FWD one does on the simulated drive with the catalogue's friction."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.tuning.excitation import BiasDirection, ExcitationPlan, plan_excitation
from fha_studio.logic.tuning.measure import measure
from fha_studio.logic.tuning.response import estimate_response
from fha_studio.logic.tuning.session import declared_model, tuner_for
from fha_studio.logic.tuning.travel import MovableRange, TravelRefused, check_travel, travel_deg
from fha_studio.physics import catalogue_effects

PARAMETERS = load_parameter_model("HA-655")
CODE = "FHA-25C-50-US250"

#: a plan as an FHA-25C-50 with 1 x has it, in round figures: 60 deg of jog, the drive's stop at 5 deg
PLAN = ExcitationPlan(amplitude_rpm=0.5, hold_periods=1, period_samples=4095, records=5,
                      travel_bound_deg=2.495, travel_limit_deg=5.0, peak_current_a=1.0, f_max_hz=2000.0,
                      settle_s=1.0, duration_s=5.0, bias_rpm=1.0, speed_bound_rpm=0.8)
# the limit switches as the procedures record them: limit switch 1 (CCW end) at -100 deg, 2 at +100
SWITCHES = {"limit_switch_1": -100.0, "limit_switch_2": 100.0}


def _rev(plan: ExcitationPlan) -> ExcitationPlan:
    from dataclasses import replace

    return replace(plan, bias_sign=-1)


def test_the_travel_each_way_is_the_jogs_angle_and_the_excitations_stop() -> None:
    along = PLAN.bias_travel_deg
    assert 30.0 < along < 90.0  # 1 r/min for the records, their settling and restarts
    assert travel_deg(PLAN, +1) == pytest.approx(along + 5.0)
    assert travel_deg(PLAN, -1) == pytest.approx(5.0)  # back along the path: the excitation's swing only
    assert travel_deg(_rev(PLAN), -1) == pytest.approx(along + 5.0)
    in_place = ExcitationPlan(**{**PLAN.__dict__, "bias_rpm": 0.0})
    assert in_place.bias_direction is BiasDirection.NONE
    assert travel_deg(in_place, +1) == travel_deg(in_place, -1) == pytest.approx(5.0)


@pytest.mark.parametrize("position_deg, fits_fwd, fits_rev", [
    (0.0, True, True),      # the middle: room both ways
    (60.0, False, True),    # 40 deg to the CW end: FWD does not fit
    (-60.0, True, False),   # 40 deg to the CCW end: REV does not fit
    (97.0, False, False),   # 3 deg from the end: not even in place
])
def test_the_plan_refuses_what_does_not_fit_the_movable_range(position_deg: float, fits_fwd: bool,
                                                              fits_rev: bool) -> None:
    movable = MovableRange.from_switch_angles(SWITCHES, position_deg)
    assert movable is not None
    ends = {"limit switch 2 (CW end)": 100.0, "limit switch 1 (CCW end)": -100.0}
    room_to = ends.__getitem__
    cw_end, ccw_end = "limit switch 2 (CW end)", "limit switch 1 (CCW end)"
    cases = ((PLAN, fits_fwd, cw_end, ccw_end), (_rev(PLAN), fits_rev, ccw_end, cw_end))
    for plan, fits, end, other_end in cases:
        if fits:
            line = check_travel(plan, movable, fwd_is_cw=True)
            assert line == (f"within the movable range: {abs(room_to(end) - position_deg):.3g}° to {end}, "
                            f"{abs(room_to(other_end) - position_deg):.3g}° to {other_end}")
            continue
        with pytest.raises(TravelRefused) as refused:
            check_travel(plan, movable, fwd_is_cw=True)
        line = str(refused.value)
        assert "\n" not in line
        way = "FWD (CW" if plan.bias_sign > 0 else "REV (CCW"
        room = abs(100.0 - abs(position_deg))
        if abs(position_deg) < 90:  # refused for the jog's own way: how far, and the room to that end
            assert line.startswith(f"on a {way} seen from the flange) jog the excitation would turn the axis "
                                   f"up to about {travel_deg(plan, plan.bias_sign):.3g}° that way")
            assert f"only {room:.3g}° to {end}" in line
        other = "REV (CCW" if plan.bias_sign > 0 else "FWD (CW"
        assert (f"choose {other}" in line) == (fits_fwd or fits_rev)
        assert ("measure in place" in line) == (abs(position_deg) < 90)
        if not (fits_fwd or fits_rev) and abs(position_deg) >= 90:
            assert line.endswith("move the axis towards the middle of its range first")


def test_the_rotary_direction_names_the_rotation_and_the_range_is_named_unknown() -> None:
    """Rotary direction 1 (1-10): a FWD command turns the output CCW; the angles are the feedback
    position's (command sense), so the FWD end is the larger angle, whichever switch it is."""
    movable = MovableRange.from_switch_angles({"limit_switch_1": 100.0, "limit_switch_2": -100.0}, 60.0)
    assert movable is not None
    with pytest.raises(TravelRefused, match=r"FWD \(CCW seen from the flange\).*only 40° to limit switch 1"):
        check_travel(PLAN, movable, fwd_is_cw=False)
    assert MovableRange.from_switch_angles({"limit_switch_1": -100.0}, 0.0) is None
    line = check_travel(_rev(PLAN), None, fwd_is_cw=True)
    assert line.startswith("the movable range is not known") and "confirm" in line
    said = _rev(PLAN).describe(manual_units=True, fwd_is_cw=True)
    turns = f"{PLAN.bias_travel_deg:.3g}° REV"
    assert f"r/min REV (CCW seen from the flange), which turns the axis up to about {turns}" in said
    assert "REV" in _rev(PLAN).describe() and "FWD" not in _rev(PLAN).describe()


def test_a_rev_jog_turns_the_axis_the_other_way_and_measures_as_fwd() -> None:
    """On the drive with the catalogue's friction, FWD and REV each: the jog turns the output its
    way, the excitation runs on it to the end (its travel limit about the jog's path both ways), the
    axis never reverses, and the plant is within test_tuning_cases.py's tolerances of the drive's
    linearisation (1 dB, 5 deg) both ways."""
    model = declared_model(CODE, 0.81)
    url = (f"sim://{CODE}?load_inertia=0.81&effects=torsional_compliance&stepped=1&paced=0&quantised=0"
           "&catalogue_friction=1")
    turned = {}
    for direction in (BiasDirection.FWD, BiasDirection.REV):
        with DriveClient.open(url) as client:
            drive = client.transaction.transport.inner.sim_drive
            client.servo(True)
            tuner = tuner_for(client, PARAMETERS, model, quantised_feedback=False)
            plan = plan_excitation(tuner.loop({}), bias=direction)
            assert plan.jog_speed_rpm == pytest.approx(direction.sign * plan.bias_rpm)
            start = drive.axis.output_pos_rad
            records = measure(client, plan, tuner.servo_rate_hz, drive.advance, lambda d=drive: d.clock_s,
                              output_ppr=model.output_resolution_ppr,
                              jog_accel_rpm_s=tuner.items["jog_acceleration"])
            turned[direction] = np.degrees(drive.axis.output_pos_rad - start)
            assert not drive.excitation.active  # ended, and the jog stopped (STP: it decelerates)
            drive.advance(0.5)
            assert not drive.moving
            actual = tuner_for(client, PARAMETERS, model.replace(effects=catalogue_effects(model)),
                               quantised_feedback=False).loop({})
        assert records.reversal_share() == 0.0
        assert records.travel_deg() <= plan.travel_bound_deg
        plant = estimate_response(records.plant(), records.sample_rate_hz, f_max_hz=plan.f_max_hz)
        trusted = plant.trusted()
        assert trusted.sum() > 0.8 * len(trusted)
        mag, phase = actual.response("plant", plant.freq_hz)
        assert np.max(np.abs(plant.magnitude_db - mag)[trusted]) <= 1.0
        assert np.max(np.abs((plant.phase_deg - phase + 180.0) % 360.0 - 180.0)[trusted]) <= 5.0
    # rotary direction 0 (the default): FWD turns the output CW (+), REV CCW (-), each within the
    # stated bound, and a good part of it (the jog ran throughout)
    bound = plan.bias_travel_deg + plan.travel_limit_deg
    assert 0.3 * plan.bias_travel_deg < turned[BiasDirection.FWD] <= bound
    assert -bound <= turned[BiasDirection.REV] < -0.3 * plan.bias_travel_deg


def test_cli_bias_rev_states_the_direction_and_turns_the_axis_rev(drives, tmp_path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    """``tune measure --bias rev``: the plan on stderr says REV (CCW with rotary direction 0) and how
    far, the range not known; the axis turns REV; the JSON says the direction."""
    from fha_studio.cli import main as cli_main

    out = tmp_path / "measure.json"
    url = f"sim://{CODE}?load_inertia=0.81&effects=torsional_compliance&stepped=1&paced=0&quantised=0"
    code = cli_main(["tune", "measure", "--url", url, "--actuator", CODE, "--load-inertia", "0.81",
                     "--amplitude-rpm", "0.3", "--bias", "rev", "--json", str(out)])
    _said, err = capsys.readouterr()
    assert code == 0, err
    plan_line = err.splitlines()[0]
    assert "r/min REV (CCW seen from the flange)" in plan_line and "deg REV" in plan_line
    assert "the movable range is not known" in plan_line and "FWD" not in plan_line
    result = json.loads(out.read_text())
    assert result["excitation"]["bias_direction"] == "rev" and result["excitation"]["bias_rpm"] > 0
    (drive,) = drives
    assert drive.axis.output_pos_rad < 0  # from 0 at power-on: REV is CCW with rotary direction 0


def test_cli_refuses_a_bias_the_limit_switches_leave_no_room_for(drives,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """Limit switch 1 (CCW end) 20 deg from the axis: REV is refused in one line (exit 4) that says
    how far and how much room, and suggests FWD or in place; nothing moved. --in-place with a
    different --bias is a usage error."""
    from fha_studio.cli import main as cli_main

    url = f"sim://{CODE}?load_inertia=0.81&effects=torsional_compliance&stepped=1&paced=0&quantised=0"
    base = ["tune", "measure", "--url", url, "--actuator", CODE, "--load-inertia", "0.81"]
    code = cli_main([*base, "--bias", "rev", "--limit-switches=-20,200"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 4 and len(err) == 1, err
    assert "on a REV (CCW seen from the flange) jog the excitation would turn the axis up to about" in err[0]
    assert "only 20 deg to limit switch 1 (CCW end)" in err[0]
    assert "choose FWD (CW seen from the flange)" in err[0] and "measure in place" in err[0]
    (drive,) = drives
    assert drive.axis.output_pos_rad == 0.0 and not drive.excitation.active and not drive.moving
    assert cli_main([*base, "--in-place", "--bias", "fwd"]) == 2
    assert "--in-place is --bias none" in capsys.readouterr().err
