"""The ``fha-studio drive`` contract, against a line in another process over a pty.

The far end (``line_server.py``) is a drive that answers only the manual's DGR and OWW, or a line
that is silent, floods, trickles or answers garbage. The CLI runs as its own process too, as a
script would run it; its wall time is part of the contract (exit 3 within 5 s).
"""

from __future__ import annotations

import json
import os
import re
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fha_studio.cli import drive as drive_cli
from fha_studio.main import main as entry
from tests.support.processes import Child

pytestmark = pytest.mark.e2e

ROOT = Path(__file__).resolve().parents[2]
SERVER = Path(__file__).with_name("line_server.py")
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
ACTUATOR = "FHA-25C-50-S248"  # ratio 50, absolute encoder
POSITION = 3 * 8192 + 1234


@pytest.fixture
def line(children):
    """Factory: line(MODE, *options) -> line_server.py in its own process, its pty at ``address``
    (stopped after the test)."""

    def start(*args: str) -> Child:
        server = children(Child.python, SERVER, *args)
        server.address = server.first_line("the line server", expect="/dev/")
        return server

    return start


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
    code, out, err, _ = fha("drive", "probe", "--url", server.address, "--actuator", ACTUATOR, "--json")
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
    code, out, err, _ = fha("drive", "probe", "--url", server.address, "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["position_counts"] == POSITION and data["position_deg"] is None
    code, out, _, _ = fha("drive", "probe", "--url", server.address)
    assert code == 0
    assert "only the manual's DGR and OWW" in out and "front panel" in out
    assert f"{POSITION} counts (multi-turn 3, single-turn 1234)" in out


def test_probe_servo_on_and_incremental(line):
    on = line("documented", "--servo-on")
    code, out, err, _ = fha("drive", "probe", "--url", on.address, "--actuator", ACTUATOR, "--json")
    assert code == 0, err
    data = json.loads(out)
    assert (data["servo"], data["encoder"], data["position_counts"], data["position_deg"]) == (
        "on", "unknown", None, None)
    assert data["documented_only"] is True and data["parameter_access"] is False
    inc = line("documented", "--incremental")
    code, out, err, _ = fha("drive", "probe", "--url", inc.address, "--json")
    assert code == 0, err
    data = json.loads(out)
    assert (data["servo"], data["encoder"], data["position_counts"]) == ("off", "incremental", None)


#: what ``drive probe`` promises on a line that never answers usefully
PROMISE_S = 5.0


def taken_s(err: str) -> float:
    """The time the command says it took, from its own start (Python's start-up counted) to where
    it gave up: the figure the 5 s promise is about, which a loaded machine cannot stretch in the
    test's own measurement (the test's wall time includes its own waiting for the child)."""
    found = re.search(r" in (\d+\.\d) s\b", err)
    assert found, err
    return float(found.group(1))


@pytest.mark.parametrize("mode", ["silent", "flood", "slow", "garbage"])
def test_probe_exits_3_within_5_s_whatever_the_line_does(line, mode, time_ceiling):
    server = line(mode)
    code, out, err, elapsed = fha("drive", "probe", "--url", server.address, "--json")
    assert code == 3, (out, err)
    assert out == ""
    one_line(err)
    # one deadline for the whole probe, from the process's start: 4.0 s, the rest of 4.5 s is
    # closing and exiting; attempts and retries each with their own timeouts came to 5.2-5.4 s.
    # The figure is held to the 5 s promise: on a machine loaded well past its cores the
    # process is woken some tenths after its deadline (4.4 s seen at a load of 7.5 on 2 cores)
    assert drive_cli.CONNECT_S < drive_cli.PROBE_S < PROMISE_S
    assert taken_s(err) <= PROMISE_S, err
    time_ceiling(f"drive probe on a {mode} line", elapsed, 30.0)
    if mode == "silent":
        assert "nothing arrived" in err
    else:
        assert "bytes arrived" in err and "but no usable reply" in err


@pytest.fixture
def listener():
    """A TCP listener that never accepts: the kernel completes the first connection into the
    backlog (then nothing is ever read or written); with ``full=True`` the backlog is taken by a
    connection of the test's own, so a probe's connect is never answered (SYNs dropped)."""
    opened: list[socket.socket] = []

    def start(full: bool) -> str:
        server = socket.socket()
        server.bind(("127.0.0.1", 0))
        server.listen(0)
        opened.append(server)
        port = server.getsockname()[1]
        if full:
            filler = socket.create_connection(("127.0.0.1", port), timeout=5)
            opened.append(filler)
            probe = socket.socket()
            probe.settimeout(0.3)
            opened.append(probe)
            try:  # does the backlog refuse a second one? (it does on Linux with listen(0))
                probe.connect(("127.0.0.1", port))
                pytest.skip("this system's listen(0) backlog took a second connection")
            except TimeoutError:
                pass
        return f"socket://127.0.0.1:{port}"

    yield start
    for one in opened:
        one.close()


@pytest.mark.parametrize("full", [False, True], ids=["connected-silent", "connect-unanswered"])
def test_probe_on_a_listener_that_never_accepts_ends_within_5_s(listener, full, time_ceiling):
    url = listener(full)
    code, out, err, elapsed = fha("drive", "probe", "--url", url, "--json")
    assert code == 3 and out == "", (out, err)
    one_line(err)
    assert taken_s(err) <= PROMISE_S, err  # the process gives up at 4.0 s, woken late under load
    time_ceiling("drive probe on a listener that never accepts", elapsed, 30.0)
    if full:
        assert "nothing accepted the connection" in err
    else:
        assert "nothing arrived" in err


def test_probe_on_a_missing_port_is_exit_3(tmp_path, time_ceiling):
    code, _, err, elapsed = fha("drive", "probe", "--url", str(tmp_path / "ttyNOPE"))
    assert code == 3 and "ttyNOPE" in one_line(err)
    time_ceiling("drive probe on a missing port", elapsed, 30.0)


def test_position_servo_off_servo_on_incremental(line):
    server = line("documented")
    code, out, err, _ = fha("drive", "position", "--url", server.address, "--actuator", ACTUATOR, "--json")
    assert code == 0, err
    assert json.loads(out) == {"position_counts": POSITION,
                               "position_deg": pytest.approx(POSITION * 360 / (8192 * 50))}
    on = line("documented", "--servo-on")
    code, out, err, _ = fha("drive", "position", "--url", on.address, "--actuator", ACTUATOR)
    assert code == 4 and out == ""
    assert "servo on (controller)" in one_line(err)
    inc = line("documented", "--incremental")
    code, out, err, _ = fha("drive", "position", "--url", inc.address, "--actuator", ACTUATOR)
    assert code == 4 and "incremental" in one_line(err)


def test_position_needs_an_actuator_and_a_valid_code(line):
    server = line("documented")
    code, _, err, _ = fha("drive", "position", "--url", server.address)
    assert code == 2 and "--actuator" in err
    code, _, err, _ = fha("drive", "position", "--url", server.address, "--actuator", "FHA-99C-50-S248")
    assert code == 2 and "--actuator FHA-99C-50-S248" in one_line(err)


def test_origin_clears_the_multi_turn_data_and_reads_back(line):
    server = line("documented", "--oww-s", "1.0")
    code, out, err, elapsed = fha("drive", "origin", "--url", server.address, "--actuator", ACTUATOR,
                                  "--yes", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["before_counts"] == POSITION
    assert data["position_counts"] == 1234  # multi-turn 0, single-turn unchanged
    assert data["position_deg"] == pytest.approx(1234 * 360 / (8192 * 50))
    assert data["oww_s"] >= 0.9 and elapsed >= 1.0
    # the drive now says turn 0
    code, out, _, _ = fha("drive", "position", "--url", server.address, "--actuator", ACTUATOR, "--json")
    assert json.loads(out)["position_counts"] == 1234


def test_origin_with_a_5_s_acknowledgement_as_the_manual_says(line):
    server = line("documented", "--oww-s", "5.0")
    code, out, err, _ = fha("drive", "origin", "--url", server.address, "--actuator", ACTUATOR, "--yes")
    assert code == 0, err
    assert "position read back: 1234 counts (multi-turn 0, single-turn 1234)" in out


def test_origin_refuses_servo_on_and_incremental_and_asks_without_yes(line):
    on = line("documented", "--servo-on")
    code, out, err, _ = fha("drive", "origin", "--url", on.address, "--actuator", ACTUATOR, "--yes")
    assert code == 4 and "servo on" in one_line(err) and out == ""
    inc = line("documented", "--incremental")
    code, out, err, _ = fha("drive", "origin", "--url", inc.address, "--actuator", ACTUATOR, "--yes")
    assert code == 4 and "incremental" in one_line(err)
    server = line("documented")
    code, _, err, _ = fha("drive", "origin", "--url", server.address, "--actuator", ACTUATOR)
    assert code == 2 and "--yes" in one_line(err)
    code, out, _, _ = fha("drive", "position", "--url", server.address, "--actuator", ACTUATOR, "--json")
    assert json.loads(out)["position_counts"] == POSITION  # nothing was cleared


@pytest.mark.parametrize("action", [["read"], ["write", "rotary_direction=1"], ["backup", "--out", "x.toml"],
                                    ["restore", "x.toml"]])
def test_params_on_a_documented_only_drive_say_front_panel(line, action, tmp_path):
    server = line("documented")
    args = [a.replace("x.toml", str(tmp_path / "x.toml")) for a in action]
    code, out, err, _ = fha("drive", "params", args[0], "--url", server.address, *args[1:])
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
