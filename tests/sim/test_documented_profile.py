"""The simulated drive's ``documented`` profile: only what the public HA-655 manual documents.

DGR and OWW over CN3, ``x`` to everything else, ``s`` to everything while the servo is on; the
servo is switched by the controller's CN2 input; the output can be turned by hand with the servo off.
"""

from __future__ import annotations

import os
import select
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fha_studio.cli.sim import panel_line
from fha_studio.hardware.client import CapabilityLevel, DriveClient
from fha_studio.hardware.errors import ServoOnRefused
from fha_studio.hardware.protocol import EXTENSION_COMMANDS
from fha_studio.hardware.sim import SimConfigError, SimDrive, config_from_url
from tests.sim.conftest import ask, responder
from tests.support.processes import Child

ROOT = Path(__file__).resolve().parents[2]
COUNTS_PER_DEG_50 = 8192 * 50 / 360  # DGR counts per output degree at ratio 50


def dgr(drive: SimDrive) -> int:
    reply = ask(drive, "DGR", 0)
    assert reply is not None and reply.terminal == "q", reply
    return int(reply.lines[0])


def test_answers_only_dgr_and_oww(make_drive):
    drive = make_drive("FHA-25C-50-S248", profile="documented")
    assert responder(drive).documented_only and responder(drive).capabilities() == []
    for command in EXTENSION_COMMANDS:
        assert ask(drive, command, 0).terminal == "x", command
    assert ask(drive, "DGR", 0).terminal == "q"


def test_servo_on_from_cn2_answers_s_to_everything(make_drive):
    drive = make_drive("FHA-25C-50-S248", profile="documented")
    drive.set_servo(True)
    for command in ("DGR", "OWW", "CAP", "SVO", "MON"):
        assert ask(drive, command, 0).terminal == "s", command
    drive.set_servo(False)
    assert ask(drive, "DGR", 0).terminal == "q"


def test_turning_by_hand_changes_dgr_by_ratio_x_8192_per_motor_turn(make_drive):
    drive = make_drive("FHA-25C-50-S248", profile="documented")
    start = dgr(drive)
    drive.turn_by_hand(10.0)  # CW seen from the flange
    assert dgr(drive) - start == pytest.approx(10 * COUNTS_PER_DEG_50, abs=1)
    drive.turn_by_hand(-25.0)
    assert dgr(drive) - start == pytest.approx(-15 * COUNTS_PER_DEG_50, abs=1)
    drive.set_servo(True)
    with pytest.raises(Exception, match="servo is on"):
        drive.turn_by_hand(1.0)


def test_a_held_brake_cannot_be_turned_by_hand(make_drive):
    drive = make_drive("FHA-25C-50-S248-B", profile="documented")
    assert "refused: the brake holds" in panel_line(responder(drive), "turn 5")
    assert panel_line(responder(drive), "brake release") == "brake released"
    assert panel_line(responder(drive), "turn 5") == "turned by hand by 5 deg"


@pytest.mark.parametrize("rotary_direction, sign", [(0, 1), (1, -1)])
def test_a_fwd_command_turns_cw_unless_parameter_8_reverses_it(make_drive, rotary_direction, sign):
    drive = make_drive("FHA-25C-50-S248", profile="documented")
    drive.write_parameter("system", 8, rotary_direction)  # on the front panel
    drive.power_cycle()
    before = dgr(drive)
    assert panel_line(responder(drive), "servo on") == "servo on (CN2)"
    assert panel_line(responder(drive), "fwd 5") == "controller: FWD 5 deg"
    drive.advance(2.0)
    assert panel_line(responder(drive), "servo off") == "servo off (CN2)"
    assert (dgr(drive) - before) * sign == pytest.approx(5 * COUNTS_PER_DEG_50, rel=0.02)


def test_oww_clears_the_multi_turn_data_about_5_s_later(make_drive):
    drive = make_drive("FHA-25C-50-S248", profile="documented")
    drive.turn_by_hand(3 * 360 / 50 + 1.0)  # three motor turns and a bit
    assert dgr(drive) // 8192 == 3
    single = dgr(drive) % 8192
    assert ask(drive, "OWW", 0) is None  # the q comes later
    assert ask(drive, "OWW", 0).terminal == "x"  # repeated before the first acknowledgement
    drive.advance(4.9)
    assert responder(drive).take_deferred_replies() == []
    drive.advance(0.2)
    assert [r.terminal for r in responder(drive).take_deferred_replies()] == ["q"]
    assert dgr(drive) == single


def test_an_incremental_encoder_answers_x_to_dgr_and_oww(make_drive):
    drive = make_drive("FHA-25C-50-US250", profile="documented")
    assert ask(drive, "DGR", 0).terminal == "x"
    assert ask(drive, "OWW", 0).terminal == "x"


def test_url_option_and_its_check():
    assert config_from_url("sim://FHA-25C-50-S248?profile=documented").profile == "documented"
    assert config_from_url("sim://FHA-25C-50-S248").profile == "full"
    with pytest.raises(SimConfigError, match="profile"):
        config_from_url("sim://FHA-25C-50-S248?profile=everything")


def test_the_client_sees_a_drive_of_the_manual(tmp_path):
    url = f"sim://FHA-25C-50-S248?profile=documented&paced=0&eeprom={tmp_path / 'e.json'}"
    with DriveClient.open(url) as client:
        caps = client.capabilities
        assert caps.level is CapabilityLevel.ABSOLUTE_POSITION and not caps.parameters
        assert isinstance(client.absolute_position(), int)


def said_by(proc: Child, words: bytes, limit_s: float = 30.0) -> None:
    """Wait until ``proc`` says ``words`` on its stderr; fail naming what it said when it ends
    first or stays silent ``limit_s``."""
    said = b""
    deadline = time.monotonic() + limit_s
    while words not in said:
        ready, _, _ = select.select([proc.stderr], [], [], max(0.0, deadline - time.monotonic()))
        if not ready:
            pytest.fail(f"the sim did not say {words.decode()!r} within {limit_s:g} s; "
                        f"it said {said.decode()!r}")
        chunk = os.read(proc.stderr.fileno(), 4096)  # the pipe's bytes, no buffer select cannot see
        if not chunk:
            pytest.fail(f"the sim ended (exit code {proc.proc.wait(10)}) before it said {words.decode()!r}; "
                        f"it said {said.decode()!r}")
        said += chunk


@pytest.mark.e2e
def test_probe_a_documented_sim_in_another_process_and_switch_its_servo(tmp_path):
    """``fha-studio sim --profile documented --panel`` over a pty; servo-ON typed on its stdin."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    with Child.sim(tmp_path / "e.json", "--pty", "--profile", "documented", "--panel",
                   "--actuator", "FHA-25C-50-S248", stdin=True) as sim:
        path = sim.address

        def fha(*args: str) -> subprocess.CompletedProcess:
            return subprocess.run([sys.executable, "-m", "fha_studio", "drive", *args, "--url", path],
                                  cwd=ROOT, env=env, capture_output=True, text=True, timeout=60)

        done = fha("probe", "--json")
        assert done.returncode == 0, done.stderr
        assert '"documented_only": true' in done.stdout and '"servo": "off"' in done.stdout
        sim.stdin.write(b"servo on\n")
        sim.stdin.flush()
        said_by(sim, b"servo on (CN2)")
        done = fha("position", "--actuator", "FHA-25C-50-S248")
        assert done.returncode == 4 and "servo on (controller)" in done.stderr
        with pytest.raises(ServoOnRefused), DriveClient.open(path) as client:
            client.absolute_position()
    assert sim.returncode == 0


def test_the_tests_drive_of_the_manual_answers_as_this_profile_does(make_drive):
    """tests/support's DocumentedDrive (no axis behind it) and this profile give the same answer
    to every command, with the servo off and on; a reply that comes later is "later"."""
    from fha_studio.hardware.protocol import decode_request
    from tests.support.documented import DocumentedDrive

    drive = make_drive("FHA-25C-50-S248", profile="documented")
    stand_in = DocumentedDrive()
    commands = ["DGR", "OWW", "OWW", *sorted(EXTENSION_COMMANDS), "ZZZ"]
    for servo_on in (False, True):
        drive.set_servo(servo_on)
        stand_in.servo_on = servo_on
        for command in commands:
            _, request = decode_request(f"{command}+00000\r".encode())
            ours, its = responder(drive).respond(request), stand_in.answer(request, 0.0)
            answers = (ours.terminal if ours else "later", its.status if its else "later")
            assert answers[0] == answers[1], (command, f"servo {'on' if servo_on else 'off'}", answers)
