"""The simulated drive's CN2 outputs, written by the virtual bench instrument, played back through
the real sigrok-cli's input modules (``-i FILE``, ``-I vcd`` / ``-I csv:...``, ``.sr``) and
streamed like an instrument into the decoder: encoder counts exact, command counts exact, speed
within 1 % of the drive's; the channels keep the file's names and kinds (never D0 positions)."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from fha_studio.hardware.bench import sigrok_input
from fha_studio.hardware.bench.sigrok import SigrokError
from fha_studio.logic.bench.display import LiveQuadrature
from fha_studio.logic.bench.importer import AxisFacts, DriveSettings, SignalSpec, import_bench
from tests.support.cn2_capture import (
    CHANNELS,
    CODE,
    controller_move,
    drive_settings,
    expected_speed_rpm,
    recorded_move,
)

pytestmark = pytest.mark.skipif(shutil.which("sigrok-cli") is None, reason="sigrok-cli is not installed")

NAMES = {"sr": "cn2.sr", "vcd": "cn2.vcd", "sigrok-csv": "cn2-sigrok.csv", "csv": "cn2.csv"}


@pytest.fixture(scope="module")
def drive():
    return recorded_move(pulse_form=1, gear=(2, 1))


def _through_sigrok(path: str):
    try:
        return sigrok_input.read_through_sigrok(path)
    except SigrokError as exc:  # as the importer's own loader: one line
        raise ValueError(str(exc)) from None


@pytest.mark.parametrize("form", list(NAMES))
def test_each_file_form_through_sigrok_cli_gives_the_drives_positions_back(drive, form, tmp_path):
    axis, instrument = drive
    path = tmp_path / NAMES[form]
    instrument.write(path, form)
    plan = sigrok_input.plan_input(path)
    # the file's own names and kinds, as sigrok-cli reads them
    assert {"ENC_A", "ENC_B", "CMD_A", "IN_POS"} <= set(plan.logic)
    assert plan.analog == (() if form == "vcd" else ("SPD_MON",))  # sigrok-cli's VCD input skips reals
    assert not any(name.startswith("D") and name[1:].isdigit() for name in plan.channels)
    assert plan.sample_rate_hz == 200e3  # the VCD's 1 us timescale downsampled to its stated rate

    acquisition = sigrok_input.FileAcquisition(path)
    live = LiveQuadrature()
    counts, firsts = [], []
    with acquisition:
        for block in acquisition.blocks():  # decoded as the blocks come, as from an instrument
            firsts.append((block.first_sample, block.samples))
            counts.append(live.feed(block.bit("ENC_A"), block.bit("ENC_B")))
    assert [f for f, _ in firsts] == list(np.cumsum([0] + [n for _, n in firsts[:-1]]))
    truth = instrument.truth.arrays()
    assert np.array_equal(np.concatenate(counts), truth["encoder_counts"] - truth["encoder_counts"][0])

    signals = [SignalSpec(role, str(path), channel) for role, channel in CHANNELS.items()
               if not (form == "vcd" and role == "speed_monitor")]
    result = import_bench(signals, AxisFacts.for_actuator(CODE), DriveSettings(1, 4, 2, 1, 3000.0),
                          loader=_through_sigrok)
    decoded = result.decoded
    assert decoded.samples == truth["encoder_counts"].size
    assert np.array_equal(decoded.encoder.counts, truth["encoder_counts"] - truth["encoder_counts"][0])
    assert truth["encoder_counts"][-1] == axis.feedback_pulses
    assert result.summary["encoder"]["illegal_transitions"] == 0
    assert result.summary["encoder"]["z_count_errors"] == 0
    assert np.array_equal(decoded.command.counts, truth["command_counts"] - truth["command_counts"][0])
    assert result.summary["command_counts"] == 10000 == axis.command_pulses
    if form == "vcd":
        return
    recording = result.recording
    expected = expected_speed_rpm(recording, truth, instrument.sample_rate_hz)
    peak = float(np.max(np.abs(expected)))
    assert peak > 7.5
    assert float(np.max(np.abs(recording.vel_rpm - expected))) < 0.01 * peak


def test_the_documented_drive_moved_by_the_controller_through_sigrok_cli(tmp_path):
    """The stepped SimDrive on the documented profile (CN3 silent in motion), moved by the
    controller's pulses: its CN2 as a sigrok session, streamed back through sigrok-cli."""
    with controller_move(tmp_path) as (drive, instrument):
        instrument.record(0.6)
        instrument.write(tmp_path / "cn2.sr", "sr")
        signals = [SignalSpec(role, str(tmp_path / "cn2.sr"), channel) for role, channel in CHANNELS.items()]
        result = import_bench(signals, AxisFacts.for_actuator(CODE), drive_settings(drive),
                              loader=_through_sigrok)
        truth = instrument.truth.arrays()
        counts = truth["encoder_counts"]
        assert np.array_equal(result.decoded.encoder.counts, counts - counts[0])
        assert result.summary["command_counts"] == drive.axis.command_pulses == round(12.0 / 360 * 500000)
        expected = expected_speed_rpm(result.recording, truth, instrument.sample_rate_hz)
        peak = float(np.max(np.abs(expected)))
        assert peak > 9.0
        assert float(np.max(np.abs(result.recording.vel_rpm - expected))) < 0.01 * peak


def test_a_decimal_comma_csv_is_refused_for_sigrok_cli_in_one_line(drive, tmp_path):
    _, instrument = drive
    instrument.write(tmp_path / "eu.csv", "csv-semicolon")
    with pytest.raises(SigrokError) as refused:
        sigrok_input.plan_input(tmp_path / "eu.csv")
    text = str(refused.value)
    assert "eu.csv: line 2: decimal commas" in text and "\n" not in text


def test_channels_asked_for_that_the_file_lacks_are_named(drive, tmp_path):
    _, instrument = drive
    instrument.write(tmp_path / "c.sr", "sr")
    with pytest.raises(SigrokError, match=r"c\.sr: no channel D0 \(it has ENC_A, ENC_B"):
        sigrok_input.FileAcquisition(tmp_path / "c.sr", ["D0"]).start()


def test_a_file_sigrok_cannot_read_is_one_line(tmp_path):
    bad = tmp_path / "bad.vcd"
    bad.write_text("$timescale 1 us $end\n$var wire 1 ! A $end\n$enddefinitions $end\n#0 2!\n")
    with pytest.raises((SigrokError, ValueError)) as refused:
        sigrok_input.read_through_sigrok(bad)
    text = str(refused.value)
    assert "bad.vcd: sigrok-cli cannot read the logic channels: Skipping unknown token '2!'" in text
    assert "\n" not in text
