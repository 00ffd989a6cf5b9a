"""``fha-studio bench devices`` and ``bench record`` on sigrok-cli's demo driver: the contract's
options, exit 2 with one line for bad input, exit 3 with one line when the instrument vanishes and
the partial recording kept."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from fha_studio.hardware.bench.readers import read_capture
from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.paramfile import dump_parameter_file
from fha_studio.main import main as cli_main
from fha_studio.recording import read_recording

pytestmark = pytest.mark.skipif(shutil.which("sigrok-cli") is None, reason="sigrok-cli is not installed")
CODE = "FHA-25C-50-US250"


def test_devices_lists_the_demo_driver_in_words_and_as_json(capsys):
    assert cli_main(["bench", "devices", "--driver", "demo"]) == 0
    said = capsys.readouterr().out
    assert said == "demo: Demo device; logic D0 D1 D2 D3 D4 D5 D6 D7; analog A0 A1 A2 A3 A4\n"
    small = "demo:logic_channels=2:analog_channels=1"
    assert cli_main(["bench", "devices", "--driver", small, "--json"]) == 0
    (device,) = json.loads(capsys.readouterr().out)
    assert device["device"] == "demo" and device["channels"] == ["D0", "D1", "A0"]
    assert device["logic_channels"] == ["D0", "D1"] and device["analog_channels"] == ["A0"]


def test_record_without_decoding_writes_the_raw_channels_as_a_capture_file(tmp_path: Path, capsys):
    out = tmp_path / "raw.csv"
    code = cli_main(["bench", "record", "--device", "demo", "--signal", "encoder_a=D3", "--signal",
                     "encoder_b=D1", "--seconds", "0.25", "--rate", "400000", "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    capture = read_capture(out)
    assert (capture.samples, capture.sample_rate_hz, capture.channels) == (100_000, 400e3, ("D3", "D1"))
    assert "100000 samples at 400 kHz (0.25 s) from demo written raw" in capsys.readouterr().out
    assert out.read_text().splitlines()[1] == "; from demo through sigrok-cli (fha-studio bench record)"


def test_record_with_the_actuator_and_parameters_decodes_into_a_recording(tmp_path: Path, capsys):
    model = load_parameter_model("HA-655")
    values = {(i.mode, i.number): i.default for i in model
              if i.mode in ("tune", "system") and i.default is not None}
    params = tmp_path / "params.toml"
    params.write_text(dump_parameter_file(model, values, CODE, "HA-655-2-200"))
    out, summary = tmp_path / "rec.csv", tmp_path / "summary.json"
    code = cli_main(["bench", "record", "--device", "demo", "--signal", "encoder_a=D0", "--signal",
                     "encoder_b=D1", "--seconds", "0.2", "--actuator", CODE, "--parameters", str(params),
                     "-o", str(out), "--json", str(summary)])
    assert code == 0, capsys.readouterr().err
    recording = read_recording(out)
    assert set(recording.channels) == {"t", "pos"}
    assert recording.metadata.extra["source_pos"].startswith("demo#D0 and demo#D1, x4")
    assert recording.metadata.extra["recorded_by"] == "fha-studio bench record"
    facts = json.loads(summary.read_text())
    assert facts["samples"] == 40_000 and facts["complete"] is True and facts["sample_rate_hz"] == 200e3
    # the demo's pattern is no encoder: its counts and illegal transitions are what decoding found
    assert facts["encoder"]["illegal_transitions"] > 0
    assert np.isclose(recording.channels["pos"][-1] * 500_000 / 360, facts["encoder"]["counts"], atol=200)


@pytest.mark.parametrize(("args", "said"), [
    (["--signal", "encoder_x=D0"], "unknown role 'encoder_x'"),
    (["--signal", "encoder_a"], "expected ROLE=CHANNEL"),
    (["--signal", "encoder_a=D9"], "demo: no channel D9 (it has D0"),
    (["--signal", "encoder_a=D0", "--signal", "speed_monitor=A0"], "logic channels (D0, D1, ...) or analog"),
    (["--signal", "encoder_a=D0", "--actuator", CODE], "--actuator without --parameters"),
    (["--signal", "encoder_a=D0", "--device", "nosuch"], "Driver nosuch not found"),
    (["--signal", "encoder_a=D0", "--seconds", "0"], "--seconds: 0 is outside more than 0"),
])
def test_bad_input_is_refused_with_one_line_and_exit_2(tmp_path: Path, capsys, args, said):
    options = {"--device": "demo", "--seconds": "0.1"}
    signals = []
    for name, value in zip(args[::2], args[1::2], strict=True):
        if name in options:
            options[name] = value
        else:
            signals += [name, value]
    argv = ["bench", "record", *signals, *(x for item in options.items() for x in item),
            "-o", str(tmp_path / "x.csv")]
    try:
        code = cli_main(argv)
    except SystemExit as exc:  # argparse's refusal of a value
        code = int(exc.code or 0)
    err = capsys.readouterr().err
    assert code == 2 and said in err and err.count("\n") == 1, err
    assert not (tmp_path / "x.csv").exists()


def _sigrok_child(pid: int) -> int | None:
    for task in Path(f"/proc/{pid}/task").iterdir():
        for child in (task / "children").read_text().split():
            cmdline = Path(f"/proc/{child}/cmdline").read_bytes()
            if b"--continuous" in cmdline:
                return int(child)
    return None


def test_an_instrument_that_vanishes_mid_recording_exits_3_in_one_line_and_keeps_what_came(tmp_path: Path):
    out = tmp_path / "partial.csv"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    process = subprocess.Popen([sys.executable, "-m", "fha_studio", "bench", "record", "--device", "demo",
                                "--signal", "encoder_a=D0", "--signal", "encoder_b=D1", "--seconds", "60",
                                "-o", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    try:
        deadline = time.monotonic() + 30
        child = None
        while child is None and time.monotonic() < deadline:
            child = _sigrok_child(process.pid)
            if child is None:
                with pytest.raises(subprocess.TimeoutExpired):
                    process.wait(timeout=0.05)
        assert child is not None, "sigrok-cli never started streaming"
        with pytest.raises(subprocess.TimeoutExpired):
            process.wait(timeout=0.3)  # let samples come
        killed_at = time.monotonic()
        os.kill(child, signal.SIGKILL)  # as an instrument unplugged
        _, stderr = process.communicate(timeout=30)
        said_after = time.monotonic() - killed_at
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert process.returncode == 3, stderr
    lines = stderr.decode().splitlines()
    assert len(lines) == 1 and "demo: the instrument stopped sending" in lines[0], lines
    assert f"kept in {out}" in lines[0]
    capture = read_capture(out)
    assert capture.samples > 0 and f"{capture.samples} samples before are kept" in lines[0]
    assert said_after < 30  # a ceiling only a hang reaches: the library's test times the saying
