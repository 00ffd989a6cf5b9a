"""Tuning on the simulated drive over the client and the protocol (EXA/EXL/EXG and the trace at
the servo rate): measured against the loop's own linearisation, and the refusals (exit 4)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fha_studio.cli import main as cli_main
from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.tuning.excitation import plan_excitation
from fha_studio.logic.tuning.measure import NotExcitable, measure
from fha_studio.logic.tuning.response import estimate_response, find_resonance, inertia_from_plant
from fha_studio.logic.tuning.session import declared_model, measure_report, tuner_for

PARAMETERS = load_parameter_model("HA-655")
CODE = "FHA-25C-50-US250"


def _url(load: float, extra: str = "") -> str:
    return (f"sim://{CODE}?load_inertia={load}&effects=torsional_compliance&stepped=1&paced=0&quantised=0"
            f"{extra}")


def test_measured_over_the_protocol_matches_the_linearisation() -> None:
    own = declared_model(CODE, 0.0).actuator_inertia_kgm2
    load = 1.0 * own
    with DriveClient.open(_url(load)) as client:
        drive = client.transaction.transport.inner.sim_drive
        client.servo(True)
        tuner = tuner_for(client, PARAMETERS, declared_model(CODE, load), quantised_feedback=False)
        lm = tuner.loop({})
        plan = plan_excitation(lm)
        records = measure(client, plan, tuner.servo_rate_hz, drive.advance)
        assert not drive.excitation.active
    for which, recs in (("closed", records.closed_loop()), ("plant", records.plant())):
        measured = estimate_response(recs, records.sample_rate_hz, f_max_hz=plan.f_max_hz)
        mag, phase = lm.response(which, measured.freq_hz)
        ok = measured.trusted()
        assert ok.sum() > 0.8 * len(ok)
        assert np.max(np.abs(measured.magnitude_db - mag)[ok]) <= 1.0
        assert np.max(np.abs((measured.phase_deg - phase + 180.0) % 360.0 - 180.0)[ok]) <= 5.0
    plant = estimate_response(records.plant(), records.sample_rate_hz, f_max_hz=plan.f_max_hz)
    found = find_resonance(plant)
    from fha_studio.logic.tuning.linear import two_mass_prediction

    assert found.resonance_hz == pytest.approx(two_mass_prediction(tuner.model).resonance_hz, rel=0.1)
    inertia = inertia_from_plant(plant, tuner.model.torque_constant_nm_per_a, found)
    assert inertia == pytest.approx(tuner.model.total_inertia_kgm2, rel=0.1)


def test_measure_report_has_the_contract_keys() -> None:
    with DriveClient.open(_url(0.81)) as client:
        drive = client.transaction.transport.inner.sim_drive
        client.servo(True)
        tuner = tuner_for(client, PARAMETERS, declared_model(CODE, 0.81))
        result = measure_report(client, tuner, drive.advance)
    for key in ("resonance_hz", "antiresonance_hz", "load_inertia_estimate_kgm2", "gain_margin_db",
                "phase_margin_deg", "crossover_hz", "bandwidth_hz"):
        assert key in result
    assert set(result["frequency_response"]) == {"freq_hz", "magnitude_db", "phase_deg", "coherence"}
    json.dumps(result)


def test_servo_off_is_refused_and_nothing_moves() -> None:
    with DriveClient.open(_url(0.81)) as client:
        drive = client.transaction.transport.inner.sim_drive
        before = drive.axis.output_pos_rad
        tuner = tuner_for(client, PARAMETERS, declared_model(CODE, 0.81))
        with pytest.raises(NotExcitable, match="servo is off"):
            measure(client, plan_excitation(tuner.loop({})), tuner.servo_rate_hz, drive.advance)
        drive.advance(0.5)
        assert drive.axis.output_pos_rad == before


@pytest.mark.parametrize("extra", ["&profile=documented", ""])
def test_cli_exit_4_when_the_drive_cannot_be_excited(extra: str, capsys: pytest.CaptureFixture[str]) -> None:
    code = cli_main(["tune", "measure", "--url", _url(0.81, extra), "--actuator", CODE,
                     "--load-inertia", "0.81"])
    assert code == 4
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert ("servo is off" in err[0]) or ("front-panel" in err[0])
