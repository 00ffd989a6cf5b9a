"""`fha-studio discrepancy` end to end: a recording file in, the summary, the JSON report and the
updated model file out; the model file loads and re-simulates; user mistakes are one-line errors."""

from __future__ import annotations

import json

import numpy as np
import pytest
from modelcheck_gen import moves_for, record, trapezoid_moves

from fha_studio.cli import main
from fha_studio.logic.modelcheck import run_modelcheck
from fha_studio.physics import AxisModel, Effects, simulate
from fha_studio.recording import read_recording, write_recording

CODE = "FHA-25C-50-US250"


@pytest.fixture(scope="module")
def recording_file(tmp_path_factory):
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    t, cmd = trapezoid_moves(moves_for(model, n_moves=5), 1000.0)
    effects = Effects().with_effect("coulomb_friction", torque_nm=6.0)
    path = tmp_path_factory.mktemp("rec") / "axis.csv"
    write_recording(path, record(model, effects, t, cmd, actuator_code=CODE).recording)
    return path


def test_cli_prints_the_finding_and_writes_report_and_model(recording_file, tmp_path, capsys):
    report, model_out = tmp_path / "report.json", tmp_path / "model.toml"
    code = main(["discrepancy", str(recording_file), "--json", str(report), "--model-out", str(model_out)])
    out = capsys.readouterr().out
    assert code == 0
    assert "Coulomb friction missing: " in out and "torque gap" in out and "held-out" in out
    data = json.loads(report.read_text())
    (effect,) = data["effects"]
    assert effect["id"] == "coulomb_friction" and effect["channel"] == "torque"
    assert effect["params"]["torque_nm"] == pytest.approx(6.0, rel=0.1)
    gap = data["gap"]["torque"]
    assert gap["unit"] == "N m" and gap["rms_after"] < 0.5 * gap["rms_before"]
    assert "position" not in data["gap"]  # no load_pos in this recording
    # the updated model: the sim and later checks load it
    model = AxisModel.load(model_out)
    assert model.effects.enabled() == ["coulomb_friction"]
    assert model.effects.coulomb_friction.torque_nm == pytest.approx(6.0, rel=0.1)
    assert model.load_inertia_kgm2 == 1.5 and model.actuator_code == CODE


def test_resimulation_with_the_updated_model_closes_the_gap(recording_file):
    rec = read_recording(recording_file)
    result = run_modelcheck(rec)
    r = result.resimulation
    assert r is not None
    n = len(r.t_s)
    for arr in (
        r.torque_measured_nm,
        r.torque_nominal_nm,
        r.torque_updated_nm,
        r.pos_measured_deg,
        r.pos_nominal_deg,
        r.pos_updated_deg,
    ):
        assert arr.shape == (n,) and np.all(np.isfinite(arr))
    assert r.rms_updated_nm < 0.8 * r.rms_nominal_nm
    # the written model re-simulates the same way
    again = simulate(result.updated_model, None, rec.t_s, np.radians(rec.cmd_pos_deg))
    assert np.all(np.isfinite(again["current"]))


def test_user_mistakes_are_one_line_errors(recording_file, tmp_path, capsys):
    garbage = tmp_path / "garbage.csv"
    text = recording_file.read_text().splitlines()
    header = next(i for i, line in enumerate(text) if not line.startswith("#"))
    text[header + 5] = "0.005,abc,1.0,0.0"
    garbage.write_text("\n".join(text) + "\n")
    assert main(["discrepancy", str(garbage)]) == 2
    err = capsys.readouterr().err
    assert f"line {header + 6}" in err and "'pos'" in err and err.count("\n") == 1

    wrong = tmp_path / "wrong.csv"
    wrong.write_text(recording_file.read_text().replace(CODE, "FHA-25C-50-S248", 1))
    assert main(["discrepancy", str(wrong)]) == 2
    err = capsys.readouterr().err
    assert "wrong actuator declared" in err and err.count("\n") == 1

    assert main(["discrepancy", str(tmp_path / "missing.csv")]) == 2
    assert main(["discrepancy", str(recording_file), "--window", "5"]) == 2
