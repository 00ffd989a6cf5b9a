"""The re-simulation's memory and cost stay bounded whatever the recording's duration."""

from __future__ import annotations

import importlib
import math
import tracemalloc

import numpy as np
import pytest
from modelcheck_gen import record

from fha_studio.logic.modelcheck import run_modelcheck, workflow
from fha_studio.physics import AxisModel, Effects, simulate

# the package exports the function under the module's name: take the module itself
simulate_module = importlib.import_module("fha_studio.physics.simulate")

CODE = "FHA-25C-50-US250"


@pytest.mark.slow
def test_simulate_keeps_only_one_chunk_of_servo_periods_in_memory(monkeypatch):
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    t = np.arange(0.0, 4.0, 0.01)  # 4 s sampled at 100 Hz: 20 000 servo periods
    cmd = math.radians(90.0) * np.sin(t)
    whole = simulate(model, None, t, cmd, current_average=True)
    monkeypatch.setattr(simulate_module, "SIMULATION_CHUNK", 2_000)
    tracemalloc.start()
    try:
        chunked = simulate(model, None, t, cmd, current_average=True)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    # per-period records of the whole run would take ~4.5 MB; one chunk ~0.5 MB
    assert peak < 1.5e6, peak
    for key, values in whole.items():
        np.testing.assert_allclose(chunked[key], values, rtol=0, atol=1e-12, err_msg=key)


def test_a_long_recording_is_re_simulated_over_a_bounded_span(monkeypatch):
    # the bound, shortened for the test: the recording is 5 s longer than what is re-simulated
    bound = 3.0
    monkeypatch.setattr(workflow, "RESIM_MAX_S", bound)
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    rate = 200.0
    t = np.arange(0.0, bound + 5.0, 1.0 / rate)
    cmd = math.radians(60.0) * (1.0 - np.cos(2.0 * math.pi * t / 3.0))
    rec = record(
        model, Effects().with_effect("coulomb_friction", torque_nm=5.0), t, cmd, actuator_code=CODE
    ).recording
    result = run_modelcheck(rec)
    r = result.resimulation
    assert r is not None
    assert r.t_s[-1] <= rec.t_s[0] + bound + 1e-9
    assert r.t_s[-1] > rec.t_s[0] + bound - 0.5
    assert f"first {bound:g} s" in r.command
    assert r.rms_updated_nm < r.rms_nominal_nm
    assert [e.id for e in result.effects] == ["coulomb_friction"]
