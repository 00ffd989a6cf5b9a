"""The simulated drive's state machine, in stepped mode (no threads, no sleeps)."""

from __future__ import annotations

import math

import pytest

from fha_studio.hardware.parameters import Mode
from fha_studio.hardware.sim.io import (
    BIT_ALARM,
    BIT_BRAKE_RELEASED,
    BIT_FWD_INHIBIT,
    BIT_IN_POSITION,
    BIT_LIMIT_1,
    BIT_LIMIT_2,
    BIT_ORIGIN,
    BIT_READY,
    BIT_SERVO_ON,
)
from tests.sim.conftest import ask, jog_for, responder

RPM = 2 * math.pi / 60


def speed_rpm(drive) -> float:
    return drive.monitor(103) / 100.0


def bit(drive, n: int) -> int:
    return drive.io_bits() >> n & 1


def test_nothing_moves_with_the_servo_off_and_jog_is_refused(make_drive):
    drive = make_drive(effects={"gravity_load": {"amplitude_nm": 0.0}})
    reply = ask(drive, "JOG", 1000)
    assert reply.terminal == "x" and "servo is off" in reply.reason
    assert ask(drive, "MOV", 9000).terminal == "x"
    drive.advance(0.2)
    assert drive.feedback_pulses == 0 and drive.monitor(103) == 0


def test_jog_held_by_repeats_then_the_watchdog_stops_within_100_ms(make_drive):
    drive = make_drive()
    drive.set_servo(True)
    jog_for(drive, 20.0, 0.6)  # 20 r/min, JOG every 50 ms
    assert speed_rpm(drive) == pytest.approx(20.0, abs=0.5)
    start = drive.feedback_pulses
    # no more JOG: it holds for the rest of its 100 ms, then the axis stops within 100 ms (the
    # command is at standstill; what is left is the position loop settling, under 10 %)
    drive.advance(0.05)
    assert speed_rpm(drive) == pytest.approx(20.0, abs=0.5)
    drive.advance(0.05 + 0.1)
    assert not drive.moving
    assert abs(speed_rpm(drive)) < 2.0
    drive.advance(0.1)
    assert abs(speed_rpm(drive)) < 0.4
    assert drive.feedback_pulses > start
    drive.advance(0.3)
    assert bit(drive, BIT_IN_POSITION) == 1


def test_servo_on_is_refused_while_an_alarm_is_active(make_drive):
    drive = make_drive()
    assert ask(drive, "FLT", 50).terminal == "q"
    assert drive.alarm == 50
    reply = ask(drive, "SVO", 1)
    assert reply.terminal == "x" and "alarm" in reply.reason
    assert bit(drive, BIT_SERVO_ON) == 0 and bit(drive, BIT_READY) == 0 and bit(drive, BIT_ALARM) == 1
    # the 4-bit code on ALM-A..D: 50 is 1101 (D C B A)
    assert drive.io_bits() >> 11 & 0xF == 0b1101
    assert ask(drive, "ACL", 0).terminal == "x"  # encoder failure needs a power cycle
    assert ask(drive, "PWC", 0).terminal == "q"
    assert drive.alarm == 0 and ask(drive, "SVO", 1).terminal == "q"
    assert ask(drive, "AHS", 0).lines[0].startswith("50,")


def test_alarm_20_overload_raises_and_clears(make_drive):
    # holding a constant 140 N m load is 4x the continuous torque of an FHA-25C-50 (35 N m)
    drive = make_drive(effects={"load_torque_offset": {"torque_nm": 140.0}},
                       constants={"overload_time_at_max_current_s": 0.5})
    drive.set_servo(True)
    drive.advance(0.3)
    assert 0 < drive.monitor(105) < 1000
    drive.advance(1.5)
    assert drive.alarm == 20
    assert not drive.servo_on  # de-energised on the alarm
    assert bit(drive, BIT_ALARM) == 1 and drive.io_bits() >> 11 & 0xF == 0b0001
    assert ask(drive, "ACL", 0).terminal == "q"
    assert drive.alarm == 0 and drive.monitor(105) == 0
    assert ask(drive, "SVO", 1).terminal == "q"


def jog_until_alarm(drive, speed_rpm: float, seconds: float) -> None:
    for _ in range(round(seconds / 0.05)):
        if ask(drive, "JOG", round(speed_rpm * 100)).terminal != "q":
            break
        drive.advance(0.05)


def test_alarm_60_error_counter_overflow_raises_and_clears(make_drive):
    drive = make_drive()
    drive.write_parameter(Mode.SYSTEM, 6, 1)  # allowance 1 x 100 pulses
    drive.set_servo(True)
    jog_until_alarm(drive, 40.0, 0.3)
    assert drive.alarm == 60
    assert ask(drive, "JOG", 1000).terminal == "x"
    assert ask(drive, "ACL", 0).terminal == "q"
    assert drive.alarm == 0 and drive.error_pulses == 0
    # the CLEAR input (CN2-2) clears it too
    drive.set_servo(True)
    jog_until_alarm(drive, 40.0, 0.3)
    assert drive.alarm == 60
    drive.set_inputs(1 << 10)
    assert drive.alarm == 0


def test_alarm_10_over_speed_needs_a_power_cycle(make_drive):
    # servo off, no brake: a 100 N m load torque runs the free axis away
    drive = make_drive(effects={"load_torque_offset": {"torque_nm": 100.0}})
    drive.advance(0.5)
    assert drive.alarm == 10
    reply = ask(drive, "ACL", 0)
    assert reply.terminal == "x" and "power cycle" in reply.reason
    assert drive.alarm == 10
    drive.power_cycle()
    assert drive.alarm == 0


def test_alarm_41_abnormal_regeneration_needs_a_power_cycle(make_drive):
    # a big load stopped hard by the watchdog feeds its kinetic energy back to the bus
    drive = make_drive(load_inertia_kgm2=3.0, constants={"regeneration_energy_capacity_j": 20.0})
    drive.write_parameter(Mode.TEST, 1, 400)  # JOG acceleration 400 r/min/s
    drive.set_servo(True)
    jog_for(drive, 60.0, 0.4)
    assert drive.alarm == 0
    drive.advance(0.5)
    assert drive.alarm == 41
    assert ask(drive, "ACL", 0).terminal == "x"
    assert ask(drive, "PWC", 0).terminal == "q"
    assert drive.alarm == 0


def test_limit_switch_inhibits_motion_towards_its_end_only(make_drive):
    drive = make_drive("FHA-25C-50-US250-L", ls2_deg=5.0, ls1_deg=-5.0)
    drive.set_servo(True)
    jog_for(drive, 10.0, 0.6)  # 60 deg/s towards CW: the dog at +5 deg stops it
    angle = math.degrees(drive.physical_angle_rad)
    assert 5.0 <= angle < 8.0
    assert bit(drive, BIT_LIMIT_2) == 1 and bit(drive, BIT_LIMIT_1) == 0
    jog_for(drive, 10.0, 0.3)
    assert math.degrees(drive.physical_angle_rad) == pytest.approx(angle, abs=0.5)
    jog_for(drive, -10.0, 0.3)  # away from the end: allowed
    assert math.degrees(drive.physical_angle_rad) < angle - 1.0
    assert bit(drive, BIT_LIMIT_2) == 0
    # the origin slit at 0 deg is seen on the way
    drive.set_sensor_angle("origin", math.degrees(drive.physical_angle_rad))
    assert bit(drive, BIT_ORIGIN) == 1


def test_fwd_inhibit_input_blocks_forward_only(make_drive):
    drive = make_drive()
    drive.set_servo(True)
    drive.set_inputs(1 << BIT_FWD_INHIBIT)
    jog_for(drive, 10.0, 0.3)
    assert abs(drive.feedback_pulses) < 50
    jog_for(drive, -10.0, 0.3)
    assert drive.feedback_pulses < -1000


def test_brake_holds_while_its_coil_is_unpowered(make_drive):
    # 30 N m of load torque against the FHA-25C-50 brake's 49 N m holding torque (4-2-1)
    drive = make_drive("FHA-25C-50-US250-B", effects={"load_torque_offset": {"torque_nm": 30.0}})
    assert drive.brake_holding_torque_nm == pytest.approx(49.0)
    drive.advance(0.5)
    assert abs(drive.feedback_pulses) < 5
    drive.set_inputs(1 << BIT_BRAKE_RELEASED)  # 24 V on the coil
    assert bit(drive, BIT_BRAKE_RELEASED) == 1
    drive.advance(0.2)
    assert drive.feedback_pulses < -1000  # the load torque turns it CCW


def test_absolute_position_survives_a_power_cycle_incremental_does_not(make_drive):
    for code, keeps in (("FHA-25C-50-S248", True), ("FHA-25C-50-US250", False)):
        drive = make_drive(code)
        drive.set_servo(True)
        jog_for(drive, 30.0, 0.5)
        drive.advance(0.3)
        drive.set_servo(False)
        before = drive.feedback_pulses
        assert before > 10000
        dgr = ask(drive, "DGR", 0)
        drive.power_cycle()
        if keeps:
            assert drive.feedback_pulses == pytest.approx(before, abs=2)
            assert ask(drive, "DGR", 0) == dgr and int(dgr.lines[0]) > 8192
        else:
            assert drive.feedback_pulses == 0
            assert dgr.terminal == "x"


def test_dgr_answers_s_with_the_servo_on_and_oww_clears_the_multi_turn_data(make_drive):
    drive = make_drive("FHA-25C-50-S248", oww_clear_s=0.05)
    drive.set_servo(True)
    jog_for(drive, 30.0, 0.5)
    drive.advance(0.3)
    assert ask(drive, "DGR", 0).terminal == "s"
    assert ask(drive, "OWW", 0).terminal == "x"  # servo on
    drive.set_servo(False)
    counts = int(ask(drive, "DGR", 0).lines[0])
    assert counts // 8192 >= 1
    assert ask(drive, "OWW", 0) is None  # the q comes later
    assert ask(drive, "OWW", 0).terminal == "x"  # repeated before the first q
    assert responder(drive).take_deferred_replies() == []
    drive.advance(0.06)
    assert [r.terminal for r in responder(drive).take_deferred_replies()] == ["q"]
    after = int(ask(drive, "DGR", 0).lines[0])
    assert 0 <= after < 8192 and abs(after - counts % 8192) < 16  # the multi-turn data is gone


def test_rotary_direction_applies_only_after_a_power_cycle(make_drive):
    drive = make_drive()
    assert ask(drive, "PSL", 8).terminal == "q"
    assert ask(drive, "PWR", 1).terminal == "q"
    assert ask(drive, "PRD", 0).lines == ("1",)
    assert drive.active_parameter("rotary_direction") == 0
    drive.set_servo(True)
    jog_for(drive, 10.0, 0.3)
    assert drive.monitor(107) > 0  # FWD still turns CW (the load encoder is physical)
    drive.set_servo(False)
    assert ask(drive, "PWC", 0).terminal == "q"
    assert drive.active_parameter("rotary_direction") == 1
    start = drive.monitor(107)
    drive.set_servo(True)
    jog_for(drive, 10.0, 0.3)
    assert drive.monitor(107) < start  # FWD now turns CCW
    assert drive.feedback_pulses > 0  # ... and still counts up in the command sense


def test_parameter_writes_refused_as_the_protocol_says(make_drive):
    drive = make_drive()
    assert ask(drive, "PRD", 0).terminal == "x"  # nothing selected
    assert ask(drive, "PSL", 7).terminal == "x"  # no such item
    assert ask(drive, "PSL", 8).terminal == "q"
    assert ask(drive, "PWR", 2).terminal == "x"  # out of range
    drive.set_servo(True)
    assert ask(drive, "PWR", 1).terminal == "s"  # parameter mode with the servo on
    assert ask(drive, "TSL", 4).terminal == "q"
    assert ask(drive, "PWR", 20).terminal == "q"  # tune items are allowed
    assert drive.active_parameter("in_position_range") == 20
    assert ask(drive, "ZZZ", 0).terminal == "x"


def test_eeprom_persists_across_instances(make_drive, tmp_path):
    path = str(tmp_path / "drive.json")
    first = make_drive(eeprom=path)
    first.write_parameter(Mode.TUNE, 2, 55)
    first.write_parameter(Mode.SYSTEM, 8, 1)
    first.raise_alarm(51)
    first.close()
    second = make_drive(eeprom=path)
    assert second.read_parameter(Mode.TUNE, 2) == 55
    assert second.active_parameter("rotary_direction") == 1  # a fresh start is a power-on
    assert second.alarm == 0 and second.alarm_history[0].code == 51


def test_corrupt_eeprom_names_the_file(make_drive, tmp_path):
    from fha_studio.hardware.sim import EepromError

    path = tmp_path / "broken.json"
    path.write_text('{"format": "fha-sim-eeprom/1", "parameters": ', encoding="utf-8")
    with pytest.raises(EepromError, match=r"broken\.json.*corrupt"):
        make_drive(eeprom=str(path))
    path.write_text('{"format": "fha-sim-eeprom/1", "parameters": {"system": {"rotary_direction": 7}}}',
                    encoding="utf-8")
    with pytest.raises(EepromError, match=r"broken\.json.*parameter 8, rotary direction"):
        make_drive(eeprom=str(path))


def test_move_by_angle_reaches_the_target_and_is_in_position(make_drive):
    drive = make_drive()
    drive.set_servo(True)
    assert ask(drive, "SPD", 3000).terminal == "q"  # 30 r/min
    assert ask(drive, "MOV", 9000).terminal == "q"  # +90 deg
    assert ask(drive, "MOV", 100).terminal == "x"  # moving
    drive.advance(1.5)
    assert not drive.moving
    assert drive.feedback_pulses == pytest.approx(drive.output_ppr // 4, abs=20)
    assert bit(drive, BIT_IN_POSITION) == 1


def test_trace_capture_in_blocks(make_drive):
    drive = make_drive()
    drive.set_servo(True)
    for cmd, value in (("TCH", 0b1001), ("TDV", 5), ("TTG", 0), ("TPR", 0), ("TAR", 100)):
        assert ask(drive, cmd, value).terminal == "q", cmd
    assert ask(drive, "TST", 0).lines[0].startswith("2,")
    jog_for(drive, 10.0, 0.1)  # 100 samples x 5 periods at 5 kHz = 0.1 s
    assert ask(drive, "TST", 0).lines == ("3,100",)
    block0 = ask(drive, "TRB", 0).lines
    block1 = ask(drive, "TRB", 1).lines
    assert len(block0) == 64 and len(block1) == 36
    assert ask(drive, "TRB", 2).terminal == "x"
    positions = [int(line.split(",")[0]) for line in block0 + block1]
    assert positions == sorted(positions) and positions[-1] > positions[0]
    assert ask(drive, "TCH", 0b11111).terminal == "x"  # more than 4 channels


def test_packed_trace_blocks_carry_the_text_blocks_values_in_fewer_characters(make_drive):
    from fha_studio.hardware import protocol as p

    drive = make_drive()
    assert "TRP" in ask(drive, "CAP", 0).lines[0].split()
    drive.set_servo(True)
    for cmd, value in (("TCH", 0b11011), ("TDV", 5), ("TTG", 0), ("TPR", 0), ("TAR", 100)):
        assert ask(drive, cmd, value).terminal == "q", cmd
    jog_for(drive, 20.0, 0.15)
    for block, samples in ((0, 64), (1, 36)):
        text = ask(drive, "TRB", block).lines
        packed = ask(drive, "TRP", block).lines
        assert p.decode_packed_block(packed, samples, 4) == [tuple(p.parse_values(line)) for line in text]
        assert all(2 <= len(line) <= p.PACKED_LINE_CHARS for line in packed)
        assert sum(len(line) + 1 for line in packed) * 2 < sum(len(line) + 1 for line in text)
    assert ask(drive, "TRP", 2).terminal == "x"


def test_a_drive_from_before_the_packed_encoding_has_no_trp(make_drive):
    drive = make_drive(packed_trace=False)
    assert "TRP" not in ask(drive, "CAP", 0).lines[0].split()
    assert "TRB" in ask(drive, "CAP", 0).lines[0].split()
    for cmd, value in (("TCH", 0b1), ("TTG", 0), ("TAR", 10)):
        ask(drive, cmd, value)
    drive.advance(0.01)
    assert ask(drive, "TRP", 0).terminal == "x"
    assert len(ask(drive, "TRB", 0).lines) == 10


def test_trace_level_trigger_keeps_pretrigger_samples(make_drive):
    drive = make_drive()
    drive.set_servo(True)
    for cmd, value in (("TCH", 0b1000), ("TDV", 10), ("TTG", 1), ("TTC", 103), ("TTL", 500),
                       ("TPR", 20), ("TAR", 60)):
        assert ask(drive, cmd, value).terminal == "q", cmd
    drive.advance(0.1)
    assert ask(drive, "TST", 0).lines[0].startswith("1,")
    jog_for(drive, 10.0, 0.3)
    assert ask(drive, "TST", 0).lines == ("3,60",)
    speeds = [int(line) for line in ask(drive, "TRB", 0).lines]
    assert speeds[19] < 500 <= speeds[20]


def test_speed_mode_after_a_power_cycle_has_no_error_counter(make_drive):
    drive = make_drive()
    drive.write_parameter(Mode.SYSTEM, 0, 1)  # control mode: speed (restart required)
    drive.write_parameter(Mode.SYSTEM, 6, 1)  # an allowance that position mode would overflow
    assert not drive.speed_mode
    drive.power_cycle()
    assert drive.speed_mode
    drive.set_servo(True)
    jog_for(drive, 40.0, 0.4)
    assert drive.alarm == 0 and drive.error_pulses == 0
    assert speed_rpm(drive) == pytest.approx(40.0, abs=1.0)


def test_quantised_feedback_gives_a_real_drives_current_noise_while_moving(make_drive):
    drive = make_drive()
    drive.set_servo(True)
    jog_for(drive, 30.0, 0.4)
    currents = []
    for _ in range(40):
        drive.jog(30.0)
        drive.advance(0.002)
        currents.append(drive.monitor(104))
    assert len(set(currents)) > 5  # not a constant: the pulse-difference speed is noisy
    assert abs(sum(currents) / len(currents)) < 500  # ... around zero without friction


@pytest.mark.parametrize("load_inertia_kgm2", [0.0, 1.5])
def test_the_status_current_is_the_mean_not_one_sample_of_the_quantisation_dither(make_drive,
                                                                                 load_inertia_kgm2):
    # A frictionless, gravity-free axis needs no current at a steady 8 r/min or at rest; one sample
    # of monitor 104 per status poll read -0.19 A and -0.3 A there (the pulse-difference speed's
    # dither). Monitor 112, the mean over 10 ms, is what the read-outs show.
    drive = make_drive(load_inertia_kgm2=load_inertia_kgm2)
    drive.set_servo(True)

    def polls(hold_rpm: float | None) -> tuple[list[int], list[int]]:
        instantaneous, mean = [], []
        for k in range(25):  # polls at phases that do not repeat the dither's period
            if hold_rpm is not None:
                drive.jog(hold_rpm)
            drive.advance(0.0503 + 0.0007 * k)
            instantaneous.append(drive.monitor(104))
            mean.append(drive.monitor(112))
        return instantaneous, mean

    for rpm in (8.0, -8.0):
        jog_for(drive, rpm, 1.5)
        instantaneous, mean = polls(rpm)
        assert max(instantaneous) - min(instantaneous) > 200  # mA: the dither is there ...
        assert max(abs(m) for m in mean) < 30  # ... and the mean is zero within its residue (mA)
        drive.stop()
        drive.advance(1.0)
    drive.move_by(90.0)
    drive.advance(4.0)
    assert drive.axis.motion_done and drive.axis.in_position
    _, mean = polls(None)  # at rest the axis hunts between pulses now and then (or sits still)
    assert max(abs(m) for m in mean) < 30
    # the mean is item 104's over the last 10 ms, servo period by servo period (5 kHz)
    drive.move_by(-30.0)
    samples = []
    for _ in range(100):
        drive.advance(0.0002)
        samples.append(drive.monitor(104))
    assert drive.monitor(112) == pytest.approx(sum(samples[-50:]) / 50, abs=1.0)


def test_driver_from_the_combination_table_and_supply_voltage(make_drive):
    assert make_drive("FHA-25C-50-US250-A").driver == "HA-655-4-100"  # 100 V (option A), 1-3
    assert make_drive("FHA-32C-100-S248").driver == "HA-655-4A-200"
    drive = make_drive("FHA-17C-50-US250", driver="HA-675-2-200")
    assert ask(drive, "IDN", 0).lines[0] == "HA-675-2-200"
    assert drive.parameters.driver == "HA-675"


def test_user_eeprom_lives_in_the_user_data_directory(make_drive, tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    drive = make_drive(eeprom="user")
    drive.write_parameter(Mode.TUNE, 4, 33)
    expected = tmp_path / "data" / "fha-studio" / "sim" / "HA-655-2-200_FHA-25C-50-US250.json"
    assert drive.eeprom.path == expected and expected.exists()
