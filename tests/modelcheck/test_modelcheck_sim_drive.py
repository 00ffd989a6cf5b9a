"""A recording written by the simulated drive (hardware layer) goes through the model check."""

from __future__ import annotations

from fha_studio.hardware.sim import SimDrive
from fha_studio.logic.modelcheck import run_modelcheck
from fha_studio.recording import read_recording


def test_the_simulated_drive_recording_reveals_its_hidden_effect(tmp_path):
    path = tmp_path / "sim.csv"
    effects = {"coulomb_friction": {"torque_nm": 5.0}}
    with SimDrive("FHA-25C-50-US250", load_inertia_kgm2=1.5, effects=effects) as drive:
        drive.set_servo(True)
        drive.start_recording(path, 1000.0)
        drive.advance(0.2)
        for angle_deg, speed_rpm in [(120, 40), (-80, 20), (150, 60), (-190, 30), (60, 10)]:
            drive.set_move_speed(speed_rpm)
            drive.move_by(angle_deg)
            while drive.moving:
                drive.advance(0.05)
            drive.advance(0.2)
        drive.stop_recording()
    result = run_modelcheck(read_recording(path), resimulate=False)
    assert [e.id for e in result.effects] == ["coulomb_friction"], result.summary_lines()
    assert abs(result.effects[0].params["torque_nm"] - 5.0) < 0.5
    assert result.gap["torque"].rms_after < 0.5 * result.gap["torque"].rms_before
    # the simulated drive records load_pos; its rigid gear shows nothing there beyond the encoders
    position = result.channel_status["position"]
    assert position.status == "too little signal", position
    assert "position channel shows nothing above" in "\n".join(result.summary_lines())
    assert result.to_json()["channels"]["position"]["status"] == "too little signal"
