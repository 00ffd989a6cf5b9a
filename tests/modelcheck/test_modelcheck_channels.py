"""Each channel judged on its own; nothing named below what the recording can show; windows bounded.

A weak current (a heavy load moving slowly on a 160:1 gear) is reported as "too little signal" while
the position channel is still checked; only garbage is refused. A short recording whose single
acceleration makes inertia and Coulomb friction look alike names neither alone. A window longer
than the recording supports is one clear line, never a traceback or a fit of edge effects.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from modelcheck_gen import moves_for, record, trapezoid_moves

from fha_studio.cli import main
from fha_studio.logic.modelcheck import ModelCheckError, run_modelcheck
from fha_studio.physics import AxisModel, Effects
from fha_studio.recording import Recording, write_recording

CODE = "FHA-25C-50-US250"


def test_a_weak_current_is_reported_and_the_position_channel_still_checked():
    code = "FHA-17C-160-US250"
    model = AxisModel.from_code(code, load_inertia_kgm2=1.0)
    # 1 r/min with 0.05-0.08 rad/s^2: the inertial torque stays under the 0.32 N m practical floor
    t, cmd = trapezoid_moves([(12, 1.0, 0.05, 0.2), (-12, 1.0, 0.08, 0.2)], 1000.0)
    effects = Effects().with_effect(
        "kinematic_error", amplitude_arcsec=30.0, cycles_per_motor_rev=2.0, phase_deg=20.0
    )
    rec = record(model, effects, t, cmd, actuator_code=code, with_load_pos=True, noise_steps=2.0).recording
    result = run_modelcheck(rec, resimulate=False)
    torque, position = result.channel_status["torque"], result.channel_status["position"]
    assert torque.status == "too little signal" and position.status == "checked"
    assert [e.id for e in result.effects] == ["kinematic_error"], result.summary_lines()
    assert result.effects[0].params["amplitude_arcsec"] == pytest.approx(30.0, rel=0.1)
    first = result.summary_lines()[0]
    assert (
        first.startswith("The torque channel shows nothing above ") and "only the position channel" in first
    )
    report = result.to_json()
    assert report["channels"]["torque"]["status"] == "too little signal"
    assert "shows nothing above" in report["channels"]["torque"]["reason"]
    assert report["channels"]["position"]["status"] == "checked"
    assert report["bandwidth_hz"] == pytest.approx(result.bandwidth_hz) and report["bandwidth_hz"] > 0


def test_without_load_pos_the_position_channel_is_absent_and_only_garbage_current_is_refused():
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    t, cmd = trapezoid_moves(moves_for(model, n_moves=3), 1000.0)
    rec = record(model, Effects(), t, cmd, actuator_code=CODE).recording
    result = run_modelcheck(rec, resimulate=False)
    assert result.to_json()["channels"]["position"]["status"] == "absent"
    assert result.channel_status["torque"].status == "checked"
    # a column of another quantity (white noise of 1 A on a 5.6 A actuator) is still refused
    noise = np.random.default_rng(2).normal(0.0, 1.0, len(rec))
    with pytest.raises(ModelCheckError, match="'current' looks like noise"):
        run_modelcheck(
            Recording(rec.metadata, {**rec.channels, "current": noise}, rec.source), resimulate=False
        )


@pytest.fixture(scope="module")
def friction_recording():
    """5.6 s of FHA-25C-50 with a hidden 6 N m Coulomb friction (no load_pos)."""
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    t, cmd = trapezoid_moves(moves_for(model, n_moves=5), 1000.0)
    effects = Effects().with_effect("coulomb_friction", torque_nm=6.0)
    return record(model, effects, t, cmd, actuator_code=CODE).recording


def test_a_short_start_names_no_effect_the_record_cannot_tell_from_another(friction_recording):
    # the first 309 rows: a dwell and one acceleration. A constant friction and an inertia error
    # both add a constant torque there; the Coulomb detection limit is above 6 N m.
    rec = friction_recording.slice(0, 309)
    result = run_modelcheck(rec, resimulate=False)
    lines = result.summary_lines()
    assert not any(line.startswith("Inertia error missing") for line in lines), lines
    pairs = [{a.chosen, a.alternative} for a in result.ambiguities]
    assert {"inertia_error", "coulomb_friction"} in pairs, lines
    assert "long constant-speed part" in "\n".join(lines)
    # the whole recording tells them apart
    whole = run_modelcheck(friction_recording, resimulate=False)
    assert [e.id for e in whole.effects] == ["coulomb_friction"] and not whole.ambiguities


@pytest.mark.parametrize("window", [5001, 5617, 6000, 9])
def test_a_window_the_recording_cannot_support_is_one_clear_line(
    friction_recording, window, tmp_path, capsys
):
    n = len(friction_recording)
    with pytest.raises(
        ModelCheckError,
        match=rf"window {window} samples: this recording \({n} samples\) "
        r"supports 11 to \d+",
    ) as err:
        run_modelcheck(friction_recording, window=window, resimulate=False)
    assert "\n" not in str(err.value)
    path = tmp_path / "rec.csv"
    write_recording(path, friction_recording)
    assert main(["discrepancy", str(path), "--window", str(window), "--no-resim"]) == 2
    err_text = capsys.readouterr().err
    assert err_text.count("\n") == 1 and "supports 11 to" in err_text and "Traceback" not in err_text


def test_a_window_within_the_bounds_is_used_and_reported(friction_recording, tmp_path, capsys):
    path, report = tmp_path / "rec.csv", tmp_path / "report.json"
    write_recording(path, friction_recording)
    assert main(["discrepancy", str(path), "--window", "61", "--no-resim", "--json", str(report)]) == 0
    data = json.loads(report.read_text())
    assert data["analysis"]["savgol_window_samples"] == 61
    assert data["bandwidth_reason"] == "given by the user"
    assert [e["id"] for e in data["effects"]] == ["coulomb_friction"]
