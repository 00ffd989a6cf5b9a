"""``fha-studio catalog MODEL-CODE [--json]``, in-process and once as a subprocess."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from fha_studio.cli import main

ROOT = Path(__file__).resolve().parents[2]
CONTRACT_KEYS = {
    "max_torque_nm",
    "max_speed_rpm",
    "torque_constant_nm_per_a",
    "max_current_a",
    "inertia_kgm2",
    "ratio",
    "output_resolution_ppr",
    "continuous_torque_nm",
    "continuous_speed_rpm",
    "allowable_inertia_kgm2",
    "stiffness",
    "model_code",
    "frame",
    "encoder",
    "supply_voltage",
    "friction_torque_nm",
    "brake",
    "bearing",
    "compatible_drivers",
    "notes",
}


def test_json_has_the_contract_keys_in_si(capsys):
    assert main(["catalog", "FHA-25C-50-US250", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d.keys() >= CONTRACT_KEYS
    assert set(d["stiffness"]) >= {"t1_nm", "t2_nm", "k1_nm_per_rad", "k2_nm_per_rad", "k3_nm_per_rad"}
    assert (d["max_torque_nm"], d["ratio"], d["friction_torque_nm"], d["inertia_kgm2"]) == (
        150,
        50,
        10.6,
        0.81,
    )
    assert d["output_resolution_ppr"] == 500_000
    assert d["continuous_torque_nm"] == 35 and d["allowable_inertia_kgm2"] == 2.4
    assert d["stiffness"]["k1_nm_per_rad"] == 4.7e4
    assert d["brake"] is None
    assert d["compatible_drivers"] == ["HA-655-2-200", "HA-675-2-200"]


def test_table_output_is_readable(capsys):
    assert main(["catalog", "fha-32c-100-s248-b"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("FHA-32C-100-S248-B  (absolute, 200 V)")
    assert "holding_torque_nm" in out and "k1_nm_per_rad" in out and "notes" in out


def test_bad_code_is_one_line_exit_2(capsys):
    assert main(["catalog", "FHA-40C-50-US250-A"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1
    assert "option A" in lines[0] and "FHA-17C, FHA-25C, FHA-32C only" in lines[0]


def test_subprocess_json_and_error():
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    ok = subprocess.run(
        [sys.executable, "-m", "fha_studio", "catalog", "FHA-17C-160-S248-A", "--json"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert ok.returncode == 0, ok.stderr
    d = json.loads(ok.stdout)
    assert (d["supply_voltage"], d["max_speed_rpm"], d["output_resolution_ppr"]) == (100, 27, 1_310_720)
    bad = subprocess.run(
        [sys.executable, "-m", "fha_studio", "catalog", "FHA-25C-60-US250"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert bad.returncode == 2
    assert "Traceback" not in bad.stderr
    assert bad.stderr.strip().count("\n") == 0 and "ratio '60'" in bad.stderr
