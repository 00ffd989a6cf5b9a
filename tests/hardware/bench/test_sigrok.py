"""Live acquisition through the real sigrok-cli and its demo driver (no hardware, no mocks)."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fha_studio.hardware.bench import sigrok
from fha_studio.hardware.bench.capture import join_blocks
from fha_studio.hardware.bench.readers import read_capture

pytestmark = pytest.mark.skipif(shutil.which("sigrok-cli") is None, reason="sigrok-cli is not installed")


def test_scan_lines_are_parsed_with_connection_and_channels():
    text = ("The following devices were found:\n"
            "demo - Demo device with 13 channels: D0 D1 D2 D3 D4 D5 D6 D7 A0 A1 A2 A3 A4\n"
            "fx2lafw:conn=1.5 - Saleae Logic with 8 channels: D0 D1 D2 D3 D4 D5 D6 D7\n"
            "rigol-ds:conn=/dev/usbtmc0 - Rigol DS1054Z 00.04.04 with 1 channel: CH1\n")
    demo, saleae, rigol = sigrok.parse_scan(text)
    assert (demo.spec, demo.description) == ("demo", "Demo device")
    assert demo.analog_channels == ("A0", "A1", "A2", "A3", "A4")
    assert saleae.spec == "fx2lafw:conn=1.5" and saleae.logic_channels == tuple(f"D{i}" for i in range(8))
    assert rigol.spec == "rigol-ds:conn=/dev/usbtmc0"
    assert rigol.channels == rigol.analog_channels == ("CH1",)
    assert sigrok.parse_scan("") == []


def test_scan_finds_the_demo_driver_with_its_options():
    (device,) = sigrok.scan("demo:analog_channels=2:logic_channels=4")
    assert device.channels == ("D0", "D1", "D2", "D3", "A0", "A1")


def test_a_logic_stream_delivers_the_samples_a_finite_capture_of_the_same_pattern_has(tmp_path: Path):
    reference = tmp_path / "demo.sr"
    subprocess.run(["sigrok-cli", "-d", "demo", "--config", "samplerate=1m", "--samples", "20000",
                    "-C", ",".join(f"D{i}" for i in range(8)), "-o", str(reference)], check=True,
                   capture_output=True, timeout=20)
    expected = read_capture(reference)
    with sigrok.Acquisition("demo", ["D2", "D5"], 1e6, max_samples=20000) as acquisition:
        blocks = list(acquisition.blocks())
    block = join_blocks(blocks)
    assert (block.samples, block.sample_rate_hz, acquisition.samples) == (20000, 1e6, 20000)
    assert block.logic_channels == ("D0", "D1", "D2", "D3", "D4", "D5")  # up to the highest asked
    for name in ("D2", "D5", "D0"):
        assert np.array_equal(block.bit(name), expected.logic(name)), name
    assert np.count_nonzero(np.diff(block.bit("D2").astype(int))) > 100


def test_an_analog_stream_is_in_volts_with_millivolt_lines_scaled():
    with sigrok.Acquisition("demo", ["A0", "A1"], 10_000, max_samples=3000) as acquisition:
        block = join_blocks(list(acquisition.blocks()))
    assert block.samples == 3000 and block.analog["A0"].dtype == np.float32
    assert acquisition.units == {"A0": "V", "A1": "V"}
    assert set(np.unique(block.analog["A0"])) == {-10.0, 10.0}  # the demo's square wave
    a1 = block.analog["A1"]  # the demo's sine, 10 V peak: its zero is printed as "0.0 mV"
    assert a1[0] == 0.0 and 9.9 < a1.max() <= 10.0 and -10.0 <= a1.min() < -9.9


def test_stop_from_outside_ends_the_stream_cleanly():
    acquisition = sigrok.Acquisition("demo", ["D0"], 1e6)
    with acquisition:
        for _ in acquisition.blocks():
            if acquisition.samples > 100_000:
                acquisition.stop()
    assert acquisition.samples > 100_000
    assert acquisition._process is not None and acquisition._process.returncode == 0


def test_an_instrument_that_dies_mid_stream_is_said_at_once_and_its_samples_kept():
    acquisition = sigrok.Acquisition("demo", ["D0", "D1"], 1e6)
    kept = []
    with acquisition, pytest.raises(sigrok.DeviceVanished) as vanished:
        for block in acquisition.blocks():
            kept.append(block)
            if acquisition.samples > 100_000 and acquisition._process is not None:
                os.kill(acquisition._process.pid, signal.SIGKILL)
    assert vanished.value.samples == sum(b.samples for b in kept) > 100_000
    assert join_blocks(kept).samples == vanished.value.samples  # no gap in what was kept
    assert "stopped sending" in str(vanished.value) and "\n" not in str(vanished.value)


def test_an_instrument_that_falls_silent_is_said_within_a_second():
    acquisition = sigrok.Acquisition("demo", ["D0"], 1e6)
    process = None
    try:
        with pytest.raises(sigrok.DeviceVanished) as vanished:
            for _ in acquisition.blocks():
                if acquisition.samples > 100_000 and process is None:
                    process = acquisition._process
                    assert process is not None
                    os.kill(process.pid, signal.SIGSTOP)  # alive but silent, as a hung USB device
        assert sigrok.STALL_S <= vanished.value.silent_s < 1.0
        assert "no samples for" in str(vanished.value)
    finally:
        acquisition.close()


def test_bad_channels_and_unknown_drivers_are_refused_in_one_line():
    with pytest.raises(sigrok.SigrokError, match=r"^demo: no channel D9 \(it has D0, D1"):
        sigrok.Acquisition("demo", ["D9"], 1e6).start()
    with pytest.raises(sigrok.SigrokError, match="not both"):
        sigrok.Acquisition("demo", ["D0", "A0"], 1e6)
    with pytest.raises(sigrok.SigrokError, match="nosuch") as refused:
        sigrok.scan("nosuch")
    assert "\n" not in str(refused.value)


def test_a_missing_sigrok_cli_says_how_to_get_it():
    with pytest.raises(sigrok.SigrokMissing, match="apt-get install sigrok-cli"):
        sigrok.scan(program="sigrok-cli-not-installed-here")
