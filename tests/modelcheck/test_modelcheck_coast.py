"""Friction from the coast after an alarm, in a bench capture without current (coast.py).

The captures are made as a technician makes them on a real HA-655 (bench_capture_gen.py): the
controller's moves, then a move at speed, an alarm on the drive and the de-energised axis coasting,
with the ALARM line recorded beside the encoder, the command pulses and IN-POS. Asserted against
the friction hidden in the simulated drive: viscous friction (which the servo-on part cannot tell
from the loop's speed lag) named from the coast within 35 %, with Coulomb friction and beside a
gravity load; a frictionless coast, one too short and one a brake stops name nothing from it and
say why; the servo-on part's findings are those of the same recording cut before the alarm.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from bench_capture_gen import BenchCase, checked_captures
from test_modelcheck_bench_captures import MEDIUM_17C, MEDIUM_40C

from fha_studio.logic.modelcheck import ModelCheckError, run_modelcheck
from fha_studio.logic.modelcheck.candidates import CANDIDATES
from fha_studio.main import main as cli_main
from fha_studio.physics import AxisModel, catalogue_effects
from fha_studio.recording import Recording

TOL = 0.35
ON_THE_COAST = "from the coast after the alarm at"

VISCOUS_17C = BenchCase(MEDIUM_17C, {"viscous_friction": {"coefficient_nm_s_per_rad": 1.95}},
                        coast_s=1.0, coast_rpm=15.0)
BOTH_40C = BenchCase(
    MEDIUM_40C,
    {"viscous_friction": {"coefficient_nm_s_per_rad": 25.0}, "coulomb_friction": {"torque_nm": 25.0}},
    coast_s=1.0,
    coast_rpm=15.0,
)
#: a pendulum: the coast is mostly the gravity the servo-on part names, the drag beside it
GRAVITY_17C = BenchCase(
    MEDIUM_17C,
    {
        "gravity_load": {"amplitude_nm": 7.8, "phase_deg": 30.0},
        "viscous_friction": {"coefficient_nm_s_per_rad": 1.95},
    },
    coast_s=1.0,
    coast_rpm=15.0,
)
CATALOGUE_17C = BenchCase(MEDIUM_17C, catalogue_friction=True, coast_s=0.8, coast_rpm=15.0)
CATALOGUE_40C = BenchCase(MEDIUM_40C, catalogue_friction=True, coast_s=1.3, coast_rpm=15.0)
#: coasts both ways (the alarm cleared and the servo on again between them) with a load pulling one way
BOTH_WAYS_17C = BenchCase(MEDIUM_17C, {"load_torque_offset": {"torque_nm": 1.0}}, coast_s=0.6, coast_rpm=15.0,
                          catalogue_friction=True, both_ways=True)
FRICTIONLESS_17C = BenchCase(MEDIUM_17C, coast_s=0.5, coast_rpm=15.0)
TOO_SHORT_17C = BenchCase(MEDIUM_17C, catalogue_friction=True, coast_s=0.02, coast_rpm=15.0)
BRAKED_17C = BenchCase(MEDIUM_17C, catalogue_friction=True, coast_s=0.3, coast_rpm=15.0, brake=True)


@pytest.fixture(scope="module")
def checked(tmp_path_factory):
    """Each case captured and checked once per module."""
    return checked_captures(tmp_path_factory.mktemp("coast-captures"))


def _truth(case: BenchCase) -> dict[str, float]:
    if case.catalogue_friction:
        model = AxisModel.from_code(case.axis.code, load_inertia_kgm2=case.axis.load_kgm2)
        hidden = catalogue_effects(model).to_dict()
    else:
        hidden = case.effects
    return {k: v for effect in hidden.values() for k, v in effect.items()}


@pytest.mark.parametrize("case", [VISCOUS_17C, BOTH_40C, GRAVITY_17C, CATALOGUE_17C, CATALOGUE_40C],
                         ids=lambda c: c.name)
def test_the_coast_after_an_alarm_names_viscous_friction(case, checked):
    _, result = checked(case)
    text = "\n".join(result.summary_lines())
    truth = _truth(case)
    effects = {e.id: e for e in result.effects}
    viscous = effects["viscous_friction"]
    assert viscous.params["coefficient_nm_s_per_rad"] == pytest.approx(
        truth["coefficient_nm_s_per_rad"], rel=TOL), text
    assert ON_THE_COAST in viscous.basis and "rests on the declared inertia" in viscous.basis
    assert "Viscous friction missing: " in text and ON_THE_COAST in text
    if "torque_nm" in truth:  # Coulomb friction: from the servo-on part, checked against the coast
        coulomb = effects["coulomb_friction"].params["torque_nm"]
        assert coulomb == pytest.approx(truth["torque_nm"], rel=TOL), text
        # what to do next adds the value named (the weighted mean), not the servo-on part's
        assert effects["coulomb_friction"].advice == CANDIDATES["coulomb_friction"].advice(
            effects["coulomb_friction"].params)
        assert "Coulomb friction: the servo-on moves give" in text, text
    else:
        assert "coulomb_friction" not in effects, text
    # the gap on the coast: its speed from the start, the nominal model (no friction) far off,
    # the updated one close
    (coast,) = result.coasts
    assert coast.rms_after_rpm < 0.2 * coast.rms_before_rpm, text
    assert "Coast after the alarm at " in text
    assert " r/min rms (nominal model, no friction -> updated model" in text
    # the updated model carries it (the model file a later check or the simulated drive loads)
    assert result.updated_model.effects.viscous_friction is not None
    # the servo-on part says what the coast showed, not that nothing could
    assert any("with the servo on: the coast after the alarm shows it" in line for line in result.not_seen)


def test_the_servo_on_part_is_read_as_if_the_recording_ended_at_the_alarm(checked):
    capture, result = checked(VISCOUS_17C)
    rec = capture.recording
    onset = int(np.flatnonzero(rec.channels["alarm"] > 0.5)[0])
    cut = rec.slice(0, onset)
    cut = Recording(cut.metadata, {k: v for k, v in cut.channels.items() if k != "alarm"}, cut.source)
    before = run_modelcheck(cut)
    assert result.loop.position_gain_per_s == before.loop.position_gain_per_s
    assert result.loop.torque_per_speed_error_nm_s_per_rad == before.loop.torque_per_speed_error_nm_s_per_rad
    servo_on = [e for e in result.effects if not e.basis]
    assert [(e.id, e.params) for e in servo_on] == [(e.id, e.params) for e in before.effects]
    assert before.coasts == [] and "viscous_friction" not in {e.id for e in before.effects}
    # without a coast the report says which recording would show viscous friction
    why = next(line for line in before.not_seen if line.startswith("Without a torque measurement"))
    assert "a coast from speed after an alarm, with the ALARM line recorded, shows it" in why


@pytest.mark.parametrize(
    ("case", "said"),
    [
        (FRICTIONLESS_17C, "Viscous friction from the coast after the alarm at"),
        (TOO_SHORT_17C, "too short or too slow for a friction at the detection floor to show"),
        (BRAKED_17C, "more than friction of this actuator could"),
    ],
    ids=lambda c: c.name if isinstance(c, BenchCase) else "",
)
def test_a_coast_that_cannot_tell_friction_names_nothing(case, said, checked):
    _, result = checked(case)
    text = "\n".join(result.summary_lines())
    assert not any(e.basis for e in result.effects), text
    assert "viscous_friction" not in {e.id for e in result.effects}, text
    assert said in text, text
    assert result.loop is not None and result.loop.plausible, text


def test_the_command_line_shows_the_coast(checked, tmp_path, capsys):
    """``fha-studio discrepancy`` on the imported capture: the viscous friction the coast shows, where it
    was read, and the coast's gap, in the report and in the JSON."""
    capture, _ = checked(VISCOUS_17C)
    recording = tmp_path / "coast.csv"
    recording.write_text(capture.capture.with_suffix(".csv").read_text())
    report = tmp_path / "report.json"
    code = cli_main(["discrepancy", str(recording), "--json", str(report),
                     "--load-inertia", str(VISCOUS_17C.axis.load_kgm2)])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "Viscous friction missing: " in out and ON_THE_COAST in out
    assert "Coast after the alarm at " in out and "r/min rms" in out
    data = json.loads(report.read_text())
    (viscous,) = [e for e in data["effects"] if e["id"] == "viscous_friction"]
    assert ON_THE_COAST in viscous["read_from"]
    assert data["coasts"][0]["speed_rms_updated_rpm"] < data["coasts"][0]["speed_rms_nominal_rpm"]


def test_the_command_during_the_alarm_and_too_little_before_it(checked):
    """The command is not compared with a coasting axis (a drive in alarm ignores the pulses a
    controller may still send), and a recording with too little before its alarm gets one line."""
    capture, result = checked(VISCOUS_17C)
    rec = capture.recording
    alarm = rec.channels["alarm"] > 0.5
    onset = int(np.flatnonzero(alarm)[0])
    channels = dict(rec.channels)
    channels["cmd_pos"] = np.where(alarm, rec.channels["cmd_pos"] + 3600.0, rec.channels["cmd_pos"])
    sent_on = run_modelcheck(Recording(rec.metadata, channels, rec.source))
    assert [(e.id, e.params) for e in sent_on.effects] == [(e.id, e.params) for e in result.effects]
    refused = r"the recording before the alarm at \d+\.\d\d s \(the servo on\) cannot be checked"
    for start, said in ((onset - 5, "5 samples"), (onset, "the ALARM line is on from the first sample")):
        with pytest.raises(ModelCheckError, match=refused) as err:
            run_modelcheck(rec.slice(start, len(rec)))
        assert said in str(err.value)


def test_coasts_both_ways_separate_coulomb_friction_from_a_constant_load_torque(checked):
    """Forward the coast's level is Coulomb friction plus the load torque, in reverse minus it: the
    mean is named Coulomb friction, half the difference a load torque offset (or friction that
    differs by direction, which no coast tells from it: said)."""
    _, result = checked(BOTH_WAYS_17C)
    text = "\n".join(result.summary_lines())
    truth = _truth(BOTH_WAYS_17C)
    effects = {e.id: e for e in result.effects}
    assert effects["coulomb_friction"].params["torque_nm"] == pytest.approx(truth["torque_nm"], rel=TOL), text
    viscous = effects["viscous_friction"].params["coefficient_nm_s_per_rad"]
    assert viscous == pytest.approx(truth["coefficient_nm_s_per_rad"], rel=TOL), text
    offset = effects["load_torque_offset"]
    assert offset.params["torque_nm"] == pytest.approx(1.0, rel=TOL), text
    assert offset.alternatives == ["asymmetric_friction"]
    assert "from the coasts after the alarm at" in offset.basis
    assert "The coasts' friction differs by direction" in text
    assert len(result.coasts) == 2
    assert all(c.rms_after_rpm < 0.2 * c.rms_before_rpm for c in result.coasts), text
