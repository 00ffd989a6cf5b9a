"""SimProtocolServer (bytes through the codec, line pacing) and the sim:// URL handler."""

from __future__ import annotations

import threading

import pytest
import serial

from fha_studio.hardware.protocol import character_time_s
from fha_studio.hardware.sim import SimConfigError, SimProtocolServer, config_from_url, register_url_handler
from tests.support.clock import FakeClock


def test_unpaced_server_answers_at_once_and_resynchronises(make_drive):
    server = SimProtocolServer(make_drive(), paced=False)
    server.feed(b"IDN+00000\r")
    assert server.read_ready() == b"HA-655-2-200\rFHA-25C-50-US250\rFHA Studio simulated drive 0.1.0\rq\r"
    # a half frame, noise, then a good frame: only the good one is answered
    server.feed(b"DGR+00\x00\xffPSL+00008\r")
    assert server.read_ready() == b"q\r"
    server.feed(b"PRD+0000")
    assert server.read_ready() == b""  # nothing until all ten characters are there
    server.feed(b"0\r")
    assert server.read_ready() == b"0\rq\r"
    server.feed(b"ZZZ+00000\rDGR+00000\r")  # unknown command; DGR on an incremental encoder
    assert server.read_ready() == b"x\rx\r"
    assert server.garbage_bytes == 8 and server.transactions == 5


def test_paced_server_takes_the_time_of_a_19200_baud_line(make_drive):
    clock = FakeClock()
    server = SimProtocolServer(make_drive(), clock=clock)
    char = character_time_s()
    assert char == pytest.approx(10 / 19200)
    server.feed(b"PSL+00008\r")
    clock.now += 9.5 * char
    assert server.read_ready() == b""  # the CR has not arrived yet
    clock.now += 0.5 * char  # the command is complete: it is handled, the reply starts
    assert server.read_ready() == b""
    clock.now += 1 * char
    assert server.read_ready() == b"q"
    clock.now += 1 * char
    assert server.read_ready() == b"\r"
    server.feed(b"PRD+00000\r")
    clock.now += 10 * char
    assert server.in_waiting() == 0
    assert server.next_event_s() == pytest.approx(char)
    clock.now += 4 * char
    assert server.read_ready() == b"0\rq\r"


def test_sim_url_options_are_parsed_and_checked():
    config = config_from_url(
        "sim://FHA-32C-100-S248-B?load_inertia=1.5&brake=0&sensors=1&paced=0&ls1_deg=-30"
        "&effects=coulomb_friction:torque_nm=8;viscous_friction:coefficient_nm_s_per_rad=2"
        "&effect=gravity_load:amplitude_nm=20,phase_deg=90&oww_clear_s=0.1"
    )
    assert config.actuator == "FHA-32C-100-S248-B"
    assert config.load_inertia_kgm2 == 1.5 and config.brake is False and config.sensors is True
    assert config.paced is False and config.ls1_deg == -30 and config.oww_clear_s == 0.1
    assert config.effects == {
        "coulomb_friction": {"torque_nm": 8.0},
        "viscous_friction": {"coefficient_nm_s_per_rad": 2.0},
        "gravity_load": {"amplitude_nm": 20.0, "phase_deg": 90.0},
    }
    with pytest.raises(SimConfigError, match=r"no option 'inertia' \(did you mean 'load_inertia'\?\)"):
        config_from_url("sim://FHA-25C-50-US250?inertia=1")
    with pytest.raises(SimConfigError, match="load_inertia"):
        config_from_url("sim://FHA-25C-50-US250?load_inertia=-1")
    with pytest.raises(SimConfigError, match="paced"):
        config_from_url("sim://FHA-25C-50-US250?paced=maybe")
    with pytest.raises(SimConfigError, match="actuator model code is missing"):
        config_from_url("sim://?paced=0")


def test_bad_actuator_or_effect_says_what_is_wrong(make_drive):
    with pytest.raises(SimConfigError, match="frame"):
        make_drive("FHA-99C-50-US250")
    with pytest.raises(SimConfigError, match="friction_nm"):
        make_drive(effects={"coulomb_friction": {"friction_nm": 1.0}})
    with pytest.raises(SimConfigError, match="HA-655-4-200"):
        make_drive(driver="HA-655-4-200")  # 1-3: an FHA-25C runs on the -2- driver


def test_serial_for_url_reaches_the_drive_through_bytes(tmp_path):
    register_url_handler()
    before = set(threading.enumerate())
    port = serial.serial_for_url(f"sim://FHA-25C-50-S248-L?paced=0&eeprom={tmp_path / 'e.json'}", timeout=1.0)
    try:
        assert port.sim_drive.actuator_code == "FHA-25C-50-S248-L"
        port.write(b"DGR+00000\r")
        assert port.read_until(b"q\r") == b"0\rq\r"
        port.write(b"SVO+00001\rDGR+00000\r")
        assert port.read(4) == b"q\rs\r"
        port.write(b"SNQ+00000\r")
        assert port.read_until(b"q\r") == b"0,-15000,15000\rq\r"
        assert port.in_waiting == 0
    finally:
        port.close()
    assert port.sim_drive is None
    assert not [t for t in threading.enumerate() if t not in before and t.is_alive()]


def test_paced_url_reads_wait_for_the_line(tmp_path):
    register_url_handler()
    port = serial.serial_for_url(f"sim://FHA-17C-50-US250?eeprom={tmp_path / 'e.json'}", timeout=1.0)
    try:
        port.write(b"IDN+00000\r")
        reply = port.read_until(b"q\r")
        assert reply.endswith(b"q\r") and reply.startswith(b"HA-655-2-200\r")
        port.timeout = 0.0
        assert port.read(10) == b""
    finally:
        port.close()


def test_bad_sim_url_is_a_serial_exception_naming_the_option():
    register_url_handler()
    with pytest.raises(serial.SerialException,
                       match=r"no option 'colour'; its options are listed in docs/sim\.md"):
        serial.serial_for_url("sim://FHA-25C-50-US250?colour=red")


def test_oww_acknowledges_later_through_the_url_in_real_time(tmp_path):
    register_url_handler()
    url = f"sim://FHA-25C-50-S248?paced=0&oww_clear_s=0.2&eeprom={tmp_path / 'e.json'}"
    with serial.serial_for_url(url, timeout=0.05) as port:
        assert port.sim_drive.running
        port.write(b"OWW+00000\r")
        assert port.read(2) == b""  # nothing yet: the multi-turn data is being cleared
        port.write(b"OWW+00000\r")
        assert port.read(2) == b"x\r"  # repeated before the first q
        port.timeout = 2.0
        assert port.read(2) == b"q\r"


def test_a_stepped_url_drive_takes_only_the_time_its_holder_gives_it(tmp_path):
    register_url_handler()
    url = f"sim://FHA-25C-50-S248?paced=0&stepped=1&oww_clear_s=0.2&eeprom={tmp_path / 'e.json'}"
    with serial.serial_for_url(url, timeout=0.3) as port:
        drive = port.sim_drive
        assert not drive.running  # no real-time thread
        port.write(b"OWW+00000\r")
        assert port.read(2) == b""  # 0.3 s of wall clock: no drive time has passed
        drive.advance(0.19)
        assert port.read(2) == b""
        drive.advance(0.02)
        assert port.read(2) == b"q\r"  # the multi-turn data cleared after 0.2 s of drive time
