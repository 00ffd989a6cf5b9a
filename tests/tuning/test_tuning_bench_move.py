"""Where no analog output can drive SPD-CMD: the loop fitted to moves captured on CN2 (the command
pulses, the encoder outputs, SPD-MON) gives the load inertia within 10 %, says what a capture
without current cannot tell, and refuses a move the loop model does not follow; a verification
capture after the worksheet's items compared with their prediction.

The captures are the real path's: a stepped simulated drive (``SimDrive``, the manual's commands
only) carrying 1 x or 3 x the actuator's own inertia, moved by the controller's command pulses and
recorded on CN2 by the virtual bench instrument, imported as ``bench import`` does. The drive's
gains do not know the load (tune 0 is read on the actuator's own inertia, ``physics.PanelGains``),
so the fit, declared without the load, finds it in how the loop follows."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fha_studio.hardware.parameters import Mode, load_parameter_model
from fha_studio.hardware.sim.cn2 import VirtualBenchInstrument
from fha_studio.hardware.sim.drive import SimDrive
from fha_studio.logic.paramfile import dump_parameter_file
from fha_studio.logic.tuning.bench_move import verify_move
from fha_studio.logic.tuning.bench_session import RoleSignal, bench_move_report, bench_tuner, move_samples
from fha_studio.logic.tuning.session import declared_model
from fha_studio.main import main as cli_main

PARAMETERS = load_parameter_model("HA-655")
CODE = "FHA-25C-50-US250"
OWN = declared_model(CODE, 0.0).actuator_inertia_kgm2
#: the encoder's edges at 10 r/min (output) of a 500000-count output turn: 83 kHz
RATE_HZ = 250e3
CHANNELS = {"encoder_a": "ENC_A", "encoder_b": "ENC_B", "command_a": "CMD_A", "command_b": "CMD_B",
            "speed_monitor": "SPD_MON", "in_position": "IN_POS"}


def _values(**items: int) -> dict[tuple[str, int], int]:
    values = {(str(i.mode), i.number): int(i.default) for i in PARAMETERS
              if i.mode in (Mode.TUNE, Mode.SYSTEM) and i.default is not None}
    for key, value in items.items():
        item = PARAMETERS.by_key(key)
        values[(str(item.mode), item.number)] = value
    return values


def _capture(folder: Path, load: float, values: dict[tuple[str, int], int]) -> Path:
    """A move of +10 deg and back at 10 r/min, 200 r/min/s (the JOG acceleration, test item 1: the
    controller's profile), the drive set up with ``values``, recorded on CN2 as a sigrok session."""
    preset = tuple((mode, number, value) for (mode, number), value in values.items()
                   if PARAMETERS.item(Mode(mode), number).default != value)
    drive = SimDrive(CODE, profile="documented", stepped=True, eeprom=str(folder / "eeprom.json"),
                     load_inertia_kgm2=load, effects={"torsional_compliance": {}}, preset=preset)
    try:
        instrument = VirtualBenchInstrument.on_drive(drive, RATE_HZ)
        drive.set_servo(True)
        instrument.record(0.05)
        drive.set_move_speed(10.0)
        for angle in (10.0, -10.0):
            drive.controller_command(angle)
            instrument.record(0.7)
        assert drive.alarm == 0
        return instrument.write(folder / "move.sr", "sr")
    finally:
        drive.close()


def _signals(path: Path) -> list[RoleSignal]:
    return [RoleSignal(role, str(path), channel) for role, channel in CHANNELS.items()]


def test_the_load_inertia_from_a_move_at_three_times_the_actuators_own(tmp_path: Path) -> None:
    load = 3.0 * OWN
    capture = _capture(tmp_path, load, _values())
    tuner = bench_tuner(CODE, 0.0, PARAMETERS, _values())  # declared without the load
    result = bench_move_report(tuner, _signals(capture), _values())
    assert result["load_inertia_estimate_kgm2"] == pytest.approx(load, rel=0.1)
    assert 0.0 < result["load_inertia_uncertainty_kgm2"] < 0.1 * load
    assert result["fit"]["position_rms_counts"] < 5.0  # of a following error of about 2000 counts
    measured, predicted = result["move"]["measured"], result["move"]["predicted"]
    assert predicted["following_error_peak_counts"] == pytest.approx(measured["following_error_peak_counts"],
                                                                     rel=0.02)
    assert any("load torque" in note for note in result["notes"])
    assert result["phase_margin_deg"] > 0 and result["frequency_response"]["coherence"] == []


def test_cli_analyse_fits_a_move(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    capture = _capture(tmp_path, OWN, _values())
    params = tmp_path / "params.toml"
    params.write_text(dump_parameter_file(PARAMETERS, _values(), CODE, "HA-655-2-200"))
    out = tmp_path / "fit.json"
    argv = ["tune", "analyse", "--actuator", CODE, "--parameters", str(params), "--load-inertia", "0",
            "--json", str(out)]
    for role, channel in CHANNELS.items():
        argv += ["--signal", f"{role}={capture}#{channel}"]
    assert cli_main(argv) == 0, capsys.readouterr().err
    result = json.loads(out.read_text())
    for key in ("resonance_hz", "antiresonance_hz", "load_inertia_estimate_kgm2", "gain_margin_db",
                "phase_margin_deg", "crossover_hz", "bandwidth_hz", "frequency_response"):
        assert key in result
    assert result["load_inertia_estimate_kgm2"] == pytest.approx(OWN, rel=0.1)
    assert "cannot be told" in capsys.readouterr().out
    capsys.readouterr()
    # the same capture without the command pulses: one line, exit 2
    argv = ["tune", "analyse", "--actuator", CODE, "--parameters", str(params), "--load-inertia", "0",
            "--signal", f"encoder_a={capture}#ENC_A", "--signal", f"encoder_b={capture}#ENC_B"]
    assert cli_main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "command_a" in err[0]


def test_a_verification_capture_against_the_worksheets_prediction(tmp_path: Path) -> None:
    """The proposal typed on the front panel (here: a stiffer position loop), a move captured with
    it, compared with what the loop predicts for those items on the declared axis."""
    typed = {"position_loop_gain": 60, "speed_loop_gain": 80}
    capture = _capture(tmp_path, 0.0, _values(**typed))
    tuner = bench_tuner(CODE, 0.0, PARAMETERS, _values())  # the items before the worksheet
    samples = move_samples(tuner, _signals(capture), _values(**typed))
    check = verify_move(tuner, typed, samples)
    assert check["items"]["position_loop_gain"] == 60
    peak = check["following_error_peak_counts"]
    assert peak["predicted"] == pytest.approx(peak["measured"], rel=0.02)
    assert check["difference_rms_counts"] < 0.01 * peak["measured"]
    # the items before the worksheet would have predicted another move: the comparison can fail
    before = verify_move(tuner, {}, samples)
    assert before["difference_rms_counts"] > 5 * check["difference_rms_counts"]
