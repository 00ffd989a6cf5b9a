"""The alarm code lines ALM-A ... ALM-D as roles: the 4-bit code (D C B A, ON = 1) in the
recording's alm_code column, and each code that came named with the HA-655's alarms it can be."""

from __future__ import annotations

import numpy as np
import pytest

from fha_studio.hardware.bench.capture import Capture, SampleBlock, pack_logic
from fha_studio.logic.bench.importer import (
    AxisFacts,
    BenchImportError,
    DriveSettings,
    SignalSpec,
    import_bench,
)
from fha_studio.logic.bench.live import parse_live_signal

RATE = 100e3


def _capture() -> Capture:
    n = int(RATE)  # 1 s: the encoder stands, an encoder alarm (1101) from 0.5 s, overload (0001) at 0.8 s
    t = np.arange(n) / RATE
    code = np.where(t >= 0.8, 0b0001, np.where(t >= 0.5, 0b1101, 0))
    bits = [(code >> bit) & 1 == 1 for bit in range(4)]
    alarm = code != 0
    zeros = np.zeros(n, bool)
    logic = pack_logic([zeros, zeros, alarm, *bits])
    names = ("ENC_A", "ENC_B", "ALARM", "ALM_A", "ALM_B", "ALM_C", "ALM_D")
    return Capture("alarm.sr", SampleBlock(RATE, names, logic), {}, 0.0, "sigrok session")


def _import(roles: dict[str, str]):
    capture = _capture()
    signals = [SignalSpec(role, "alarm.sr", channel) for role, channel in roles.items()]
    axis = AxisFacts.for_actuator("FHA-25C-50-US250")
    return import_bench(signals, axis, DriveSettings(0, 4, 1, 1, 3000.0), loader=lambda path: capture)


def test_the_alarm_code_lines_give_the_4_bit_code_and_the_alarms_it_can_be():
    result = _import({"encoder_a": "ENC_A", "encoder_b": "ENC_B", "alarm": "ALARM", "alm_a": "ALM_A",
                      "alm_b": "ALM_B", "alm_c": "ALM_C", "alm_d": "ALM_D"})
    rec = result.recording
    t, code = rec.channels["t"], rec.channels["alm_code"]
    assert set(code[t < 0.5]) == {0.0} and set(code[(t >= 0.5) & (t < 0.8)]) == {13.0}
    assert set(code[t >= 0.8]) == {1.0} and set(rec.channels["alarm"][t >= 0.5]) == {1.0}
    seen = result.summary["alarm_codes"]
    assert [s["alm_code"] for s in seen] == ["1101", "0001"]
    assert seen[0]["first_s"] == pytest.approx(0.5) and seen[1]["first_s"] == pytest.approx(0.8)
    assert "50 Encoder failure" in seen[0]["alarms"] and "52 UVW failure" in seen[0]["alarms"]
    assert seen[1]["alarms"] == ["20 Overload"]
    assert rec.metadata.extra["source_alm_code"].startswith("D C B A, ON = 1: ALM-A alarm.sr#ALM_A")
    assert result.summary["roles"]["alm_d"]["scale_unit"] == "logic, high = on"


def test_lines_not_mapped_count_zero_and_are_named():
    result = _import({"encoder_a": "ENC_A", "encoder_b": "ENC_B", "alm_a": "ALM_A"})
    assert set(result.recording.channels["alm_code"]) == {0.0, 1.0}
    assert result.recording.metadata.extra["source_alm_code"].endswith("(ALM-B, ALM-C, ALM-D not mapped: 0)")


def test_the_roles_are_the_commands_words():
    assert parse_live_signal("alm_c=D6").role == "alm_c"
    with pytest.raises(BenchImportError, match="unknown role 'alm_e'"):
        parse_live_signal("alm_e=D6")


def test_the_simulated_drives_cn2_gives_the_alarm_tables_code_on_alm_a_to_d(tmp_path):
    """A stepped simulated drive raises alarm 60 (error counter overflow) while its CN2 is recorded:
    ALARM comes on and ALM-D C B A show 0010, as the HA-655's table gives it, and the import names it."""
    from fha_studio.hardware.sim.cn2 import VirtualBenchInstrument
    from fha_studio.hardware.sim.drive import SimDrive

    drive = SimDrive("FHA-25C-50-US250", profile="documented", stepped=True, eeprom=str(tmp_path / "e.json"))
    try:
        instrument = VirtualBenchInstrument.on_drive(drive, 50e3)
        drive.set_servo(True)
        instrument.record(0.05)
        drive.raise_alarm(60)
        instrument.record(0.05)
        instrument.write(tmp_path / "cn2.sr", "sr")
    finally:
        drive.close()
    roles = {"encoder_a": "ENC_A", "encoder_b": "ENC_B", "alarm": "ALARM", "alm_a": "ALM_A", "alm_b": "ALM_B",
             "alm_c": "ALM_C", "alm_d": "ALM_D"}
    signals = [SignalSpec(role, str(tmp_path / "cn2.sr"), channel) for role, channel in roles.items()]
    axis = AxisFacts.for_actuator("FHA-25C-50-US250")
    result = import_bench(signals, axis, DriveSettings(0, 4, 1, 1, 3000.0))
    t, code = result.recording.channels["t"], result.recording.channels["alm_code"]
    came = result.summary["alarm_codes"]
    assert [(c["alm_code"], c["alarms"]) for c in came] == [("0010", ["60 Error counter overflow"])]
    assert came[0]["first_s"] == pytest.approx(0.05, abs=0.002)
    assert set(code[t < 0.045]) == {0.0} and set(code[t > 0.055]) == {2.0}
    assert set(result.recording.channels["alarm"][t > 0.055]) == {1.0}


def test_an_instrument_takes_the_lines_asked_for_in_their_order():
    """As sigrok-cli's -C: the alarm lines alone, in the order given, one byte a sample."""
    from fha_studio.catalog import get_actuator
    from fha_studio.hardware.sim.cn2 import Cn2Settings, signals_of_axis
    from fha_studio.physics import AxisModel, ServoAxis

    axis = ServoAxis(AxisModel.from_actuator(get_actuator("FHA-25C-50-US250")))
    signals = signals_of_axis(axis, 10e3, Cn2Settings(), logic_channels=("ALM_D", "ALM_C", "ALARM", "ALM_A"))
    axis.start_trace(1)
    axis.step(20)
    block, _ = signals.feed(axis.read_trace(clear=True), alarm=50)  # encoder failure: 1101
    assert block.logic_channels == ("ALM_D", "ALM_C", "ALARM", "ALM_A") and block.logic.dtype == np.uint8
    assert set(block.logic) == {0b1111}  # D, C, ALARM and A on (B is 0)
    axis.step(20)
    block, _ = signals.feed(axis.read_trace(clear=True), alarm=0)
    assert block.samples > 0 and set(block.logic) == {0}
    with pytest.raises(ValueError, match="no CN2 output ALM_E"):
        signals_of_axis(axis, 10e3, Cn2Settings(), logic_channels=("ALM_E",))
