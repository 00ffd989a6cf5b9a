"""Proposed gains applied on the simulated drive (quantised feedback, as a real drive): backup
first, verified writes, and a 90 deg move that settles no slower than with the defaults and
overshoots at most 10 %; beyond FHA-C manual 2-1 (10 x) the proposal is soft and says so."""

from __future__ import annotations

import json

import pytest

from fha_studio.cli import main as cli_main
from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.parameters import Mode, load_parameter_model
from fha_studio.logic.paramfile import load_parameter_file
from fha_studio.logic.tuning.propose import AIMS
from fha_studio.logic.tuning.session import (
    backup_parameters,
    declared_model,
    tuner_for,
    verify_move,
    write_tune_items,
)

PARAMETERS = load_parameter_model("HA-655")
ACTUATORS = ("FHA-17C-100-US250", "FHA-25C-50-US250", "FHA-40C-160-S248")


@pytest.mark.slow
@pytest.mark.parametrize("load_ratio", [0.0, 1.0, 3.0])
@pytest.mark.parametrize("code", ACTUATORS)
def test_applied_standard_gains_settle_a_90_deg_move_no_slower(code: str, load_ratio: float,
                                                               tmp_path) -> None:
    load = load_ratio * declared_model(code, 0.0).actuator_inertia_kgm2
    url = f"sim://{code}?load_inertia={load}&effects=torsional_compliance&stepped=1&paced=0"
    with DriveClient.open(url) as client:
        drive = client.transaction.transport.inner.sim_drive
        client.servo(True)
        tuner = tuner_for(client, PARAMETERS, declared_model(code, load))
        before = verify_move(client, PARAMETERS, tuner, drive.advance)
        proposal = tuner.propose("standard")
        assert proposal.warning is None
        assert proposal.proposed.meets(*AIMS["standard"])
        backup = backup_parameters(client, PARAMETERS, code, tmp_path / "backup.toml")
        saved = load_parameter_file(backup, PARAMETERS)
        assert saved is not None
        entries = write_tune_items(client, PARAMETERS, proposal.proposed.items)
        assert all(e["verified"] for e in entries)
        speed_gain = PARAMETERS.by_key("speed_loop_gain")
        wanted = proposal.proposed.items["speed_loop_gain"]
        assert client.read_parameter(Mode.TUNE, speed_gain.number) == wanted
        after = verify_move(client, PARAMETERS, tuner_for(client, PARAMETERS, tuner.model), drive.advance)
    assert before.settling_ms is not None and after.settling_ms is not None
    assert after.settling_ms <= before.settling_ms
    assert after.overshoot_pct <= 10.0


@pytest.mark.slow
@pytest.mark.parametrize("code", ACTUATORS)
def test_beyond_2_1_the_proposal_is_soft_and_says_so(code: str) -> None:
    model = declared_model(code, 10.0 * declared_model(code, 0.0).actuator_inertia_kgm2)
    url = f"sim://{code}?load_inertia={model.load_inertia_kgm2}&stepped=1&paced=0"
    with DriveClient.open(url) as client:
        proposal = tuner_for(client, PARAMETERS, model).propose("standard")
    assert proposal.used_aim == "soft"
    assert "2-1" in (proposal.warning or "")
    assert proposal.proposed.meets(*AIMS["soft"])
    assert proposal.proposed.overshoot_pct is not None and proposal.proposed.overshoot_pct <= 10.0


def test_cli_propose_prints_the_contract(tmp_path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "propose.json"
    code = cli_main(["tune", "propose", "--url", "sim://FHA-25C-50-US250?load_inertia=0.81&paced=0",
                     "--actuator", "FHA-25C-50-US250", "--load-inertia", "0.81", "--json", str(out)])
    assert code == 0
    result = json.loads(out.read_text())
    for side in ("present", "proposed"):
        for key in ("speed_loop_gain", "speed_loop_integral_compensation", "position_loop_gain",
                    "feed_forward_gain", "gain_margin_db", "phase_margin_deg", "overshoot_pct",
                    "settling_ms"):
            assert key in result[side]
    assert "measured" not in result
