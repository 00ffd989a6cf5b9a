"""The simulated drive's CN2 outputs written in the CSV layouts real instruments export (Saleae
Logic's changes, Rigol, Tektronix, Siglent, PicoScope), imported: encoder and command counts
exact, speed within 1 % of the drive's, as through sigrok's own forms (test_round_trip.py)."""

from __future__ import annotations

import numpy as np
import pytest

from fha_studio.catalog import get_actuator
from fha_studio.hardware.bench import readers
from fha_studio.hardware.bench.readers import read_capture
from fha_studio.hardware.sim.cn2 import RAD_S_PER_RPM, Cn2Settings, VirtualBenchInstrument
from fha_studio.logic.bench.importer import AxisFacts, DriveSettings, SignalSpec, import_bench
from fha_studio.physics import AxisModel, ServoAxis
from tests.support import instrument_csv as layouts
from tests.support.cn2_capture import CODE

# two four-channel scopes side by side: the encoder and SPD-MON on one, the command on the other
SCOPE_A = {"encoder_a": "ENC_A", "encoder_b": "ENC_B", "encoder_z": "ENC_Z", "speed_monitor": "SPD_MON"}
SCOPE_B = {"command_a": "CMD_A", "command_b": "CMD_B", "in_position": "IN_POS", "alarm": "ALARM"}


#: Command pulses of the short move (FWD, then back), through the electronic gear 2/1.
PULSES = (900, -400)


@pytest.fixture(scope="module")
def drive():
    """A short move of the simulated FHA-25C-50 (a small file in each layout): 900 command pulses
    FWD at 8 r/min, 400 back at 5 r/min, CN2 recorded at 200 kHz (0.2 s)."""
    axis = ServoAxis(AxisModel.from_actuator(get_actuator(CODE), load_inertia_kgm2=0.3))
    axis.set_settings(axis.settings.replace(electronic_gear_numerator=2, electronic_gear_denominator=1))
    axis.servo_on()
    instrument = VirtualBenchInstrument(axis, 200e3, Cn2Settings(pulse_form=1, multiplication=4))
    instrument.record(0.01)  # standing: where the monitor's offset is taken
    axis.move_by_pulses(PULSES[0], speed_rad_s=8 * RAD_S_PER_RPM)
    instrument.record(0.1)
    axis.move_by_pulses(PULSES[1], speed_rad_s=5 * RAD_S_PER_RPM)
    instrument.record(0.09)
    return axis, instrument


def _settings():
    return DriveSettings(1, 4, 2, 1, 3000.0)


def _check(result, instrument, axis, first: int = 0, speed: bool = True):
    """Counts exact sample by sample from ``first`` on, the command's pulses, speed within 1 %."""
    truth = instrument.truth.arrays()
    enc = truth["encoder_counts"][first:]
    n = result.decoded.samples
    assert np.array_equal(result.decoded.encoder.counts, enc[:n] - enc[0])
    assert result.summary["encoder"]["illegal_transitions"] == 0
    assert result.summary["encoder"]["counts"] == enc[n - 1] - enc[0] == axis.feedback_pulses - enc[0]
    cmd = truth["command_counts"][first:]
    assert np.array_equal(result.decoded.command.counts, cmd[:n] - cmd[0])
    assert result.summary["command_counts"] == 2 * sum(PULSES) == axis.command_pulses
    if speed:
        rec = result.recording
        idx = np.rint(rec.t_s * instrument.sample_rate_hz).astype(int)
        expected = truth["motor_rpm"][first:][idx] / 50.0
        peak = float(np.max(np.abs(expected)))
        assert peak > 3.0  # r/min at the output: the move reaches speed
        assert float(np.max(np.abs(rec.vel_rpm - expected))) < 0.01 * peak


def _scope_signals(path_a, path_b, names_a, names_b):
    signals = [SignalSpec(role, str(path_a), name) for role, name in zip(SCOPE_A, names_a, strict=True)]
    signals += [SignalSpec(role, str(path_b), name) for role, name in zip(SCOPE_B, names_b, strict=True)]
    return signals


@pytest.mark.parametrize("layout", ["rigol", "tek", "picoscope"])
def test_a_pair_of_four_channel_scopes_in_each_layout(drive, layout, tmp_path):
    axis, instrument = drive
    block = instrument.capture()
    names = {
        "rigol": ["CH1", "CH2", "CH3", "CH4"],
        "tek": ["CH1", "CH2", "CH3", "CH4"],
        "picoscope": ["Channel A", "Channel B", "Channel C", "Channel D"],
    }[layout]
    write = {"rigol": layouts.write_rigol, "tek": layouts.write_tek, "picoscope": layouts.write_picoscope}[
        layout
    ]
    path_a = write(tmp_path / "a.csv", block, dict(zip(names, SCOPE_A.values(), strict=True)))
    path_b = write(tmp_path / "b.csv", block, dict(zip(names, SCOPE_B.values(), strict=True)))
    capture = read_capture(path_a)
    assert capture.channels == tuple(names) and capture.samples == block.samples
    assert capture.sample_rate_hz == pytest.approx(instrument.sample_rate_hz, rel=1e-9)
    assert capture.units == dict.fromkeys(names, "V")
    result = import_bench(
        _scope_signals(path_a, path_b, names, names), AxisFacts.for_actuator(CODE), _settings()
    )
    _check(result, instrument, axis)


def test_siglent_one_channel_per_file(drive, tmp_path):
    axis, instrument = drive
    block = instrument.capture()
    signals = []
    roles = ("encoder_a", "encoder_b", "speed_monitor", "command_a", "command_b")
    for k, (role, source) in enumerate((r, c) for r, c in {**SCOPE_A, **SCOPE_B}.items() if r in roles):
        path = layouts.write_siglent(tmp_path / f"SDS{k:05d}.CSV", block, source, f"CH{k % 4 + 1}")
        signals.append(SignalSpec(role, str(path), None))  # one channel: no name needed
    capture = read_capture(tmp_path / "SDS00002.CSV")
    assert capture.channels == ("CH3",) and capture.units == {"CH3": "V"}
    assert capture.start_s == pytest.approx(-0.004)
    result = import_bench(signals, AxisFacts.for_actuator(CODE), _settings())
    _check(result, instrument, axis)


@pytest.mark.parametrize("logic1", [False, True])
def test_a_saleae_export_of_changes_is_put_on_the_finest_interval(drive, logic1, tmp_path):
    axis, instrument = drive
    block = instrument.capture()
    path = layouts.write_saleae_digital(tmp_path / "digital.csv", block, logic1=logic1)
    capture = read_capture(path)
    # the finest interval between changes is one sample of the instrument (5 us): its own rate
    assert capture.sample_rate_hz == pytest.approx(instrument.sample_rate_hz, rel=1e-9)
    assert "200 kHz" in capture.form and "finest interval" in capture.form
    # the export ends at the last change: the samples up to it come back as they were
    last_change = int(np.flatnonzero(np.diff(block.logic.astype(np.int64)))[-1]) + 1
    assert capture.samples == last_change + 1
    assert np.array_equal(capture.block.logic, block.logic[: last_change + 1])
    names = (
        [f"Channel {k}" for k in range(len(block.logic_channels))] if logic1 else list(block.logic_channels)
    )
    assert capture.channels == tuple(names)
    roles = {r: c for r, c in {**SCOPE_A, **SCOPE_B}.items() if r != "speed_monitor"}
    index = {c: names[block.logic_channels.index(c)] for c in roles.values()}
    signals = [SignalSpec(role, str(path), index[c]) for role, c in roles.items()]
    result = import_bench(signals, AxisFacts.for_actuator(CODE), _settings())
    _check(result, instrument, axis, speed=False)


def test_a_glitch_of_a_few_ns_in_a_saleae_export_is_dropped_not_refused(drive, tmp_path, monkeypatch):
    """A 2 ns spike on ENC_A (line ringing): its finest interval would put the capture on billions
    of samples in a long capture; it is put on the coarsest 1-2-5 grid within the limit (here made
    small, so that the grid is the instrument's own 5 us), the spike dropped and said."""
    axis, instrument = drive
    block = instrument.capture()
    path = layouts.write_saleae_digital(tmp_path / "digital.csv", block)
    lines = path.read_text().splitlines()
    column = lines[0].split(",").index("ENC_A")
    k = len(lines) // 2
    fields = lines[k].split(",")
    spike = list(fields)
    spike[column] = "1" if fields[column] == "0" else "0"
    at_s = float(fields[0])
    lines[k + 1 : k + 1] = [
        ",".join([f"{at_s + 2e-9:.9f}", *spike[1:]]), ",".join([f"{at_s + 4e-9:.9f}", *fields[1:]])
    ]
    path.write_text("\n".join(lines) + "\n")
    last_change = int(np.flatnonzero(np.diff(block.logic.astype(np.int64)))[-1]) + 1
    # a limit that makes the grid a 4 us step at the finest, so 5 us on the 1-2-5 series
    monkeypatch.setattr(readers, "CHANGES_GRID_MAX_SAMPLES", round(last_change * 5e-6 / 4e-6) + 1)
    capture = read_capture(path)
    assert capture.sample_rate_hz == pytest.approx(instrument.sample_rate_hz, rel=1e-9)
    assert "its finest interval, 2 ns," in capture.form
    assert "2 changes within 5 µs of the next dropped (a pulse that short is a glitch)" in capture.form
    assert np.array_equal(capture.block.logic, block.logic[: last_change + 1])
    roles = {r: c for r, c in {**SCOPE_A, **SCOPE_B}.items() if r != "speed_monitor"}
    signals = [SignalSpec(role, str(path), c) for role, c in roles.items()]
    result = import_bench(signals, AxisFacts.for_actuator(CODE), _settings())
    _check(result, instrument, axis, speed=False)


def test_a_saleae_analog_export_reads_at_its_rate(drive, tmp_path):
    """Logic 2's analog export is one row per sample: read as a CSV at one rate, SPD-MON as it was."""
    _, instrument = drive
    block = instrument.capture()
    path = layouts.write_saleae_analog(tmp_path / "analog.csv", block, {"Channel 0": "SPD_MON"})
    capture = read_capture(path)
    assert capture.channels == ("Channel 0",) and capture.form == "CSV"
    assert capture.sample_rate_hz == pytest.approx(instrument.sample_rate_hz, rel=1e-6)
    assert np.allclose(capture.analog("Channel 0"), block.analog["SPD_MON"], atol=1e-6)


def test_a_saleae_capture_of_digital_and_analog_at_their_own_rates(drive, tmp_path):
    """Logic 2 writes digital (changes) and analog (its own rate, here 400 kHz) apart: the changes
    are sampled at the analog rate from the analog file's start, counts exact, speed within 1 %."""
    axis, instrument = drive
    block = instrument.capture()
    digital = layouts.write_saleae_digital(tmp_path / "digital.csv", block)
    twice = type(block)(2 * block.sample_rate_hz, analog={"SPD_MON": np.repeat(block.analog["SPD_MON"], 2)})
    analog = layouts.write_saleae_analog(tmp_path / "analog.csv", twice, {"Channel 0": "SPD_MON"})
    roles = {r: c for r, c in {**SCOPE_A, **SCOPE_B}.items() if r != "speed_monitor"}
    signals = [SignalSpec(role, str(digital), c) for role, c in roles.items()]
    signals.append(SignalSpec("speed_monitor", str(analog), "Channel 0"))
    result = import_bench(signals, AxisFacts.for_actuator(CODE), _settings())
    assert result.decoded.sample_rate_hz == pytest.approx(400e3)
    assert result.notes[0] == f"{digital}: its changes sampled at 400 kHz from 0 s, as {analog}"
    truth = instrument.truth.arrays()
    # every second sample is one of the instrument's: the counts there are its counts
    assert np.array_equal(
        result.decoded.encoder.counts[::2], truth["encoder_counts"] - truth["encoder_counts"][0]
    )
    assert result.summary["command_counts"] == 2 * sum(PULSES) == axis.command_pulses
    rec = result.recording
    expected = truth["motor_rpm"][np.minimum(np.rint(rec.t_s * 200e3).astype(int), block.samples - 1)] / 50.0
    peak = float(np.max(np.abs(expected)))
    assert peak > 3.0 and float(np.max(np.abs(rec.vel_rpm - expected))) < 0.01 * peak


def test_two_scopes_at_two_rates_are_still_refused(tmp_path):
    """Only changes are put on another grid: samples at two fixed rates are not made to line up."""
    from fha_studio.logic.bench.importer import BenchImportError

    rigol = tmp_path / "rigol.csv"
    rigol.write_text("X,CH1,CH2,Start,Increment,\nSequence,Volt,Volt,0,5.0e-06\n0,0,0,\n1,5,0,\n2,5,5,\n")
    pico = tmp_path / "pico.csv"
    pico.write_text("Time,Channel A\n(ms),(V)\n\n0.0000,0.1\n0.0025,0.2\n0.0050,0.3\n")
    signals = [SignalSpec("encoder_a", str(rigol), "CH1"), SignalSpec("encoder_b", str(rigol), "CH2")]
    signals.append(SignalSpec("speed_monitor", str(pico), "Channel A"))
    with pytest.raises(BenchImportError) as err:
        import_bench(signals, AxisFacts.for_actuator(CODE), _settings())
    assert str(err.value) == (
        f"{pico}: sampled at 400 kHz but {rigol} at 200 kHz: the signals of one import must come at one rate"
    )
