"""The ``fha-studio drive`` contract, against a line in another process over a pty.

The far end (``line_server.py``) is a drive that answers only the manual's DGR and OWW, or a line
that is silent, floods, trickles or answers garbage. The CLI runs as its own process too, as a
script would run it; its wall time is part of the contract (exit 3 within 5 s).
"""

from __future__ import annotations

import json
import os
import re
import select
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fha_studio.main import main as entry

pytestmark = pytest.mark.e2e

ROOT = Path(__file__).resolve().parents[2]
SERVER = Path(__file__).with_name("line_server.py")
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
ACTUATOR = "FHA-25C-50-S248"  # ratio 50, absolute encoder
POSITION = 3 * 8192 + 1234


class Line:
    def __init__(self, *args: str):
        self.proc = subprocess.Popen([sys.executable, str(SERVER), *args], cwd=ROOT, env=ENV,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        assert self.proc.stdout is not None
        ready, _, _ = select.select([self.proc.stdout], [], [], 30.0)
        if not ready:
            self.close()
            pytest.fail("the line server printed no pty path within 30 s")
        self.path = self.proc.stdout.readline().decode().strip()
        assert self.path.startswith("/dev/"), self.path

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(5)
        for stream in (self.proc.stdout, self.proc.stderr):
            if stream is not None:
                stream.close()


@pytest.fixture
def line(request):
    lines: list[Line] = []

    def start(*args: str) -> Line:
        lines.append(Line(*args))
        return lines[-1]

    yield start
    for one in lines:
        one.close()


def fha(*args: str, timeout: float = 30.0) -> tuple[int, str, str, float]:
    started = time.monotonic()
    done = subprocess.run([sys.executable, "-m", "fha_studio", *args], cwd=ROOT, env=ENV,
                          capture_output=True, text=True, timeout=timeout)
    return done.returncode, done.stdout, done.stderr, time.monotonic() - started


def one_line(err: str) -> str:
    assert err.count("\n") == 1, err
    assert "Traceback" not in err
    return err


def test_probe_documented_only_drive_servo_off(line):
    server = line("documented")
    code, out, err, _ = fha("drive", "probe", "--url", server.path, "--actuator", ACTUATOR, "--json")
    assert code == 0, err
    data = json.loads(out)
    assert list(data) == ["link", "driver", "parameter_access", "documented_only", "servo", "encoder",
                          "position_counts", "position_deg"]
    assert data == {
        "link": "ok", "driver": None, "parameter_access": False, "documented_only": True,
        "servo": "off", "encoder": "absolute", "position_counts": POSITION,
        "position_deg": pytest.approx(POSITION * 360 / (8192 * 50)),
    }


def test_probe_without_actuator_has_no_angle_and_reads_as_text(line):
    server = line("documented")
    code, out, err, _ = fha("drive", "probe", "--url", server.path, "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["position_counts"] == POSITION and data["position_deg"] is None
    code, out, _, _ = fha("drive", "probe", "--url", server.path)
    assert code == 0
    assert "only the manual's DGR and OWW" in out and "front panel" in out
    assert f"{POSITION} counts (multi-turn 3, single-turn 1234)" in out


def test_probe_servo_on_and_incremental(line):
    on = line("documented", "--servo-on")
    code, out, err, _ = fha("drive", "probe", "--url", on.path, "--actuator", ACTUATOR, "--json")
    assert code == 0, err
    data = json.loads(out)
    assert (data["servo"], data["encoder"], data["position_counts"], data["position_deg"]) == (
        "on", "unknown", None, None)
    assert data["documented_only"] is True and data["parameter_access"] is False
    inc = line("documented", "--incremental")
    code, out, err, _ = fha("drive", "probe", "--url", inc.path, "--json")
    assert code == 0, err
    data = json.loads(out)
    assert (data["servo"], data["encoder"], data["position_counts"]) == ("off", "incremental", None)


@pytest.mark.parametrize("mode", ["silent", "flood", "slow", "garbage"])
def test_probe_exits_3_within_5_s_whatever_the_line_does(line, mode):
    server = line(mode)
    code, out, err, elapsed = fha("drive", "probe", "--url", server.path, "--json")
    assert code == 3, (out, err)
    assert out == ""
    one_line(err)
    assert elapsed < 5.0, f"{mode}: {elapsed:.2f} s"
    if mode == "silent":
        assert "nothing arrived" in err
    else:
        assert "bytes arrived but no usable reply" in err


def test_probe_on_a_missing_port_is_exit_3(tmp_path):
    code, _, err, elapsed = fha("drive", "probe", "--url", str(tmp_path / "ttyNOPE"))
    assert code == 3 and "ttyNOPE" in one_line(err) and elapsed < 5.0


def test_position_servo_off_servo_on_incremental(line):
    server = line("documented")
    code, out, err, _ = fha("drive", "position", "--url", server.path, "--actuator", ACTUATOR, "--json")
    assert code == 0, err
    assert json.loads(out) == {"position_counts": POSITION,
                               "position_deg": pytest.approx(POSITION * 360 / (8192 * 50))}
    on = line("documented", "--servo-on")
    code, out, err, _ = fha("drive", "position", "--url", on.path, "--actuator", ACTUATOR)
    assert code == 4 and out == ""
    assert "servo on (controller)" in one_line(err)
    inc = line("documented", "--incremental")
    code, out, err, _ = fha("drive", "position", "--url", inc.path, "--actuator", ACTUATOR)
    assert code == 4 and "incremental" in one_line(err)


def test_position_needs_an_actuator_and_a_valid_code(line):
    server = line("documented")
    code, _, err, _ = fha("drive", "position", "--url", server.path)
    assert code == 2 and "--actuator" in err
    code, _, err, _ = fha("drive", "position", "--url", server.path, "--actuator", "FHA-99C-50-S248")
    assert code == 2 and "--actuator FHA-99C-50-S248" in one_line(err)


def test_origin_clears_the_multi_turn_data_and_reads_back(line):
    server = line("documented", "--oww-s", "1.0")
    code, out, err, elapsed = fha("drive", "origin", "--url", server.path, "--actuator", ACTUATOR,
                                  "--yes", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["before_counts"] == POSITION
    assert data["position_counts"] == 1234  # multi-turn 0, single-turn unchanged
    assert data["position_deg"] == pytest.approx(1234 * 360 / (8192 * 50))
    assert data["oww_s"] >= 0.9 and elapsed >= 1.0
    # the drive now says turn 0
    code, out, _, _ = fha("drive", "position", "--url", server.path, "--actuator", ACTUATOR, "--json")
    assert json.loads(out)["position_counts"] == 1234


def test_origin_with_a_5_s_acknowledgement_as_the_manual_says(line):
    server = line("documented", "--oww-s", "5.0")
    code, out, err, _ = fha("drive", "origin", "--url", server.path, "--actuator", ACTUATOR, "--yes")
    assert code == 0, err
    assert "position read back: 1234 counts (multi-turn 0, single-turn 1234)" in out


def test_origin_refuses_servo_on_and_incremental_and_asks_without_yes(line):
    on = line("documented", "--servo-on")
    code, out, err, _ = fha("drive", "origin", "--url", on.path, "--actuator", ACTUATOR, "--yes")
    assert code == 4 and "servo on" in one_line(err) and out == ""
    inc = line("documented", "--incremental")
    code, out, err, _ = fha("drive", "origin", "--url", inc.path, "--actuator", ACTUATOR, "--yes")
    assert code == 4 and "incremental" in one_line(err)
    server = line("documented")
    code, _, err, _ = fha("drive", "origin", "--url", server.path, "--actuator", ACTUATOR)
    assert code == 2 and "--yes" in one_line(err)
    code, out, _, _ = fha("drive", "position", "--url", server.path, "--actuator", ACTUATOR, "--json")
    assert json.loads(out)["position_counts"] == POSITION  # nothing was cleared


@pytest.mark.parametrize("action", [["read"], ["write", "rotary_direction=1"], ["backup", "--out", "x.toml"],
                                    ["restore", "x.toml"]])
def test_params_on_a_documented_only_drive_say_front_panel(line, action, tmp_path):
    server = line("documented")
    args = [a.replace("x.toml", str(tmp_path / "x.toml")) for a in action]
    code, out, err, _ = fha("drive", "params", args[0], "--url", server.path, *args[1:])
    assert code == 4 and out == ""
    assert "front panel" in one_line(err)
    assert not (tmp_path / "x.toml").exists()


def test_params_on_the_full_simulated_drive(tmp_path):
    url = f"sim://FHA-25C-50-US250?eeprom={tmp_path / 'eeprom.json'}&paced=0"
    backup = tmp_path / "backup.toml"
    code, out, err, _ = fha("drive", "params", "backup", "--url", url, "--out", str(backup))
    assert code == 0, err
    assert re.search(r"^rotary_direction +\= 0 ", backup.read_text(), re.M)
    # another process: a fresh embedded drive on the same EEPROM file
    code, out, err, _ = fha("drive", "params", "write", "--url", url, "rotary_direction=1")
    assert code == 0 and "parameter 8, rotary direction" in out, err
    code, out, err, _ = fha("drive", "params", "read", "--url", url, "--json")
    rows = {(r["mode"], r["number"]): r for r in json.loads(out)}
    assert rows[("system", 8)]["value"] == 1
    code, out, err, _ = fha("drive", "params", "restore", "--url", url, str(backup))
    assert code == 0 and "parameter 8, rotary direction" in out, err
    code, out, err, _ = fha("drive", "params", "read", "--url", url, "--json")
    assert {(r["mode"], r["number"]): r for r in json.loads(out)}[("system", 8)]["value"] == 0
    code, _, err, _ = fha("drive", "params", "write", "--url", url, "rotary_direction=7")
    assert code == 2 and "parameter 8, rotary direction" in one_line(err)


def test_help_lists_gui_and_options_start_the_gui(monkeypatch, capsys):
    with pytest.raises(SystemExit):
        entry(["--help"])
    assert "    gui " in capsys.readouterr().out
    import fha_studio.gui.app as app

    seen: list[list[str]] = []
    monkeypatch.setattr(app, "run", lambda argv: seen.append(list(argv)) or 0)
    assert entry(["--url", "/dev/ttyUSB0"]) == 0
    assert entry(["gui", "--url", "/dev/ttyUSB0"]) == 0
    assert seen == [["--url", "/dev/ttyUSB0"], ["--url", "/dev/ttyUSB0"]]


def test_fha_studio_url_starts_the_gui_in_a_process(tmp_path):
    url = f"sim://FHA-25C-50-US250?eeprom={tmp_path / 'eeprom.json'}&paced=0"
    env = {**ENV, "QT_QPA_PLATFORM": "offscreen", "XDG_CONFIG_HOME": str(tmp_path),
           "XDG_DATA_HOME": str(tmp_path)}
    done = subprocess.run([sys.executable, "-m", "fha_studio", "--url", url, "--quit-after-ms", "1500"],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "invalid choice" not in done.stderr
