"""``fha-studio size``: the JSON contract, the readable table, and one-line errors (exit 2)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from fha_studio.cli import main

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = [
    "size", "--actuator", "FHA-25C-50-US250", "--load-inertia", "1.5", "--speed", "60", "--angle", "120",
    "--cycle", "2", "--duty-factors", "7,1,7",
]  # fmt: skip


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def check_examples_json(data):
    assert round(data["accel_time_s"], 3) == 0.097
    assert round(data["decel_time_s"], 3) == 0.085
    assert data["friction_torque_nm"] == pytest.approx(10.6)
    assert abs(data["run_time_s"] - 0.242) <= 0.001
    assert round(data["percent_ed"]) == 76
    assert round(data["effective_torque_nm"]) == 45
    assert abs(data["min_cycle_time_s"] - 3.34) <= 0.01
    assert data["average_speed_rpm"] == pytest.approx(10.0)
    for check in data["checks"]:
        assert {"name", "value", "limit", "ok", "section"} <= set(check)
    by_name = {c["name"]: c for c in data["checks"]}
    assert by_name["effective torque"]["ok"] is False
    assert by_name["effective torque"]["limit"] == 35
    assert by_name["effective torque"]["section"] == "2-4-6"
    assert by_name["%ED"]["ok"] is True


def test_json_reproduces_examples_1_to_3(capsys):
    rc, out, err = run(capsys, *EXAMPLE, "--json")
    assert rc == 0 and err == ""
    check_examples_json(json.loads(out))


def test_json_through_the_module_entry_point():
    proc = subprocess.run(
        [sys.executable, "-m", "fha_studio", *EXAMPLE, "--json"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 0, proc.stderr
    check_examples_json(json.loads(proc.stdout))


def test_percent_ed_only_with_duty_factors(capsys):
    rc, out, _ = run(capsys, *EXAMPLE[:-2], "--json")
    data = json.loads(out)
    assert rc == 0 and "percent_ed" not in data
    assert "%ED" not in {c["name"] for c in data["checks"]}


def test_table(capsys):
    rc, out, _ = run(capsys, *EXAMPLE)
    assert rc == 0
    lines = out.splitlines()
    assert any(line.split()[:2] == ["effective", "torque"] and line.endswith("FAIL") for line in lines)
    assert any(line.split()[:1] == ["%ED"] and line.endswith("PASS") for line in lines)
    assert "FAIL: 2 of 10 checks fail" in out


def test_strict_exit_status(capsys):
    assert run(capsys, *EXAMPLE, "--strict")[0] == 1
    longer = [a if a != "2" else "3.4" for a in EXAMPLE]  # the manual's longer cycle passes
    assert run(capsys, *longer, "--strict")[0] == 0


def test_bearing_options(capsys):
    rc, out, _ = run(
        capsys, *EXAMPLE, "--radial-load-n", "1000", "--axial-load-n", "2000", "--radial-offset-mm", "50",
        "--axial-offset-mm", "30", "--required-life-h", "20000", "--use", "precise", "--json",
    )  # fmt: skip
    data = json.loads(out)
    assert rc == 0
    assert data["bearing"]["max_moment_nm"] == pytest.approx(128)
    by_name = {c["name"]: c for c in data["checks"]}
    assert by_name["static safety factor"]["limit"] == 3.0
    assert by_name["bearing life L10"]["ok"] is True


def test_sway_flag_checks_fretting(capsys):
    argv = [a if a != "120" else "4" for a in EXAMPLE]
    _, out, _ = run(capsys, *argv, "--radial-load-n", "1000", "--sway", "--json")
    by_name = {c["name"]: c for c in json.loads(out)["checks"]}
    assert by_name["sway angle (fretting)"]["ok"] is False


def test_suggest(capsys):
    rc, out, _ = run(
        capsys,
        "size",
        "--suggest",
        "--load-inertia",
        "0.2",
        "--speed",
        "20",
        "--angle",
        "90",
        "--cycle",
        "5",
        "--json",
    )
    data = json.loads(out)
    assert rc == 0 and data and all(r["ok"] for r in data)
    assert data[0]["actuator"] == "FHA-17C-50-US250"


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"--load-inertia": "-1"}, "--load-inertia: -1 is outside 0 ... 1500 kg m^2"),
        ({"--load-inertia": "heavy"}, "--load-inertia: 'heavy' is not a number"),
        ({"--actuator": "FHA-26C-50-US250"}, "unknown actuator 'FHA-26C-50-US250'"),
        ({"--actuator": "FHA-25C-60-US250"}, "unknown actuator"),
        ({"--speed": "91"}, "above the maximum speed of FHA-25C-50-US250 (90 r/min)"),
        ({"--duty-factors": "7,1"}, "--duty-factors"),
        ({"--duty-factors": "7;1;7"}, "--duty-factors"),
        ({"--cycle": "0"}, "--cycle: 0 is outside 0.001 ... 86400 s"),
        ({"--angle": "inf"}, "--angle"),
    ],
)
def test_bad_arguments_exit_2_with_one_line(capsys, change, message):
    argv = list(EXAMPLE)
    for option, value in change.items():
        argv[argv.index(option) + 1] = value
    rc, out, err = run(capsys, *argv)
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1
    assert message in err and "Traceback" not in err


def test_missing_actuator_and_stray_bearing_options(capsys):
    rc, _, err = run(capsys, "size", "--load-inertia", "1", "--speed", "10", "--angle", "90", "--cycle", "2")
    assert rc == 2 and "--actuator is required" in err
    rc, _, err = run(capsys, *EXAMPLE, "--radial-offset-mm", "5")
    assert rc == 2 and "need --radial-load-n or --axial-load-n" in err


def test_accel_time_sizes_for_the_machines_move(capsys):
    rc, out, _ = run(capsys, *EXAMPLE, "--accel-time", "0.3", "--json")
    data = json.loads(out)
    assert rc == 0 and data["accel_time_s"] == data["decel_time_s"] == 0.3
    assert "in the given 0.3 s" in data["assumption"]
    assert any(c["name"] == "acceleration torque" for c in data["checks"])
    rc, out, err = run(capsys, *EXAMPLE, "--accel-time", "0")
    assert rc == 2 and out == ""
    assert err.strip() == ("fha-studio size: error: --accel-time: 0 is outside more than 0 and at most "
                           "3600 s (an hour to reach the speed; a longer time is a unit mistake (ms for s))")
