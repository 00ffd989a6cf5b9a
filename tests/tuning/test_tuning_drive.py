"""Tuning on the simulated drive over the client and the protocol (EXA/EXL/EXG and the trace at
the servo rate): the command line's contract, STOP and the watchdog, waiting on the drive's own
time, and the refusals (exit 4, nothing moves). The twelve acceptance cases are in
test_tuning_cases.py."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from fha_studio.cli import main as cli_main
from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.errors import DriveRefused
from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.tuning.excitation import NotExcitable, plan_excitation
from fha_studio.logic.tuning.measure import measure
from fha_studio.logic.tuning.response import estimate_response
from fha_studio.logic.tuning.session import declared_model, tuner_for
from fha_studio.physics import catalogue_effects

PARAMETERS = load_parameter_model("HA-655")
CODE = "FHA-25C-50-US250"
ACTUATORS = ("FHA-17C-100-US250", "FHA-25C-50-US250", "FHA-40C-160-S248")


def _url(code: str, load: float, extra: str = "") -> str:
    return (f"sim://{code}?load_inertia={load}&effects=torsional_compliance&stepped=1&paced=0&quantised=0"
            f"{extra}")


def _sim(client: DriveClient):  # the embedded drive behind the client's port
    return client.transaction.transport.inner.sim_drive


def test_stp_and_servo_off_end_the_excitation() -> None:
    with DriveClient.open(_url(CODE, 0.81)) as client:
        drive = _sim(client)
        client.servo(True)
        client.set_excitation(0.2, 1.0)
        client.excite(4)
        drive.advance(0.05)
        assert drive.excitation.active
        client.stop()
        assert not drive.excitation.active
        client.excite(4)
        drive.advance(0.2)  # no renewal: the watchdog ends it as a jog's
        assert not drive.excitation.active
        client.excite(4)
        client.servo(False)
        drive.advance(0.01)
        assert not drive.excitation.active


def test_the_excitation_rides_on_a_jog_its_travel_limit_about_the_jogs_path() -> None:
    """EXG on a JOG (the bias speed that keeps a real axis off its friction's stick-slip): the
    axis turns far past the travel limit along the jog, the excitation runs on; a move refuses
    it; STP ends both."""
    with DriveClient.open(_url(CODE, 0.81, "&catalogue_friction=1")) as client:
        drive = _sim(client)
        client.servo(True)
        client.set_excitation(0.2, 0.5)
        start = drive.axis.output_pos_rad
        for _ in range(20):  # 1 s of a 3 r/min jog (its ramp and the loop's lag settle)
            client.jog(3.0)
            drive.advance(0.05)
        for _ in range(20):  # 1 s more, excited
            client.jog(3.0)
            client.excite(4)
            drive.advance(0.05)
            assert drive.excitation.active
        assert math.degrees(drive.axis.output_pos_rad - start) > 20.0  # 2 s at 18 deg/s, far past 0.5 deg
        client.stop()
        assert not drive.excitation.active
        drive.advance(0.5)
        client.move_by(10.0)
        with pytest.raises(DriveRefused, match="excitation"):
            client.excite(4)
        assert not drive.excitation.active


def test_servo_off_is_refused_and_nothing_moves() -> None:
    with DriveClient.open(_url(CODE, 0.81)) as client:
        drive = _sim(client)
        before = drive.axis.output_pos_rad
        tuner = tuner_for(client, PARAMETERS, declared_model(CODE, 0.81))
        with pytest.raises(NotExcitable, match="servo is off"):
            measure(client, plan_excitation(tuner.loop({})), tuner.servo_rate_hz, drive.advance,
                    lambda: drive.clock_s)
        drive.advance(0.5)
        assert drive.axis.output_pos_rad == before


@pytest.mark.parametrize("extra", ["&profile=documented", ""])
def test_cli_exit_4_when_the_drive_cannot_be_excited(extra: str, capsys: pytest.CaptureFixture[str]) -> None:
    code = cli_main(["tune", "measure", "--url", _url(CODE, 0.81, extra), "--actuator", CODE,
                     "--load-inertia", "0.81"])
    assert code == 4
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert ("servo is off" in err[0]) or ("front-panel" in err[0])


def test_cli_measure_runs_to_completion_with_the_contract(drives, tmp_path,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    """``tune measure`` as a script runs it, to the end: the servo switched on by the controller
    (``drives``), the excitation stated on stderr before it starts, bounded by --amplitude-rpm,
    waited for on the stepped drive's own time; exit 0, one line of figures, the contract's JSON."""
    out = tmp_path / "measure.json"
    code = cli_main(["tune", "measure", "--url", _url(CODE, 0.81), "--actuator", CODE,
                     "--load-inertia", "0.81", "--amplitude-rpm", "0.3", "--json", str(out)])
    said, err = capsys.readouterr()
    assert code == 0, err
    (drive,) = drives
    assert said.count("\n") == 1 and said.startswith("resonance ") and "load inertia" in said
    assert "excitation:" in err and "0.3 r/min" in err and "travels at most" in err
    assert "on a jog of" in err and "FWD" in err  # the bias speed, and how far it turns the axis
    result = json.loads(out.read_text())
    for key in ("resonance_hz", "antiresonance_hz", "load_inertia_estimate_kgm2", "gain_margin_db",
                "phase_margin_deg", "crossover_hz", "bandwidth_hz"):
        assert key in result, key
    response = result["frequency_response"]
    assert set(response) == {"freq_hz", "magnitude_db", "phase_deg", "coherence"}
    assert len({len(v) for v in response.values()}) == 1 and len(response["freq_hz"]) > 100
    assert result["excitation"]["amplitude_rpm"] == pytest.approx(0.3)
    # the two-mass resonance of the gear's spring and the load, and the load found again (10 %)
    assert result["resonance_hz"] == pytest.approx(result["predicted_resonance_hz"], rel=0.1)
    assert result["load_inertia_estimate_kgm2"] == pytest.approx(0.81, rel=0.1)
    assert result["phase_margin_deg"] > 0 and result["bandwidth_hz"] > 0
    assert not drive.excitation.active  # ended with the command


def test_in_place_on_friction_warns_of_stick_slip(drives, tmp_path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    """``tune measure --in-place`` (no bias speed) on a drive with the catalogue's friction: the axis
    sticks at each reversal, the response loses its gain at low frequency, and the measurement says why
    (the coherence would not: the stick-slip repeats with the periodic excitation). The same axis on
    its bias speed is in test_tuning_cases.py's friction cases."""
    out = tmp_path / "measure.json"
    url = _url(CODE, 0.81, "&catalogue_friction=1")
    code = cli_main(["tune", "measure", "--url", url, "--actuator", CODE, "--load-inertia", "0.81",
                     "--in-place", "--json", str(out)])
    _said, err = capsys.readouterr()
    assert code == 0, err
    result = json.loads(out.read_text())
    assert result["excitation"]["bias_rpm"] == 0.0 and "jog" not in err.split("\n")[0]
    assert "warning:" in err and "friction" in result["stick_slip_warning"]
    # the plant (torque -> speed) at its lowest bin far below the rigid body's 1/(J w): what the
    # stick-slip does to it (about 16 dB here; on a bias speed the response is within 1 dB of the
    # loop's linearisation, test_tuning_cases.py)
    plant = result["plant_response"]
    inertia = declared_model(CODE, 0.81).total_inertia_kgm2
    rigid_db = -20.0 * math.log10(inertia * 2.0 * math.pi * plant["freq_hz"][0])
    assert plant["magnitude_db"][0] < rigid_db - 6.0
    (drive,) = drives
    assert not drive.excitation.active and not drive.moving


def test_a_read_out_longer_than_the_watchdog_restarts_the_jog_before_the_excitation() -> None:
    """A link slower than the watchdog (a real line at 19200 baud takes seconds to read a record):
    the drive stops the excitation and the jog under it while a record is read, and the axis stops
    on its friction. Before the next record the jog runs steadily again before the excitation
    starts anew, so no record holds the restart: the response stays within test_tuning_cases.py's
    tolerances of the drive's linearisation (its viscous friction in it)."""
    model = declared_model(CODE, 0.81)
    with DriveClient.open(_url(CODE, 0.81, "&catalogue_friction=1")) as client:
        drive = _sim(client)
        client.servo(True)
        stopped_during_read_out = []

        def slow_read_out() -> float:  # each look at the clock around a read-out: 0.2 s of the drive's time
            drive.advance(0.2)
            stopped_during_read_out.append(not drive.excitation.active and not drive.moving)
            return drive.clock_s

        tuner = tuner_for(client, PARAMETERS, model, quantised_feedback=False)
        plan = plan_excitation(tuner.loop({}))
        records = measure(client, plan, tuner.servo_rate_hz, drive.advance, slow_read_out,
                          output_ppr=model.output_resolution_ppr,
                          jog_accel_rpm_s=tuner.items["jog_acceleration"])
        actual = tuner_for(client, PARAMETERS, model.replace(effects=catalogue_effects(model)),
                           quantised_feedback=False).loop({})
    assert plan.bias_rpm > 0 and any(stopped_during_read_out)
    assert records.reversal_share() == 0.0
    plant = estimate_response(records.plant(), records.sample_rate_hz, f_max_hz=plan.f_max_hz)
    trusted = plant.trusted()
    assert trusted.sum() > 0.8 * len(trusted)
    mag, phase = actual.response("plant", plant.freq_hz)
    assert np.max(np.abs(plant.magnitude_db - mag)[trusted]) <= 1.0
    assert np.max(np.abs((plant.phase_deg - phase + 180.0) % 360.0 - 180.0)[trusted]) <= 5.0
