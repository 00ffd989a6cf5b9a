"""The DGR checks of a move from CN2: the encoder outputs against the command, which way the
command turned the axis, IN-POS after the move, ALARM through it, each naming its source."""

from __future__ import annotations

import numpy as np

from fha_studio.logic.bench.checks import bench_checks

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
    assert "parameter 8 = 0 says a FWD command turns the output CW" in direction.detail
    assert "do not show CW or CCW" in direction.detail and direction.values["counted"] == "FWD"
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
