"""``fha-studio sim``: user mistakes, and serving over TCP with a recording."""

from __future__ import annotations

import time

import pytest
import serial

from fha_studio.cli import main as cli_main
from fha_studio.recording import read_recording
from tests.support.processes import Child


def test_bad_actuator_is_one_line_and_exit_2(capsys, tmp_path):
    status = cli_main(["sim", "--pty", "--actuator", "FHA-99C-50-US250",
                       "--eeprom", str(tmp_path / "e.json")])
    err = capsys.readouterr().err
    assert status == 2
    assert err.count("\n") == 1 and "fha-studio sim: error:" in err and "frame" in err


def test_bad_effect_is_one_line_and_exit_2(capsys, tmp_path):
    status = cli_main(["sim", "--tcp", "0", "--effect", "coulomb_friction:torque_nm",
                       "--eeprom", str(tmp_path / "e.json")])
    assert status == 2
    assert "NAME=VALUE" in capsys.readouterr().err


def test_corrupt_eeprom_is_named(capsys, tmp_path):
    path = tmp_path / "bad.json"
    path.write_text("not json", encoding="utf-8")
    assert cli_main(["sim", "--pty", "--eeprom", str(path)]) == 2
    assert str(path) in capsys.readouterr().err


@pytest.mark.e2e
def test_serves_tcp_and_records(tmp_path):
    record = tmp_path / "run.csv"
    with Child.sim(tmp_path / "e.json", "--tcp", "0", "--actuator", "FHA-17C-50-US250",
                   "--record", str(record)) as sim:
        assert sim.address.startswith("socket://127.0.0.1:")
        with serial.serial_for_url(sim.address, timeout=2.0) as port:
            port.write(b"IDN+00000\r")
            assert port.read_until(b"q\r").startswith(b"HA-655-2-200\rFHA-17C-50-US250\r")
            port.write(b"SVO+00001\rJOG+01000\r")
            assert port.read(4) == b"q\rq\r"
    assert sim.returncode == 0
    recording = read_recording(record)
    assert recording.metadata.actuator == "FHA-17C-50-US250"
    assert len(recording) > 10 and recording.metadata.sample_rate_hz == 1000


@pytest.mark.e2e
@pytest.mark.parametrize(("flags", "encoding"), [((), "packed"), (("--text-trace",), "text")])
def test_a_sim_in_another_process_offers_packed_trace_blocks_unless_told_not_to(tmp_path, flags, encoding):
    """The client reads a trace from a drive with packed blocks (TRP in CAP) and from one
    without (an older drive: TRB only), over TCP from another process, with the same values."""
    from fha_studio.hardware import protocol as p
    from fha_studio.hardware.client import DriveClient

    with Child.sim(tmp_path / "e.json", "--tcp", "0", *flags) as sim, DriveClient.open(sim.address) as client:
        assert client.trace_encoding == encoding
        assert ("TRP" in {c.value for c in client.capabilities.commands}) == (encoding == "packed")
        client.servo(True)
        client.jog(20.0)
        client.configure_trace([100, 103], divider=5)
        client.arm_trace(200)
        deadline = time.monotonic() + 20
        while client.trace_status().state is not p.TraceState.DONE:
            assert time.monotonic() < deadline, "the capture did not finish"
            client.jog(20.0)  # held: JOG again on every look at the capture
        seen = []
        capture = client.read_trace(progress=lambda done, total: seen.append((done, total)))
    assert len(capture.samples) == 200 and seen[0] == (0, 200) and seen[-1] == (200, 200)
    positions = capture.column(100)
    assert positions[-1] > positions[0] and positions == sorted(positions)
