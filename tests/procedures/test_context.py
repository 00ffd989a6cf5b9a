"""The catalogue fills the procedures in: the values of each actuator reach the steps."""

from __future__ import annotations

import pytest

from fha_studio.catalog import ModelCodeError, all_model_codes
from fha_studio.logic.procedures import ProcedureRun, ProcedureSession, load_all, load_procedure
from fha_studio.logic.procedures.context import build_context
from tests.procedures.conftest import _context
from tests.procedures.walk import walk


def test_catalogue_context_matches_the_hand_written_one():
    built = build_context("FHA-25C-50-US250-B-L")
    hand = _context()
    for part in ("output_flange", "flange"):
        want = hand["tightening"][part]
        got = built["tightening"][part]
        assert got["screws"] == want["screws"]
        assert float(got["torque_nm"]) == want["torque_nm"]
        assert float(got["torque_kgf_cm"]) == want["torque_kgf_cm"]  # as the manual prints it
        assert (got["torque_min_nm"], got["torque_max_nm"]) == (want["torque_min_nm"], want["torque_max_nm"])
    brake = built["brake"]
    assert (brake["supply_min_v"], brake["supply_max_v"]) == (21.6, 26.4)
    assert (brake["activating_current_a"], brake["holding_current_a"], brake["holding_torque_nm"]) == (
        1.1,
        0.15,
        "49",
    )
    assert built["drivers"] == ["HA-655-2-200", "HA-675-2-200"]
    assert built["flags"] == {**built["flags"], "brake": True, "sensor_set": True, "incremental": True}
    assert [(r["color"], r["signal"]) for r in built["cables"]["motor"]] == [
        (r["color"], r["signal"]) for r in hand["cables"]["motor"]
    ]
    assert len(built["cables"]["encoder_incremental_14"]) == 14 and built["cables"]["encoder_absolute"] == []
    assert built["environment"]["cable_bending_radius_min_mm"] == 40


def test_the_options_choose_the_tables():
    plain = build_context("FHA-17C-100-S248")
    assert "brake" not in plain and plain["flags"]["absolute"]
    assert [r["signal"] for r in plain["cables"]["motor"]][4:6] == ["No connection", "No connection"]
    assert {"BAT+", "BAT-", "CLR"} <= {r["signal"] for r in plain["cables"]["encoder_absolute"]}
    assert plain["tightening"]["output_flange"]["screws"] == "6-M5 depth: 8"
    assert plain["sensor_set"]["cw_limit_deg"] == 170.0 and plain["sensor_set"]["certain"] is False
    big = build_context("FHA-40C-160-US250-B")
    assert big["brake"]["holding_torque_nm"] == "345" and big["brake"]["activating_current_a"] == 1.3
    assert big["tightening"]["output_flange"]["torque_nm"] == "45"


@pytest.mark.parametrize("code", ["FHA-17C-50-US250-B-L", "FHA-32C-160-S248-B-L", "FHA-40C-100-US250"])
def test_every_procedure_walks_for_catalogue_actuators(code, tmp_path):
    context = build_context(code)
    session = ProcedureSession(actuator_code=code, operator="T")
    session.save(tmp_path / "s.json")
    for procedure in load_all(context):
        if procedure.applies:
            walk(ProcedureRun(session, procedure))
            assert session.runs[procedure.id].status == "completed"


def test_every_model_code_fills_every_procedure_in():
    for code in all_model_codes()[::7]:
        context = build_context(code + "-B-L")
        assert all(p.steps for p in load_all(context)), code


def test_a_wrong_code_says_what_is_wrong():
    with pytest.raises(ModelCodeError):
        build_context("FHA-99C-50-US250")
    with pytest.raises(ModelCodeError):
        load_procedure("wiring", build_context("FHA-40C-50-US250-A"))
