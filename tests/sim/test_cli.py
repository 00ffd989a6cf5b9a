"""``fha-studio sim``: user mistakes, and serving over TCP with a recording."""

from __future__ import annotations

import os
import select
import subprocess
import sys
from pathlib import Path

import pytest
import serial

from fha_studio.cli import main as cli_main
from fha_studio.recording import read_recording

ROOT = Path(__file__).resolve().parents[2]


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
    cmd = [sys.executable, "-m", "fha_studio", "sim", "--tcp", "0", "--unpaced", "--actuator",
           "FHA-17C-50-US250", "--eeprom", str(tmp_path / "e.json"), "--record", str(record)]
    proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            env={**os.environ, "PYTHONPATH": str(ROOT)})
    try:
        ready, _, _ = select.select([proc.stdout], [], [], 30.0)
        assert ready, "no address printed"
        address = proc.stdout.readline().decode().strip()
        assert address.startswith("socket://127.0.0.1:")
        with serial.serial_for_url(address, timeout=2.0) as port:
            port.write(b"IDN+00000\r")
            assert port.read_until(b"q\r").startswith(b"HA-655-2-200\rFHA-17C-50-US250\r")
            port.write(b"SVO+00001\rJOG+01000\r")
            assert port.read(4) == b"q\rq\r"
    finally:
        proc.terminate()
        proc.wait(10)
        proc.stdout.close()
        proc.stderr.close()
    assert proc.returncode == 0
    recording = read_recording(record)
    assert recording.metadata.actuator == "FHA-17C-50-US250"
    assert len(recording) > 10 and recording.metadata.sample_rate_hz == 1000
