"""``fha-studio bench import``: the command-line contract (options, SUMMARY.json keys, exit 2
with one line for bad input)."""

from __future__ import annotations

import json
import math

import pytest

from fha_studio.catalog import get_actuator
from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.hardware.sim.cn2 import Cn2Settings, VirtualBenchInstrument
from fha_studio.logic.paramfile import dump_parameter_file
from fha_studio.main import main as cli_main
from fha_studio.physics import AxisModel, ServoAxis
from fha_studio.recording import read_recording

CODE = "FHA-25C-50-US250"


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    """A capture of a move (.sr), its truth, and the drive's parameter file (pulse + sign)."""
    folder = tmp_path_factory.mktemp("bench")
    axis = ServoAxis(AxisModel.from_actuator(get_actuator(CODE), load_inertia_kgm2=0.3))
    axis.servo_on()
    instrument = VirtualBenchInstrument(axis, 200e3, Cn2Settings(pulse_form=1, speed_conversion_rpm=2000))
    instrument.record(0.03)
    axis.move_by_pulses(6000, speed_rad_s=6 * 2 * math.pi / 60)
    instrument.record(0.5)
    instrument.write(folder / "cn2.sr", "sr")
    instrument.write(folder / "cn2.csv", "csv")
    model = load_parameter_model("HA-655")
    values = {
        (i.mode, i.number): i.default for i in model if i.mode in ("tune", "system") and i.default is not None
    }
    values[("system", 1)] = 1
    values[("system", 9)] = 2000
    (folder / "params.toml").write_text(dump_parameter_file(model, values, CODE, "HA-655-2-200"))
    return folder, axis, instrument


def _signals(folder, form="sr"):
    path = folder / f"cn2.{form}"
    return [
        "--signal",
        f"encoder_a={path}#ENC_A",
        "--signal",
        f"encoder_b={path}#ENC_B",
        "--signal",
        f"encoder_z={path}#ENC_Z",
        "--signal",
        f"command_a={path}#CMD_A",
        "--signal",
        f"command_b={path}#CMD_B",
        "--signal",
        f"in_position={path}#IN_POS",
        "--signal",
        f"speed_monitor={path}#SPD_MON",
    ]


def test_import_writes_the_recording_and_the_summary(bench, tmp_path, capsys):
    folder, axis, instrument = bench
    code = cli_main(
        [
            "bench",
            "import",
            "--actuator",
            CODE,
            "--parameters",
            str(folder / "params.toml"),
            *_signals(folder),
            "-o",
            str(tmp_path / "rec.csv"),
            "--json",
            str(tmp_path / "s.json"),
        ]
    )
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "encoder: " in out and "command: 6000 counts" in out
    summary = json.loads((tmp_path / "s.json").read_text())
    for key in (
        "samples",
        "duration_s",
        "sample_rate_hz",
        "roles",
        "encoder",
        "command_counts",
        "speed_offset_v",
    ):
        assert key in summary
    assert summary["sample_rate_hz"] == 200e3 and summary["command_counts"] == 6000 == axis.command_pulses
    assert set(summary["encoder"]) >= {
        "counts",
        "glitches",
        "illegal_transitions",
        "z_pulses",
        "z_count_errors",
    }
    truth = instrument.truth.arrays()["encoder_counts"]
    assert summary["encoder"]["counts"] == truth[-1] - truth[0]
    assert summary["roles"]["speed_monitor"]["source"] == f"{folder / 'cn2.sr'}#SPD_MON"
    assert summary["roles"]["speed_monitor"]["scale"] == 200.0  # 2000 r/min at 10 V
    recording = read_recording(tmp_path / "rec.csv")
    assert not recording.has_current and recording.in_pos is not None
    assert recording.pos_deg[-1] == pytest.approx((truth[-1] - truth[0]) * 360 / 500000)


def test_a_current_probe_gives_the_current_column(bench, tmp_path, capsys):
    folder, _, _ = bench
    code = cli_main(
        [
            "bench",
            "import",
            "--actuator",
            CODE,
            "--parameters",
            str(folder / "params.toml"),
            *_signals(folder, "csv"),
            "--signal",
            f"current_probe={folder / 'cn2.csv'}#SPD_MON",
            "--current-scale",
            "2",
            "-o",
            str(tmp_path / "rec.csv"),
        ]
    )
    assert code == 0, capsys.readouterr().err
    recording = read_recording(tmp_path / "rec.csv")
    assert recording.has_current
    assert recording.metadata.extra["source_current"].endswith("#SPD_MON, 2 A/V")


@pytest.mark.parametrize(
    ("change", "expect"),
    [
        (["--signal", "torque=x.sr"], "unknown role 'torque'"),
        (["--signal", "encoder_a={folder}/cn2.sr#NOPE"], "has no channel 'NOPE' (it has ENC_A"),
        (["--signal", "speed_monitor={folder}/cn2.sr"], "the file has 12 channels"),
        (["--signal", "speed_monitor={folder}/params.toml#X"], "params.toml: line 3: no time column"),
        (["--current-scale", "2"], "--current-scale without --signal current_probe"),
        (["--signal", "current_probe={folder}/cn2.sr#SPD_MON"], "needs --current-scale A_PER_V"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(bench, tmp_path, capsys, change, expect):
    folder, _, _ = bench
    signals = _signals(folder)
    if change[0] == "--signal":  # the changed signal in place of the good one of its role
        role = change[1].partition("=")[0] + "="
        at = next((i for i, a in enumerate(signals) if a.startswith(role)), None)
        if at is not None:
            del signals[at - 1 : at + 1]
    args = [
        "bench",
        "import",
        "--actuator",
        CODE,
        "--parameters",
        str(folder / "params.toml"),
        *signals,
        *[c.format(folder=folder) for c in change],
        "-o",
        str(tmp_path / "rec.csv"),
    ]
    assert cli_main(args) == 2
    out, err = capsys.readouterr()
    assert expect in err and err.count("\n") == 1 and out == ""
    assert not (tmp_path / "rec.csv").exists()


def test_missing_parameters_are_named(bench, tmp_path, capsys):
    folder, _, _ = bench
    text = (folder / "params.toml").read_text()
    kept = [ln for ln in text.splitlines() if not ln.startswith("speed_conversion_factor")]
    (tmp_path / "p.toml").write_text("\n".join(kept) + "\n")
    assert (
        cli_main(
            [
                "bench",
                "import",
                "--actuator",
                CODE,
                "--parameters",
                str(tmp_path / "p.toml"),
                *_signals(folder),
                "-o",
                str(tmp_path / "rec.csv"),
            ]
        )
        == 2
    )
    err = capsys.readouterr().err
    assert "parameter 9 (speed conversion factor" in err and err.count("\n") == 1


def test_a_capture_too_slow_for_the_encoder_is_one_line_and_exit_2(bench, tmp_path, capsys):
    """The same move sampled at 25 kHz: the encoder's edges at the speed reached need more, and
    the command line names both figures instead of counting wrong; nothing is written."""
    from fha_studio.hardware.bench import writers
    from fha_studio.hardware.bench.capture import SampleBlock

    folder, _, instrument = bench
    block, every = instrument.capture(), 8
    writers.write_sr(tmp_path / "cn2.sr", SampleBlock(
        block.sample_rate_hz / every, block.logic_channels, block.logic[::every].copy(),
        {k: v[::every].copy() for k, v in block.analog.items()}))
    args = ["bench", "import", "--actuator", CODE, "--parameters", str(folder / "params.toml"),
            *_signals(tmp_path), "-o", str(tmp_path / "rec.csv"), "--json", str(tmp_path / "s.json")]
    assert cli_main(args) == 2
    out, err = capsys.readouterr()
    assert err.count("\n") == 1 and out == "", err
    assert "sample rate of 25 kHz cannot resolve the encoder" in err and "kHz of edges" in err
    assert not (tmp_path / "rec.csv").exists() and not (tmp_path / "s.json").exists()
