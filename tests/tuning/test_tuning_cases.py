"""Tuning's acceptance cases on the simulated drive, for FHA-17C-100, FHA-25C-50 and FHA-40C-160 with a
load of 0, 1, 3 and 10 x the actuator's own inertia (FHA-C manual 2-1 allows about 3 x):

- the measured response (closed loop and plant) within 1 dB and 5 deg of the simulated loop's own
  linearisation wherever the coherence is at least 0.9;
- the resonance within 10 % of the two-mass prediction (the catalogue's K1 and the declared load),
  the load inertia estimate within 10 %;
- the proposed standard gains meet their margins (gain margin >= 8 dB, phase margin >= 45 deg),
  and, written to the drive (backup first, verified), settle the 90 deg verification move no slower
  than the defaults did, overshooting at most 10 %, without an alarm; at 10 x the proposal says
  the load is beyond 2-1 and tunes softer (no stiffer a speed loop than the present one).

Each case is measured once (module-scoped fixture) and its figures asserted by three tests. The
measurement goes the command line's way (``measure_report`` with ``drive_clock``: the stepped
drive's own time, no clock of the computer) on a drive with ideal feedback, whose linearisation is
exact; the proposal is applied on a drive whose loops see whole encoder pulses, as a real one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.parameters import Mode, load_parameter_model
from fha_studio.logic.tuning.linear import two_mass_prediction
from fha_studio.logic.tuning.move import MoveAlarm, MoveFigures
from fha_studio.logic.tuning.propose import AIMS, ALLOWED_LOAD_RATIO, Proposal, screen_margins
from fha_studio.logic.tuning.response import COHERENCE_TRUSTED
from fha_studio.logic.tuning.session import (
    backup_parameters,
    declared_model,
    drive_clock,
    measure_report,
    tuner_for,
    verify_move,
    write_tune_items,
)

PARAMETERS = load_parameter_model("HA-655")
ACTUATORS = ("FHA-17C-100-US250", "FHA-25C-50-US250", "FHA-40C-160-S248")
LOAD_RATIOS = (0.0, 1.0, 3.0, 10.0)
CASES = [(code, ratio) for code in ACTUATORS for ratio in LOAD_RATIOS]


@dataclass
class Case:
    code: str
    ratio: float
    model: Any
    measured: dict[str, Any]
    linear: Any  # the LoopModel of the measured drive (ideal feedback)
    travel_ok: bool
    excitation_stopped: bool
    proposal: Proposal
    verified: bool
    before: MoveFigures | MoveAlarm
    after: MoveFigures | MoveAlarm
    alarm_after: int
    present_crossover_hz: float
    proposed_crossover_hz: float


def _url(code: str, load: float, quantised: bool) -> str:
    return (f"sim://{code}?load_inertia={load}&effects=torsional_compliance&stepped=1&paced=0"
            f"&quantised={int(quantised)}")


def _sim(client: DriveClient):  # the embedded drive behind the client's port
    return client.transaction.transport.inner.sim_drive


def _move(client: DriveClient, tuner: Any, pace: Any) -> MoveFigures | MoveAlarm:
    try:
        return verify_move(client, PARAMETERS, tuner, pace)
    except MoveAlarm as alarm:  # the loop could not make the move (e.g. 20 overload): said so
        return alarm


def _crossover(tuner: Any, items: dict[str, int]) -> float:
    grid = np.logspace(-1.0, math.log10(0.49 * tuner.servo_rate_hz), 400)
    return screen_margins(tuner.loop(items).polynomials().speed_open_loop_at(grid), grid)[2]


def run_case(code: str, ratio: float, backup_dir: Path) -> Case:
    """Measure, propose, apply and verify one case (benchmarks/tuning_cases.py prints them all)."""
    load = ratio * declared_model(code, 0.0).actuator_inertia_kgm2
    model = declared_model(code, load)
    with DriveClient.open(_url(code, load, quantised=False)) as client:
        drive = _sim(client)
        client.servo(True)
        pace, now = drive_clock(client)
        tuner = tuner_for(client, PARAMETERS, model, quantised_feedback=False)
        measured = measure_report(client, tuner, pace, now)
        stopped = not drive.excitation.active
        linear = tuner.loop({})
    with DriveClient.open(_url(code, load, quantised=True)) as client:
        client.servo(True)
        pace, _now = drive_clock(client)
        tuner = tuner_for(client, PARAMETERS, model)
        proposal = tuner.propose("standard")
        backup = backup_parameters(client, PARAMETERS, code, backup_dir / "backup.toml")
        assert backup.exists()
        entries = write_tune_items(client, PARAMETERS, proposal.proposed.items)
        verified = all(e["verified"] for e in entries) and all(
            client.read_parameter(Mode.TUNE, PARAMETERS.by_key(k).number) == v
            for k, v in proposal.proposed.items.items())
        after = _move(client, tuner_for(client, PARAMETERS, model), pace)
        alarm_after = client.alarm()
        # then the defaults again (a loop that trips on them must not spoil the proposal's move)
        write_tune_items(client, PARAMETERS, proposal.present.items)
        before = _move(client, tuner_for(client, PARAMETERS, model), pace)
    excitation = measured["excitation"]
    travel_ok = excitation["travelled_deg"] <= excitation["travel_bound_deg"]
    crossovers = (_crossover(tuner, proposal.present.items), _crossover(tuner, proposal.proposed.items))
    return Case(code, ratio, model, measured, linear, travel_ok, stopped, proposal, verified, before, after,
                alarm_after, *crossovers)


@pytest.fixture(scope="module", params=CASES, ids=[f"{c}-{r:g}x" for c, r in CASES])
def case(request, tmp_path_factory) -> Case:
    code, ratio = request.param
    return run_case(code, ratio, tmp_path_factory.mktemp("backup"))


def test_measured_response_matches_the_loops_linearisation(case: Case) -> None:
    assert case.excitation_stopped and case.travel_ok
    for which, key in (("closed", "frequency_response"), ("plant", "plant_response")):
        data = case.measured[key]
        f = np.asarray(data["freq_hz"])
        trusted = np.asarray(data["coherence"]) >= COHERENCE_TRUSTED
        assert trusted.sum() > 0.8 * len(f), which
        mag, phase = case.linear.response(which, f)
        assert np.max(np.abs(np.asarray(data["magnitude_db"]) - mag)[trusted]) <= 1.0, which
        phase_error = (np.asarray(data["phase_deg"]) - phase + 180.0) % 360.0 - 180.0
        assert np.max(np.abs(phase_error)[trusted]) <= 5.0, which


def test_resonance_and_load_inertia_from_the_response(case: Case) -> None:
    predicted = two_mass_prediction(case.model)
    found = case.measured["resonance_hz"]
    assert case.measured["predicted_resonance_hz"] == pytest.approx(predicted.resonance_hz)
    if case.ratio > 0:
        assert found == pytest.approx(predicted.resonance_hz, rel=0.1)
        assert case.measured["antiresonance_hz"] == pytest.approx(predicted.antiresonance_hz, rel=0.1)
        estimate = case.measured["load_inertia_estimate_kgm2"]
        assert estimate == pytest.approx(case.model.load_inertia_kgm2, rel=0.1)
    else:  # the flange alone (2 % of J_A): resonance and anti-resonance 1 % apart, nothing to see
        assert found is None or found == pytest.approx(predicted.resonance_hz, rel=0.1)
        # no load: the estimate within 10 % of the actuator's own inertia of zero
        assert abs(case.measured["load_inertia_estimate_kgm2"]) <= 0.1 * case.model.actuator_inertia_kgm2


def test_standard_proposal_meets_its_margins_and_settles_no_slower(case: Case) -> None:
    proposal = case.proposal
    assert proposal.proposed.meets(*AIMS["standard"])
    assert proposal.proposed.items != proposal.present.items
    beyond = case.ratio > ALLOWED_LOAD_RATIO
    assert (proposal.warning is not None) is beyond
    if beyond:  # the page says so and tunes softer: a speed loop no stiffer than the present one
        assert "2-1" in (proposal.warning or "") and "softer" in (proposal.warning or "")
        assert case.proposed_crossover_hz <= case.present_crossover_hz
    assert case.verified
    after = case.after
    assert isinstance(after, MoveFigures), after
    assert case.alarm_after == 0
    assert after.settling_ms is not None and after.overshoot_pct <= 10.0
    before = case.before
    if isinstance(before, MoveFigures) and before.settling_ms is not None:
        assert after.settling_ms <= before.settling_ms
    # else the defaults did not settle within the trace, or the drive tripped on them: slower
