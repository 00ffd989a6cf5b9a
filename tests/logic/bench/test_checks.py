"""The DGR checks of a move from CN2: the encoder outputs against the command, which way the
command turned the axis, IN-POS after the move, ALARM through it, each naming its source."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from fha_studio.hardware.parameters import load_cn2
from fha_studio.logic.bench.checks import bench_checks, flange_direction, source_words

T = np.arange(0, 1.0, 1e-3)
CMD = np.clip((T - 0.1) / 0.3, 0, 1) * 5000.0
ENC = np.clip((T - 0.12) / 0.3, 0, 1) * 5000.0
IN_POS = (np.abs(CMD - ENC) <= 10).astype(float)


def _by(checks):
    return {c.check: c for c in checks}


def test_a_move_that_follows_its_command_passes_every_check_and_names_its_source():
    checks = _by(bench_checks(T, CMD, ENC, in_position=IN_POS, alarm=np.zeros(T.size),
                              in_position_time_s=0.02, parameter_8=0, source="the bench instrument demo"))
    assert [c.passed for c in checks.values()] == [True, True, True, True]
    assert checks["bench_encoder"].detail.startswith("the encoder outputs counted +5000 for +5000")
    assert "from the bench instrument demo" in checks["bench_encoder"].detail
    direction = checks["bench_direction"]
    assert "a FWD command (+5000 counts) turned the axis FWD" in direction.detail
    assert "with parameter 8 = 0 that is FWD rotation, CW viewing the output flange (1-10)" \
        in direction.detail
    assert "taking the encoder outputs to count up on a FWD command" in direction.detail
    assert (direction.values["counted"], direction.values["flange"]) == ("FWD", "CW")
    assert checks["bench_in_position"].detail.startswith("IN-POS (CN2-33) came on 20.0 ms after")


def test_swapped_phases_a_wrong_gear_no_command_in_pos_and_alarm_fail_saying_why():
    swapped = _by(bench_checks(T, CMD, -ENC))
    assert not swapped["bench_encoder"].passed and "A and B swapped" in swapped["bench_encoder"].detail
    assert not swapped["bench_direction"].passed
    halved = _by(bench_checks(T, CMD, ENC / 2))["bench_encoder"]
    assert not halved.passed and "electronic gear (parameters 3/4)" in halved.detail
    nothing = bench_checks(T, np.zeros(T.size), ENC)
    assert len(nothing) == 1 and not nothing[0].passed and "no command pulses came" in nothing[0].detail
    alarm = np.where(T > 0.5, 1.0, 0.0)
    late = _by(bench_checks(T, CMD, ENC, in_position=np.ones(T.size), alarm=alarm, in_position_time_s=None))
    assert not late["bench_in_position"].passed and not late["bench_alarm"].passed
    assert late["bench_alarm"].detail.startswith("ALARM came on at 0.501 s")


@pytest.mark.parametrize(("sign", "parameter_8", "words"), [
    (+1, 0, "a FWD command (+5000 counts) turned the axis FWD as the encoder outputs count it from the "
            "bench: with parameter 8 = 0 that is FWD rotation, CW viewing the output flange"),
    (+1, 1, "a FWD command (+5000 counts) turned the axis FWD as the encoder outputs count it from the "
            "bench: with parameter 8 = 1 that is REV rotation, CCW viewing the output flange"),
    (-1, 0, "a REV command (-5000 counts) turned the axis REV as the encoder outputs count it from the "
            "bench: with parameter 8 = 0 that is REV rotation, CCW viewing the output flange"),
    (-1, 1, "a REV command (-5000 counts) turned the axis REV as the encoder outputs count it from the "
            "bench: with parameter 8 = 1 that is FWD rotation, CW viewing the output flange"),
])
def test_the_flange_turns_as_the_encoder_outputs_and_parameter_8_say(sign, parameter_8, words):
    direction = _by(bench_checks(T, sign * CMD, sign * ENC, parameter_8=parameter_8))["bench_direction"]
    assert direction.passed and direction.detail.startswith(words)


def test_without_parameter_8_the_flange_is_not_guessed():
    direction = _by(bench_checks(T, CMD, ENC))["bench_direction"]
    assert direction.passed and direction.values["flange"] is None
    assert "which way that is at the output flange (CW or CCW) follows from parameter 8" in direction.detail
    assert flange_direction(0, 0) is None and flange_direction(5, None) is None


def test_encoder_outputs_that_counted_the_flanges_cw_are_turned_into_the_commands_sense():
    # a drive whose encoder outputs count up on CW whatever parameter 8 says: with 1 a FWD command
    # turns the flange CCW and the outputs count down, which is no wiring fault
    cw = dataclasses.replace(load_cn2(), encoder_counts_up_on="CW")
    checks = _by(bench_checks(T, CMD, -ENC, parameter_8=1, cn2=cw))
    assert checks["bench_encoder"].passed and checks["bench_direction"].values["flange"] == "CCW"
    unknown = _by(bench_checks(T, CMD, -ENC, alarm=np.zeros(T.size), cn2=cw))
    assert unknown["bench_encoder"].passed is None and "needs parameter 8" in unknown["bench_encoder"].detail
    assert "bench_direction" not in unknown and unknown["bench_alarm"].passed


def test_an_alarm_on_the_code_lines_is_named_in_the_manuals_words():
    code = np.where(T > 0.5, 0b0010, 0)
    alarm = _by(bench_checks(T, CMD, ENC, alarm=(code != 0).astype(float), alarm_code=code))["bench_alarm"]
    assert not alarm.passed and alarm.values["alm_code"] == "0010"
    assert alarm.detail.startswith("ALARM came on at 0.501 s from the bench: ALM-D C B A 0010: "
                                   "60 Error counter overflow")
    # ALM-C not read: 1101 shows as 1001, which is over current or any encoder alarm
    encoder = _by(bench_checks(T, CMD, ENC, alarm_code=np.where(T > 0.5, 0b1001, 0),
                               alarm_lines_unmapped=("ALM-C",)))["bench_alarm"]
    assert "an alarm code came on at 0.501 s from the bench: ALM-D C B A 1?01: 30 Over current, 50 Encoder " \
        "failure, 51 " in encoder.detail
    assert "(ALM-C not mapped)" in encoder.detail
    quiet = _by(bench_checks(T, CMD, ENC, alarm=np.zeros(T.size), alarm_code=np.zeros(T.size)))["bench_alarm"]
    assert quiet.passed and quiet.detail.startswith("ALARM and ALM-A ... D stayed off")


@pytest.mark.parametrize("counts_cw", [False, True])
def test_the_simulated_drives_encoder_outputs_and_parameter_8_give_the_flanges_direction(counts_cw):
    """Parameter 8 = 1 on the simulated drive: a FWD command turns the flange CCW; its CN2 encoder
    outputs count in the command's sense (the data's assumption) or the flange's CW one, and the
    check, told which, says CCW either way."""
    from fha_studio.catalog import get_actuator
    from fha_studio.hardware.sim.cn2 import Cn2Settings, Cn2Signals, VirtualBenchInstrument
    from fha_studio.logic.bench.decode import command_pulses, quadrature
    from fha_studio.physics import AxisModel, ServoAxis

    axis = ServoAxis(AxisModel.from_actuator(get_actuator("FHA-25C-50-US250")))
    axis.set_settings(axis.settings.replace(rotary_direction=1))
    axis.servo_on()
    instrument = VirtualBenchInstrument(axis, 100e3, Cn2Settings(pulse_form=0))
    if counts_cw:
        s = instrument.signals
        instrument.signals = Cn2Signals(s.rate, s.s, output_pulse_rad=s.pulse_rad, ratio=s.ratio,
                                        in_position_range_counts=s.in_position_range, direction=s.direction,
                                        encoder_counts_cw=True)
    instrument.record(0.02)
    axis.move_by_pulses(2000, speed_rad_s=0.5)
    block = instrument.record(0.3)
    encoder = quadrature(block.bit("ENC_A"), block.bit("ENC_B")).counts
    command = command_pulses(block.bit("CMD_A"), block.bit("CMD_B"), 0, 4, 1, 1).counts
    assert command[-1] == 2000 and abs(encoder[-1] - (-2000 if counts_cw else 2000)) <= 10  # still settling
    cn2 = dataclasses.replace(load_cn2(), encoder_counts_up_on="CW" if counts_cw else "FWD command")
    t = np.arange(block.samples) / block.sample_rate_hz
    checks = _by(bench_checks(t, command, encoder, parameter_8=1, cn2=cn2))
    assert checks["bench_encoder"].passed and checks["bench_direction"].passed
    assert (checks["bench_direction"].values["rotation"], checks["bench_direction"].values["flange"]) == (
        "REV rotation", "CCW")


def test_the_source_names_each_cn2_signal_once_with_its_instrument_channel_only_where_it_differs():
    # a capture whose channels are named after the signals (the simulated CN2's ALARM, ALM_A):
    # the signal's name alone, never "ALARM ALARM, ALM-A ALM_A"
    words = source_words("sim-cn2", [("encoder A, B", ("ENC_A", "ENC_B")),
                                     ("command pulses", ("CMD_A", "CMD_B")), ("IN-POS", ("IN_POS",)),
                                     ("ALARM", ("ALARM",)), ("ALM-A", ("ALM_A",)), ("ALM-B", ("",))])
    assert words == ("the bench instrument sim-cn2 (encoder A, B on ENC_A, ENC_B; command pulses on CMD_A, "
                     "CMD_B; IN-POS; ALARM; ALM-A)")
    # a logic analyzer's D0 ... D7: the channel once, after the signal it carries
    words = source_words("demo", [("encoder A, B", ("D0", " D1")), ("IN-POS", ("D4",)), ("ALARM", ("",))])
    assert words == "the bench instrument demo (encoder A, B on D0, D1; IN-POS on D4)"
