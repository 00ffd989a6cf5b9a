"""What the model check refuses, what it cannot separate, and what it will not force onto a name."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from modelcheck_gen import moves_for, record, trapezoid_moves

from fha_studio.logic.modelcheck import ModelCheckError, run_modelcheck
from fha_studio.physics import AxisModel, Effects
from fha_studio.recording import Recording

CODE = "FHA-25C-50-US250"


@pytest.fixture(scope="module")
def plain():
    """A 4 s recording of FHA-25C-50 with Coulomb friction and an external load encoder."""
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    t, cmd = trapezoid_moves(moves_for(model, n_moves=4), 1000.0)
    effects = Effects().with_effect("coulomb_friction", torque_nm=5.0)
    return record(model, effects, t, cmd, actuator_code=CODE, with_load_pos=True).recording


def _with(rec: Recording, metadata: dict | None = None, **channels) -> Recording:
    meta = dataclasses.replace(rec.metadata, **(metadata or {}))
    return Recording(meta, {**rec.channels, **channels}, rec.source)


@pytest.mark.parametrize(
    ("declared", "words"),
    [
        ({"actuator": "FHA-25C-100-US250"}, "wrong actuator declared"),  # 1,000,000 pulses, 45 r/min
        ({"actuator": "FHA-25C-50-S248"}, "pulses per turn"),  # 409,600 pulses per turn
        ({"supply_voltage": 100}, "200 V actuator"),
    ],
)
def test_a_wrong_declared_actuator_is_refused(plain, declared, words):
    with pytest.raises(ModelCheckError, match=words) as err:
        run_modelcheck(_with(plain, declared), resimulate=False)
    assert "\n" not in str(err.value)


def test_garbage_columns_are_refused(plain):
    rng = np.random.default_rng(1)
    n = len(plain)
    with pytest.raises(ModelCheckError, match="'current' looks like noise"):
        run_modelcheck(_with(plain, current=rng.normal(0.0, 1.0, n)), resimulate=False)
    with pytest.raises(ModelCheckError, match="'pos' moves at"):
        run_modelcheck(_with(plain, pos=rng.uniform(-180, 180, n)), resimulate=False)
    with pytest.raises(ModelCheckError, match="'load_pos' differs from 'pos'"):
        run_modelcheck(_with(plain, load_pos=plain.pos_deg + rng.normal(0, 5, n)), resimulate=False)
    with pytest.raises(ModelCheckError, match="'current' reaches"):
        run_modelcheck(_with(plain, current=plain.current_a * 50), resimulate=False)
    with pytest.raises(ModelCheckError, match="hardly moves"):
        run_modelcheck(_with(plain, pos=np.zeros(n)), resimulate=False)
    with pytest.raises(ModelCheckError, match="'vel' does not match"):
        run_modelcheck(_with(plain, vel=rng.normal(0, 30, n)), resimulate=False)


def test_gravity_over_a_small_arc_is_not_separable_from_an_offset():
    # near the top of an unbalance (phase 90 deg), over +-4 deg, gravity is flat: it looks like an offset
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    moves = [(8.0, 3.0, 10.0, 0.3), (-8.0, 2.0, 20.0, 0.3), (6.0, 4.0, 15.0, 0.3), (-6.0, 1.5, 10.0, 0.3)] * 2
    t, cmd = trapezoid_moves(moves, 1000.0)
    cmd = cmd - math.radians(4.0)
    effects = Effects().with_effect("gravity_load", amplitude_nm=20.0, phase_deg=90.0)
    rec = record(model, effects, t, cmd, actuator_code=CODE).recording
    result = run_modelcheck(rec, resimulate=False)
    pairs = [{a.chosen, a.alternative} for a in result.ambiguities]
    assert {"gravity_load", "load_torque_offset"} in pairs, result.summary_lines()
    named = result.effects[0]
    assert named.id in ("gravity_load", "load_torque_offset")
    assert set(named.alternatives) == {"gravity_load", "load_torque_offset"} - {named.id}
    text = "\n".join(result.summary_lines())
    assert "not separable from this data" in text
    assert "half an output turn" in text  # the test that would separate them
    assert result.to_json()["not_separable"][0]["ids"] in (
        ["load_torque_offset", "gravity_load"],
        ["gravity_load", "load_torque_offset"],
    )


def test_a_structured_residual_no_candidate_explains_is_reported_as_such(plain):
    # a cam-like bump: up to 6 N m more torque around 35 deg of output position
    pos = plain.pos_deg
    kt = AxisModel.from_code(CODE).torque_constant_nm_per_a
    bump = 6.0 * np.exp(-(((pos - 35.0) / 8.0) ** 2))
    rec = _with(plain, current=plain.current_a + bump / kt)
    result = run_modelcheck(rec, resimulate=False)
    torque_structures = [s for s in result.structures if s.channel == "torque"]
    assert torque_structures, result.summary_lines()
    assert torque_structures[0].variable == "position"
    assert any("no candidate explains" in line for line in result.summary_lines())
    assert result.to_json()["structured_residual"][0]["variable"] == "position"


def test_a_small_effect_below_the_floor_is_not_named_and_the_limit_is_stated():
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    t, cmd = trapezoid_moves(moves_for(model, n_moves=4), 1000.0)
    # 0.2 N m of Coulomb friction: statistically visible in clean data, below the 0.75 N m floor
    effects = Effects().with_effect("coulomb_friction", torque_nm=0.2)
    result = run_modelcheck(record(model, effects, t, cmd, actuator_code=CODE).recording, resimulate=False)
    assert not result.effects, result.summary_lines()
    limit = next(d for d in result.detection_limits if d.id == "coulomb_friction")
    assert limit.value >= result.channels["torque"].floor > 0.2
