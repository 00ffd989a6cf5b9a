"""The simulated drive's CN2 outputs recorded through the virtual bench instrument in each file
form, imported, give the drive's own positions back: encoder counts and command counts exact,
speed within 1 % of the drive's."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fha_studio.catalog import get_actuator
from fha_studio.hardware.sim.cn2 import FORMS, Cn2Settings, VirtualBenchInstrument
from fha_studio.logic.bench.importer import (
    AxisFacts,
    BenchImportError,
    DriveSettings,
    SignalSpec,
    import_bench,
)
from fha_studio.physics import AxisModel, ServoAxis
from fha_studio.recording import read_recording, write_recording
from tests.support.cn2_capture import (
    CHANNELS,
    CODE,
    controller_move,
    drive_settings,
    expected_speed_rpm,
    recorded_move,
)

RPM = 2 * math.pi / 60


def _lag_s(recorded: np.ndarray, truth: np.ndarray, idx: np.ndarray, rate_hz: float) -> float:
    """How late ``recorded`` (one value per output sample at ``idx``) follows ``truth`` (one per
    capture sample): the shift of ``truth``, in capture samples within +-2 output intervals, that
    fits it best (negative: it leads)."""
    step = int(idx[1] - idx[0])
    inner = idx[(idx > 2 * step) & (idx < truth.size - 2 * step)]
    inside = np.isin(idx, inner)
    shifts = np.arange(-2 * step, 2 * step + 1)
    errors = [float(np.sum((recorded[inside] - truth[inner - k]) ** 2)) for k in shifts]
    return float(shifts[int(np.argmin(errors))]) / rate_hz


@pytest.fixture(scope="module")
def drive():
    return recorded_move(pulse_form=1, gear=(2, 1))


def _settings(pulse_form=1, multiplication=4, gear=(2, 1)):
    return DriveSettings(pulse_form, multiplication, gear[0], gear[1], 3000.0)


@pytest.mark.parametrize("form", FORMS)
def test_each_file_form_gives_the_drives_positions_back(drive, form, tmp_path):
    axis, instrument = drive
    path = tmp_path / ("capture.sr" if form == "sr" else "capture.vcd" if form == "vcd" else "capture.csv")
    instrument.write(path, form)
    # a VCD holds SPD-MON as a real variable
    signals = [SignalSpec(role, str(path), channel) for role, channel in CHANNELS.items()]
    result = import_bench(signals, AxisFacts.for_actuator(CODE), _settings())
    truth = instrument.truth.arrays()
    decoded = result.decoded
    assert decoded.samples == truth["encoder_counts"].size
    # encoder counts exact, sample by sample, and the drive's own feedback count at the end
    assert np.array_equal(decoded.encoder.counts, truth["encoder_counts"] - truth["encoder_counts"][0])
    assert result.summary["encoder"]["counts"] == truth["encoder_counts"][-1] - truth["encoder_counts"][0]
    assert truth["encoder_counts"][-1] == axis.feedback_pulses
    assert result.summary["encoder"]["illegal_transitions"] == 0
    assert result.summary["encoder"]["z_pulses"] >= 1 and result.summary["encoder"]["z_count_errors"] == 0
    # command counts exact: 9000 - 4000 command pulses through the 2/1 gear
    assert np.array_equal(decoded.command.counts, truth["command_counts"] - truth["command_counts"][0])
    assert result.summary["command_counts"] == 10000 == axis.command_pulses
    recording = result.recording
    assert recording.metadata.extra["source_pos"].startswith(f"{path}#ENC_A and {path}#ENC_B")
    assert not recording.has_current
    # speed: the drive's output r/min at each recording instant, within 1 % of the peak, and at
    # the same instant as the position (no lag or lead between the columns beyond the monitor's)
    idx = np.rint(recording.t_s * instrument.sample_rate_hz).astype(int)
    drive_rpm = truth["motor_rpm"] / 50.0
    expected = drive_rpm[idx]
    peak = float(np.max(np.abs(expected)))
    assert peak > 7.5
    assert float(np.max(np.abs(recording.vel_rpm - expected))) < 0.01 * peak
    assert abs(_lag_s(recording.vel_rpm, drive_rpm, idx, instrument.sample_rate_hz)) < 0.15e-3
    assert result.summary["speed_offset_v"] == pytest.approx(instrument.settings.monitor.offset_v, abs=0.002)
    # the recording as a file: fha-recording/2, read back the same
    write_recording(tmp_path / "rec.csv", recording)
    back = read_recording(tmp_path / "rec.csv")
    assert back.metadata.extra["source_vel"].startswith(f"{path}#SPD_MON")
    assert np.allclose(back.pos_deg, recording.pos_deg)


@pytest.mark.parametrize(("pulse_form", "multiplication"), [(0, 4), (2, 4), (2, 1)])
def test_every_command_pulse_form_round_trips(pulse_form, multiplication, tmp_path):
    gear = (2, 1) if multiplication == 1 else (1, 1)  # x1: four command edges per pulse, two counts
    axis, instrument = recorded_move(
        pulse_form, multiplication, gear=gear, rate_hz=400e3 if multiplication == 1 else 200e3
    )
    instrument.write(tmp_path / "c.sr", "sr")
    signals = [SignalSpec(r, str(tmp_path / "c.sr"), c) for r, c in CHANNELS.items()]
    result = import_bench(signals, AxisFacts.for_actuator(CODE), _settings(pulse_form, multiplication, gear))
    truth = instrument.truth.arrays()
    assert np.array_equal(result.decoded.command.counts, truth["command_counts"] - truth["command_counts"][0])
    assert result.summary["command_counts"] == axis.command_pulses == 5000 * gear[0] // gear[1]


def test_a_capture_too_slow_for_the_encoder_is_refused_with_both_figures(drive, tmp_path):
    from fha_studio.hardware.bench import writers
    from fha_studio.hardware.bench.capture import SampleBlock

    _, instrument = drive
    block = instrument.capture()
    every = 8  # 25 kHz: the encoder's edges at 400 r/min (motor) are 66.7 kHz
    slow = SampleBlock(
        block.sample_rate_hz / every,
        block.logic_channels,
        block.logic[::every].copy(),
        {k: v[::every].copy() for k, v in block.analog.items()},
    )
    writers.write_sr(tmp_path / "slow.sr", slow)
    signals = [SignalSpec(r, str(tmp_path / "slow.sr"), c) for r, c in CHANNELS.items()]
    with pytest.raises(BenchImportError) as err:
        import_bench(signals, AxisFacts.for_actuator(CODE), _settings())
    text = str(err.value)
    assert "25 kHz" in text and "r/min" in text and "kHz of edges" in text and "\n" not in text


def test_the_simulated_drive_on_the_documented_profile_through_the_instrument(tmp_path):
    """A stepped SimDrive whose CN3 is silent in motion (documented profile): the controller's
    pulse train moves it, the instrument samples CN2, and the import gives its counts back."""
    with controller_move(tmp_path) as (drive, instrument):
        blocks = list(instrument.stream(0.6, block_s=0.02))  # as a live stream delivers it
        assert [b.first_sample for b in blocks[1:]] == [a.first_sample + a.samples for a in blocks[:-1]]
        instrument._blocks.extend(blocks)
        instrument.write(tmp_path / "cn2.sr", "sr")
        signals = [SignalSpec(role, str(tmp_path / "cn2.sr"), channel) for role, channel in CHANNELS.items()]
        result = import_bench(signals, AxisFacts.for_actuator(CODE), drive_settings(drive))
        truth = instrument.truth.arrays()
        assert truth["encoder_counts"][-1] == drive.axis.feedback_pulses
        assert np.array_equal(
            result.decoded.encoder.counts, truth["encoder_counts"] - truth["encoder_counts"][0]
        )
        assert result.summary["command_counts"] == drive.axis.command_pulses == round(12.0 / 360 * 500000)
        assert abs(result.recording.pos_deg[-1] - 12.0) < 0.01
        recording = result.recording
        expected = expected_speed_rpm(recording, truth, instrument.sample_rate_hz)
        peak = float(np.max(np.abs(expected)))
        assert peak > 9.0
        assert float(np.max(np.abs(recording.vel_rpm - expected))) < 0.01 * peak


def test_an_encoder_on_the_load_gives_the_flange_after_the_gear(tmp_path):
    """A bench with an encoder on the output flange (LOAD_A/LOAD_B, not a CN2 signal): its counts
    come back exact, and the recording's load_pos is the flange after the gear's lost motion (here
    a dead band of 200 arcsec: load_pos - pos turns by it at the reversal), with its source."""
    from fha_studio.physics import Effects

    model = AxisModel.from_actuator(get_actuator(CODE), load_inertia_kgm2=0.3)
    axis = ServoAxis(model.with_effects(Effects().with_effect("lost_motion", width_arcsec=200.0)))
    axis.servo_on()
    counts = 1 << 19
    settings = Cn2Settings(load_counts_per_turn=counts, speed_monitor=False)
    instrument = VirtualBenchInstrument(axis, 200e3, settings)
    instrument.keep(0.03)
    axis.move_by_pulses(3000, speed_rad_s=5 * RPM)
    instrument.keep(0.3)
    axis.move_by_pulses(-3000, speed_rad_s=5 * RPM)
    instrument.keep(0.3)
    path = instrument.write(tmp_path / "bench.sr", "sr")
    roles = {"encoder_a": "ENC_A", "encoder_b": "ENC_B"}
    roles |= {"load_encoder_a": "LOAD_A", "load_encoder_b": "LOAD_B"}
    signals = [SignalSpec(role, str(path), channel) for role, channel in roles.items()]
    facts, drive = AxisFacts.for_actuator(CODE), _settings(0, 4, (1, 1))
    with pytest.raises(BenchImportError, match="--load-encoder-counts"):
        import_bench(signals, facts, drive)
    result = import_bench(signals, facts, drive, load_counts_per_turn=counts)
    truth = instrument.truth.arrays()
    assert "SPD_MON" not in instrument.capture().analog  # a logic analyzer without its analog input
    assert np.array_equal(result.decoded.load_encoder.counts, truth["load_counts"] - truth["load_counts"][0])
    assert result.summary["load_encoder"]["counts_per_output_turn"] == counts
    rec = result.recording
    assert rec.metadata.extra["source_load_pos"].startswith(f"{path}#LOAD_A and {path}#LOAD_B")
    twist_arcsec = (rec.load_pos_deg - rec.pos_deg) * 3600.0
    # after the first move the flange lags half the band behind; after the return it leads by it
    assert np.ptp(twist_arcsec) == pytest.approx(200.0, abs=8.0)
