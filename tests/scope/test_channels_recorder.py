import numpy as np
import pytest

from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.scope.channels import items_to_poll, scope_channels
from fha_studio.logic.scope.recorder import ScopeRecorder
from fha_studio.recording import RecordingMetadata, read_recording


@pytest.fixture(scope="module")
def channels():
    return scope_channels(load_parameter_model(), 500_000)


def test_channels_cover_positions_speed_current_and_io_bits(channels):
    by_key = {c.key: c for c in channels}
    assert by_key["feedback_position"].unit == "deg"
    assert by_key["feedback_position"].convert(500_000) == pytest.approx(360.0)
    assert by_key["output_speed"].convert(6000) == pytest.approx(60.0)  # 0.01 r/min on the wire
    assert by_key["motor_current"].convert(1500) == pytest.approx(1.5)  # mA on the wire
    assert by_key["flange_torque"].convert(-2050) == pytest.approx(-20.5)  # 0.01 N m on the wire
    assert by_key["in_position"].convert(0b1000) == 1.0
    assert by_key["origin_sensor"].convert(0b1000) == 0.0
    assert items_to_poll([by_key["in_position"], by_key["alarm"], by_key["feedback_position"]]) == [100, 106]


def test_recorder_writes_a_recording_the_model_check_reads(tmp_path, channels):
    keys_chosen = ("feedback_position", "command_position", "motor_current", "output_speed", "error_pulses",
                   "in_position", "flange_torque")
    chosen = [c for c in channels if c.key in keys_chosen]
    meta = RecordingMetadata(actuator="FHA-25C-50-US250", load_inertia_kgm2=1.5, sample_rate_hz=100)
    path = tmp_path / "rec.csv"
    rec = ScopeRecorder(path, meta, chosen)
    t = 100.0 + np.arange(50) * 0.01
    block = np.column_stack([t] + [np.full(50, k, dtype=float) for k in range(len(chosen))])
    rec.write(block[:20])
    rec.write(block[20:])
    rec.close()
    recording = read_recording(path)
    assert recording.t_s[0] == 0 and recording.t_s[-1] == pytest.approx(0.49)
    keys = [c.key for c in chosen]
    assert recording.pos_deg[0] == keys.index("feedback_position")
    assert recording.current_a[0] == keys.index("motor_current")
    assert recording.cmd_pos_deg[0] == keys.index("command_position")
    assert recording.vel_rpm[0] == keys.index("output_speed")
    # the simulated drive's torque sensor on the flange (monitor 111) is the recording's torque column
    assert recording.channels["torque"][0] == keys.index("flange_torque")
    assert set(recording.extra_channels) == {"error_pulses", "in_position"}
    # plain numpy reads it too
    plain = np.genfromtxt(path, delimiter=",", comments="#")[1:]
    assert plain.shape == (50, len(chosen) + 1)


def test_recorder_refuses_a_selection_without_position_or_current(tmp_path, channels):
    meta = RecordingMetadata(actuator="FHA-25C-50-US250", load_inertia_kgm2=1.5)
    only_speed = [c for c in channels if c.key == "output_speed"]
    with pytest.raises(ValueError, match="feedback_position"):
        ScopeRecorder(tmp_path / "x.csv", meta, only_speed)
