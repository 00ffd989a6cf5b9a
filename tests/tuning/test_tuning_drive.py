"""Tuning on the simulated drive over the client and the protocol (EXA/EXL/EXG and the trace at
the servo rate), what tuning promises: for FHA-17C-100, FHA-25C-50 and FHA-40C-160 with a load of
0, 1, 3 and 10 x the actuator's own inertia, the measured response within 1 dB and 5 deg of the
loop's own linearisation wherever the coherence is at least 0.9, the resonance within 10 % of the
two-mass prediction, the inertia within 10 %; and the refusals (exit 4, nothing moves)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fha_studio.cli import main as cli_main
from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.tuning.excitation import plan_excitation
from fha_studio.logic.tuning.linear import two_mass_prediction
from fha_studio.logic.tuning.measure import NotExcitable, measure
from fha_studio.logic.tuning.response import estimate_response, fit_two_mass
from fha_studio.logic.tuning.session import declared_model, measure_report, tuner_for

PARAMETERS = load_parameter_model("HA-655")
CODE = "FHA-25C-50-US250"
ACTUATORS = ("FHA-17C-100-US250", "FHA-25C-50-US250", "FHA-40C-160-S248")


def _url(code: str, load: float, extra: str = "") -> str:
    return (f"sim://{code}?load_inertia={load}&effects=torsional_compliance&stepped=1&paced=0&quantised=0"
            f"{extra}")


def _sim(client: DriveClient):  # the embedded drive behind the client's port
    return client.transaction.transport.inner.sim_drive


@pytest.mark.slow
@pytest.mark.parametrize("load_ratio", [0.0, 1.0, 3.0, 10.0])
@pytest.mark.parametrize("code", ACTUATORS)
def test_measured_over_the_protocol_matches_the_linearisation(code: str, load_ratio: float) -> None:
    load = load_ratio * declared_model(code, 0.0).actuator_inertia_kgm2
    with DriveClient.open(_url(code, load)) as client:
        drive = _sim(client)
        client.servo(True)
        tuner = tuner_for(client, PARAMETERS, declared_model(code, load), quantised_feedback=False)
        lm = tuner.loop({})
        plan = plan_excitation(lm)
        records = measure(client, plan, tuner.servo_rate_hz, drive.advance, lambda: drive.clock_s,
                          output_ppr=tuner.model.output_resolution_ppr)
        assert not drive.excitation.active
    assert records.travel_deg() <= plan.travel_bound_deg
    for which, recs in (("closed", records.closed_loop()), ("plant", records.plant())):
        measured = estimate_response(recs, records.sample_rate_hz, f_max_hz=plan.f_max_hz)
        mag, phase = lm.response(which, measured.freq_hz)
        ok = measured.trusted()
        assert ok.sum() > 0.8 * len(ok)
        assert np.max(np.abs(measured.magnitude_db - mag)[ok]) <= 1.0
        assert np.max(np.abs((measured.phase_deg - phase + 180.0) % 360.0 - 180.0)[ok]) <= 5.0
    plant = estimate_response(records.plant(), records.sample_rate_hz, f_max_hz=plan.f_max_hz)
    fit = fit_two_mass(plant, records.sample_rate_hz)
    assert fit is not None
    predicted = two_mass_prediction(tuner.model)
    if load_ratio > 0:
        assert fit.resonance_hz == pytest.approx(predicted.resonance_hz, rel=0.1)
        assert fit.antiresonance_hz == pytest.approx(predicted.antiresonance_hz, rel=0.1)
    else:  # the flange alone (2 % of J_A): resonance and anti-resonance 1 % apart, nothing to see
        assert fit.resonance_hz is None or fit.resonance_hz == pytest.approx(predicted.resonance_hz, rel=0.1)
    assert fit.total_inertia_kgm2 == pytest.approx(tuner.model.total_inertia_kgm2, rel=0.1)


def test_measure_report_has_the_contract_keys() -> None:
    with DriveClient.open(_url(CODE, 0.81)) as client:
        drive = _sim(client)
        client.servo(True)
        tuner = tuner_for(client, PARAMETERS, declared_model(CODE, 0.81))
        result = measure_report(client, tuner, drive.advance, lambda: drive.clock_s)
    for key in ("resonance_hz", "antiresonance_hz", "load_inertia_estimate_kgm2", "gain_margin_db",
                "phase_margin_deg", "crossover_hz", "bandwidth_hz"):
        assert key in result
    assert set(result["frequency_response"]) == {"freq_hz", "magnitude_db", "phase_deg", "coherence"}
    assert result["load_inertia_estimate_kgm2"] == pytest.approx(0.81, rel=0.1)
    json.dumps(result)


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
