"""The simulated drive's CN2 command-pulse lines carry what the controller sends, nothing else.

A real HA-655's CMD inputs (CN2) are driven by the controller: when an alarm switches the servo
off and the axis coasts, the drive's error counter follows the encoder, but the controller sends
no pulses; clearing the error counter (ACL, CLEAR) moves the drive's command, not the controller's
pulse count. The encoder outputs follow the axis all the while.
"""

from __future__ import annotations

import numpy as np
import pytest

from fha_studio.hardware.sim.cn2 import VirtualBenchInstrument
from fha_studio.hardware.sim.drive import SimDrive

RATE_HZ = 250e3


def _edges(instrument: VirtualBenchInstrument, since_sample: int) -> int:
    block = instrument.capture()
    edges = 0
    for line in ("CMD_A", "CMD_B"):
        levels = block.bit(line)[since_sample:]
        edges += int(np.count_nonzero(np.diff(levels.astype(np.int8))))
    return edges


@pytest.mark.parametrize("pulse_form", [0, 1, 2])  # two-pulse, pulse + sign, two-phase (parameter 1)
def test_no_command_pulses_while_the_axis_coasts_after_an_alarm_or_when_the_counter_clears(
    tmp_path, pulse_form
):
    drive = SimDrive("FHA-25C-50-US250", profile="documented", stepped=True, eeprom=str(tmp_path / "e.json"),
                     preset=(("system", 1, pulse_form),))
    try:
        instrument = VirtualBenchInstrument.on_drive(drive, RATE_HZ)
        drive.set_servo(True)
        instrument.record(0.01)
        drive.controller_command(1.0)  # the controller's pulse train: 1 deg FWD
        instrument.record(0.08)  # mid-move: the axis is turning
        assert abs(drive.output_speed_rpm) > 0.5
        sent = instrument.truth.arrays()["command_pulses"][-1]
        at_alarm = instrument.capture().samples
        encoder_at_alarm = instrument.truth.arrays()["encoder_counts"][-1]
        drive.raise_alarm(60)  # servo off: the axis coasts, the drive's command follows it
        instrument.record(0.1)
        truth = instrument.truth.arrays()
        assert truth["encoder_counts"][-1] != encoder_at_alarm  # the encoder outputs follow the coasting axis
        assert set(truth["command_pulses"][at_alarm:]) == {sent}
        assert _edges(instrument, at_alarm) == 0
        # ACL clears alarm 60 and the error counter (the drive's command jumps to the encoder)
        drive.clear_alarm()
        drive.set_servo(True)
        instrument.record(0.02)
        assert set(instrument.truth.arrays()["command_pulses"][at_alarm:]) == {sent}
        assert _edges(instrument, at_alarm) == 0
        # the controller's next command: exactly its pulses on the lines, from where they were
        before = instrument.capture().samples
        drive.controller_command(-0.5)
        instrument.record(0.15)
        pulses = instrument.truth.arrays()["command_pulses"]
        moved = int(pulses[-1] - sent)
        assert abs(moved - -0.5 / 360 * drive.output_ppr) <= 1  # an angle: the nearest whole pulse
        # two-pulse and pulse + sign: a pulse is two edges (pulse + sign: the sign line turns to REV
        # once); two-phase at x4 (parameter 2): an edge a pulse
        edges = {0: 2 * abs(moved), 1: 2 * abs(moved) + 1, 2: abs(moved)}[pulse_form]
        assert _edges(instrument, before) == edges
    finally:
        drive.close()
