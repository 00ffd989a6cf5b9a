"""Each training fault of the simulated drive, seen through the ordinary client (DriveClient over
``sim://...?paced=0&stepped=1``) as a trainee's pages see it: nothing here looks inside the drive.
The drive's time is stepped: a test holds a jog for so much drive time (``advance``), JOG inside
the 100 ms watchdog by construction, so a loaded machine changes nothing."""

from __future__ import annotations

import pytest

from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.errors import CommandNotSupported, DriveRefused
from fha_studio.hardware.parameters import MonitorItem
from fha_studio.hardware.protocol import ABSOLUTE_COUNTS_PER_TURN
from fha_studio.hardware.sim import SimDrive
from fha_studio.hardware.sim.options import (
    SimConfigError,
    config_from_url,
    forget_training,
    public_url,
    register_training,
)
from tests.sim.conftest import advance

WAIT_S = 10.0  # drive time to wait for an alarm
JOG_REPEAT_S = 0.04  # a held jog button repeats JOG inside the drive's 100 ms watchdog


def _open(query: str, actuator: str = "FHA-25C-50-US250-B-L") -> DriveClient:
    return DriveClient.open(f"sim://{actuator}?paced=0&stepped=1&{query}")


def _jog_until(client: DriveClient, speed_rpm: float, seconds: float, stop_on_alarm: bool = True) -> None:
    """Hold a jog for ``seconds`` of drive time (JOG every 40 ms), then STOP."""
    held = 0.0
    while held < seconds - 1e-9:
        try:
            client.jog(speed_rpm)
        except DriveRefused:
            if stop_on_alarm:
                return
            raise
        if stop_on_alarm and client.alarm():
            return
        step = min(JOG_REPEAT_S, seconds - held)
        advance(client, step)
        held += step
    client.stop()


def _wait_alarm(client: DriveClient, speed_rpm: float = 5.0) -> int:
    """Jog in 0.3 s holds until the drive raises an alarm (at most WAIT_S of drive time)."""
    held = 0.0
    while held < WAIT_S and not client.alarm():
        _jog_until(client, speed_rpm, 0.3)
        held += 0.3
    return client.alarm()


@pytest.mark.parametrize(
    "wiring, lurch", [("motor_open", False), ("motor_swapped", True), ("encoder_swapped", True)]
)
def test_motor_or_encoder_leads_trip_alarm_60_on_the_first_jog(wiring, lurch):
    client = _open(f"wiring={wiring}")
    try:
        client.set_inputs(brake_released=True)
        client.servo(True)
        start = client.read_monitor(MonitorItem.LOAD_POSITION)  # the load side: physical, CW +
        assert _wait_alarm(client) == 60
        assert not client.io_state().servo_on  # the drive switched it off with the alarm
        moved = client.read_monitor(MonitorItem.LOAD_POSITION) - start
        ppr_per_deg = 500_000 / 360  # FHA-25C-50 with the 2500 ppr encoder: 500000 output pulses
        if lurch:
            assert moved < -1.0 * ppr_per_deg  # against the FWD (= CW) command
        else:
            assert abs(moved) < 0.1 * ppr_per_deg
        client.clear_alarm()
        assert client.alarm() == 0
    finally:
        client.close()


def test_encoder_lead_open_raises_alarm_50_that_no_reset_clears():
    client = _open("wiring=encoder_open")
    try:
        assert client.alarm() == 50
        with pytest.raises(DriveRefused):
            client.servo(True)
        with pytest.raises(DriveRefused):
            client.clear_alarm()
        client.power_cycle()
        assert client.alarm() == 50  # the lead is still open
        assert client.alarm_history()[0].code == 50
    finally:
        client.close()


def test_encoder_leads_swapped_count_the_other_way(make_drive):
    # turning the output by hand is the panel's (the technician's hands), not a CN3 command
    good, swapped = make_drive(), make_drive(wiring="encoder_swapped")
    for drive in (good, swapped):
        drive.turn_by_hand(10.0)
    assert good.monitor(MonitorItem.FEEDBACK_POSITION) > 0 > swapped.monitor(MonitorItem.FEEDBACK_POSITION)


def test_brake_supply_missing_the_brake_never_releases_and_jogging_heats_the_motor():
    client = _open("brake_supply=0")
    try:
        assert not client.set_inputs(brake_released=True).brake_released
        client.servo(True)
        _jog_until(client, 5.0, 1.0)
        assert client.read_monitor(MonitorItem.OVERLOAD_RATE) > 0  # dragging the brake: above continuous
    finally:
        client.close()
    good = _open("")
    try:
        assert good.set_inputs(brake_released=True).brake_released
        good.servo(True)
        _jog_until(good, 5.0, 1.0)
        assert good.read_monitor(MonitorItem.OVERLOAD_RATE) == 0
    finally:
        good.close()


def test_brake_supply_missing_overload_alarm_follows(make_drive):
    drive = make_drive("FHA-25C-50-US250-B", brake_supply=False)
    drive.set_inputs(1 << 9)
    drive.set_servo(True)
    for n in range(2000):  # up to 100 s of drive time, stepped
        drive.jog(10.0 if n // 300 % 2 == 0 else -10.0)
        drive.advance(0.05)
        if drive.alarm:
            break
    assert drive.alarm == 20


def test_sensor_dog_outside_the_movable_range_shows_in_the_dog_angles():
    client = _open("ls2_deg=178", actuator="FHA-25C-50-US250-L")
    try:
        assert client.sensor_angles()["ls2"] == pytest.approx(178.0, abs=0.1)
    finally:
        client.close()


def test_position_error_allowance_far_too_low_trips_alarm_60_in_motion():
    client = _open("preset=system.6=1")
    try:
        assert client.read_parameter("system", 6) == 1
        client.set_inputs(brake_released=True)
        client.servo(True)
        assert _wait_alarm(client) == 60
        client.clear_alarm()
        client.write_parameter("system", 6, 500)  # the fix: the default
        client.servo(True)
        _jog_until(client, 5.0, 0.5)
        assert client.alarm() == 0
    finally:
        client.close()


def test_rotary_direction_preset_turns_fwd_ccw():
    client = _open("preset=system.8=1")
    try:
        assert client.read_parameter("system", 8) == 1
        client.set_inputs(brake_released=True)
        client.servo(True)
        start = client.read_monitor(MonitorItem.LOAD_POSITION)
        _jog_until(client, 5.0, 0.5)
        advance(client, 0.2)  # the axis comes to rest
        assert client.read_monitor(MonitorItem.LOAD_POSITION) < start  # FWD turned CCW
    finally:
        client.close()


def test_battery_low_raises_56_and_lost_multi_turn_data_shows_in_the_absolute_position():
    low = _open("battery=low", actuator="FHA-25C-50-S248")
    try:
        assert low.alarm() == 56
        assert abs(low.absolute_position()) < ABSOLUTE_COUNTS_PER_TURN
    finally:
        low.close()
    lost = _open("battery=lost", actuator="FHA-25C-50-S248")
    try:
        assert lost.alarm() == 56
        assert round(lost.absolute_position() / ABSOLUTE_COUNTS_PER_TURN) == 37  # output stands at 0
    finally:
        lost.close()


def test_battery_fault_needs_an_absolute_encoder():
    with pytest.raises(SimConfigError, match="incremental encoder"):
        SimDrive.from_url("sim://FHA-25C-50-US250?battery=low")
    with pytest.raises(SimConfigError, match="battery: 'flat'"):
        config_from_url("sim://FHA-25C-50-S248?battery=flat")
    with pytest.raises(SimConfigError, match="wiring: 'loose'"):
        config_from_url("sim://FHA-25C-50-S248?wiring=loose")
    with pytest.raises(SimConfigError, match="preset: 'system8=1'"):
        config_from_url("sim://FHA-25C-50-S248?preset=system8=1")
    with pytest.raises(SimConfigError, match=r"preset system\.8=7"):
        SimDrive.from_url("sim://FHA-25C-50-S248?preset=system.8=7")


def _torque_at_jog_speed_nm(query: str) -> float:
    """The median output torque (monitor 108) over the second half of a 1 s jog at 5 r/min."""
    client = _open(query, actuator="FHA-25C-50-US250")
    try:
        client.servo(True)
        samples = []
        for _ in range(round(1.0 / JOG_REPEAT_S)):
            client.jog(5.0)
            samples.append(abs(client.read_monitor(MonitorItem.OUTPUT_TORQUE)) / 100.0)
            advance(client, JOG_REPEAT_S)
        client.stop()
        steady = sorted(samples[len(samples) // 2 :])
        return steady[len(steady) // 2]
    finally:
        client.close()


def test_hidden_friction_raises_the_torque_at_jog_speed():
    plain = _torque_at_jog_speed_nm("")
    with_friction = _torque_at_jog_speed_nm("effects=coulomb_friction:torque_nm=20")
    assert with_friction - plain == pytest.approx(20.0, abs=2.0)  # 20 N·m of friction


def test_documented_profile_takes_servo_on_only_from_the_controller():
    client = _open("profile=documented", actuator="FHA-25C-50-S248")
    try:
        with pytest.raises(CommandNotSupported):
            client.servo(True)
        assert isinstance(client.absolute_position(), int)
    finally:
        client.close()


def test_a_training_drive_hides_its_options_and_journals_what_was_done():
    registration = register_training("preset=system.6=1&wiring=motor_open")
    url = f"sim://FHA-25C-50-US250-B-L?training={registration.token}&paced=0"
    try:
        assert public_url(url) == "sim://FHA-25C-50-US250-B-L (training)"
        assert "motor" not in public_url(url) and "preset" not in public_url(url)
        client = DriveClient.open(url)
        try:
            assert client.read_parameter("system", 6) == 1  # the hidden preset is there
            client.servo(True)
            with pytest.raises(DriveRefused):
                client.write_parameter("system", 8, 1)  # parameter mode, servo on: refused
        finally:
            client.close()
        entries = registration.journal.entries()
        writes = [e for e in entries if e.command == "PWR"]
        assert writes and writes[-1].servo_on and writes[-1].terminal == "s"
        assert writes[-1].item == ("system", 8)
    finally:
        forget_training(registration.token)
    with pytest.raises(SimConfigError, match="no longer registered"):
        config_from_url(url)


SAMPLE_S = 0.005


def _holding_and_peak_torque_nm(query: str) -> tuple[float, float]:
    """The output torque holding still after servo-on, and its peak starting a 20 r/min jog."""
    client = _open(query, actuator="FHA-32C-50-US250")
    try:
        client.servo(True)
        advance(client, 0.3)
        holding = abs(client.read_monitor(MonitorItem.OUTPUT_TORQUE)) / 100.0
        peak = 0.0
        for _ in range(round(0.6 / SAMPLE_S)):  # JOG held 0.6 s, the torque read every 5 ms
            client.jog(20.0)
            peak = max(peak, abs(client.read_monitor(MonitorItem.OUTPUT_TORQUE)) / 100.0)
            advance(client, SAMPLE_S)
        client.stop()
        return holding, peak
    finally:
        client.close()


def test_hidden_gravity_unbalance_shows_in_the_holding_torque():
    plain, _ = _holding_and_peak_torque_nm("load_inertia=2")
    unbalanced, _ = _holding_and_peak_torque_nm(
        "load_inertia=2&effects=gravity_load:amplitude_nm=30,phase_deg=90"
    )
    assert plain < 5.0 and unbalanced > 20.0  # 30 N·m of unbalance at the output's 0 degrees


def test_a_load_heavier_than_declared_shows_in_the_torque_to_accelerate():
    _, declared = _holding_and_peak_torque_nm("load_inertia=2")
    _, heavier = _holding_and_peak_torque_nm("load_inertia=5")
    # 1.79 x in drive time, on any machine (the drive is stepped, the torque read every 5 ms)
    assert heavier > 1.5 * declared
