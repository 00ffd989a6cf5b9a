"""A recording written by the simulated drive (hardware layer) goes through the model check."""

from __future__ import annotations

import pytest

from fha_studio.hardware.sim import SimDrive
from fha_studio.logic.modelcheck import run_modelcheck
from fha_studio.recording import read_recording
from tests.support.recorded_moves import record_moves


def test_the_simulated_drive_recording_reveals_its_hidden_effect(tmp_path):
    path = tmp_path / "sim.csv"
    effects = {"coulomb_friction": {"torque_nm": 5.0}}
    with SimDrive("FHA-25C-50-US250", load_inertia_kgm2=1.5, effects=effects) as drive:
        record_moves(drive, path, [(120, 40), (-80, 20), (150, 60), (-190, 30), (60, 10)])
    result = run_modelcheck(read_recording(path), resimulate=False)
    assert [e.id for e in result.effects] == ["coulomb_friction"], result.summary_lines()
    assert abs(result.effects[0].params["torque_nm"] - 5.0) < 0.5
    assert result.gap["torque"].rms_after < 0.5 * result.gap["torque"].rms_before
    # the simulated drive records load_pos; its rigid gear shows nothing there beyond the encoders
    position = result.channel_status["position"]
    assert position.status == "too little signal", position
    assert "position channel shows nothing above" in "\n".join(result.summary_lines())
    assert result.to_json()["channels"]["position"]["status"] == "too little signal"


def test_the_simulated_drives_torque_sensor_tells_the_gear_from_the_load(tmp_path):
    """The drive's own ``torque`` column (its sensor between the output flange and the load): with
    the current, the friction is named in the gear and the unbalance at the load."""
    path = tmp_path / "sensor.csv"
    effects = {"coulomb_friction": {"torque_nm": 5.0},
               "gravity_load": {"amplitude_nm": 20.0, "phase_deg": 30.0}}
    with SimDrive("FHA-25C-50-US250", load_inertia_kgm2=1.5, effects=effects) as drive:
        record_moves(drive, path, [(120, 40), (-80, 20), (150, 60), (-190, 30), (60, 10)], torque_sensor=True)
    recording = read_recording(path)
    assert "torque" in recording.channels
    result = run_modelcheck(recording, resimulate=False)
    found = {e.id: e for e in result.effects}
    assert set(found) == {"coulomb_friction", "gravity_load"}, result.summary_lines()
    assert found["coulomb_friction"].label.endswith("in the gear")
    assert found["gravity_load"].label.endswith("at the load")
    # the sensor measures the load's torque; the gear's friction comes out of Kt x current minus it
    # (its moves never reach a steady speed long enough to tell Coulomb from viscous: within 15 %)
    assert found["coulomb_friction"].params["torque_nm"] == pytest.approx(5.0, rel=0.15)
    assert found["gravity_load"].params["amplitude_nm"] == pytest.approx(20.0, rel=0.05)
    assert {"gear torque", "load torque"} <= set(result.channel_status)
