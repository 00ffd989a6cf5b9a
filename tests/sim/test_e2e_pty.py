"""End to end: ``fha-studio sim --pty --unpaced`` in its own process, DriveClient over the pty.

The jog loops repeat JOG on every pass (a held jog button) until the drive shows what the test
waits for, not for a time: a pass that comes late on a loaded machine lets the drive's 100 ms
watchdog stop the axis, and the next JOG starts it again. Only a hang takes LIMIT_S.
"""

from __future__ import annotations

import time

import pytest

from fha_studio.hardware.client import DriveClient, LinkSettings
from fha_studio.hardware.errors import CommandRejected, LinkLost, LinkTimeout
from fha_studio.hardware.parameters import Mode
from tests.support.processes import Child

pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def sim(tmp_path_factory):
    with Child.sim(tmp_path_factory.mktemp("sim") / "eeprom.json", "--pty") as process:
        client = DriveClient.open(process.address)
        yield client
        client.close()
    assert process.returncode == 0  # SIGTERM ends it cleanly (EEPROM saved, threads stopped)


#: Only a hang takes this long (a jog turns the output 1000 pulses in some 0.1 s).
LIMIT_S = 15.0


def jog_until_moved(client: DriveClient, speed_rpm: float, pulses: int) -> int:
    """Hold a jog until the load encoder (monitor 107) has counted ``pulses`` either way, then
    STOP; returns the count it moved."""
    start = client.read_monitor(107)
    deadline = time.monotonic() + LIMIT_S
    while abs(moved := client.read_monitor(107) - start) < pulses:
        assert time.monotonic() < deadline, f"a jog held {LIMIT_S} s moved {moved} pulses"
        client.jog(speed_rpm)
    client.stop()
    return moved


def test_reads_every_parameter_and_monitor(sim):
    ident = sim.identify()
    assert ident is not None and ident.driver_model == "HA-655-2-200"
    for mode in (Mode.TUNE, Mode.SYSTEM, Mode.TEST):
        values = sim.read_all_parameters(mode)
        expected = {item.number: item.default for item in sim.model.in_mode(mode)}
        assert values == expected, mode
    for item in sim.model.in_mode(Mode.MONITOR):
        assert isinstance(sim.read_monitor(item.number), int)


def test_writes_rotary_direction_and_reads_it_back(sim):
    result = sim.write_parameter(Mode.SYSTEM, 8, 1)
    assert result.verified and result.needs_restart
    assert sim.read_parameter(Mode.SYSTEM, 8) == 1
    assert sim.write_parameter(Mode.SYSTEM, 8, 0).verified
    assert sim.read_parameter(Mode.SYSTEM, 8) == 0


def test_jog_turns_the_way_the_rotary_direction_says(sim):
    sim.servo(True)
    assert jog_until_moved(sim, 10.0, 1000) > 0  # the load encoder: CW seen from the flange counts up
    sim.servo(False)
    sim.write_parameter(Mode.SYSTEM, 8, 1)
    sim.power_cycle()
    sim.servo(True)
    assert jog_until_moved(sim, 10.0, 1000) < 0
    sim.servo(False)
    sim.write_parameter(Mode.SYSTEM, 8, 0)
    sim.power_cycle()


def test_raises_and_clears_an_alarm(sim):
    previous = sim.read_parameter(Mode.SYSTEM, 6)
    sim.write_parameter(Mode.SYSTEM, 6, 1)  # error allowance 100 pulses
    sim.servo(True)
    deadline = time.monotonic() + LIMIT_S
    while sim.alarm() == 0 and time.monotonic() < deadline:  # held until the alarm
        try:
            sim.jog(40.0)
        except CommandRejected:
            break
    assert sim.alarm() == 60
    assert sim.io_state().alm_bits == 0b0010
    sim.clear_alarm()
    assert sim.alarm() == 0
    assert sim.alarm_history()[0].code == 60
    sim.write_parameter(Mode.SYSTEM, 6, previous)


def test_killing_the_sim_gives_a_clean_link_error(tmp_path, time_ceiling):
    process = Child.sim(tmp_path / "eeprom.json", "--pty")
    client = DriveClient.open(process.address, LinkSettings(response_timeout_s=0.3, retries=1))
    try:
        assert sim_alive(client)
        process.kill()
        started = time.monotonic()
        with pytest.raises((LinkLost, LinkTimeout)):
            for _ in range(5):
                client.read_monitor(100)
        time_ceiling("a link error after the sim is killed", time.monotonic() - started, 10.0)
    finally:
        client.close()
        process.stop()


def sim_alive(client: DriveClient) -> bool:
    return client.alarm() == 0
