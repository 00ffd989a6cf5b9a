"""Models of catalogue actuators for the physics tests."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from fha_studio import catalog
from fha_studio.physics import AxisModel, Effects

# Until fha_studio.catalog.get_actuator lands: the FHA-C manual's numbers for the actuators the
# tests use (1-4-1, 1-8, 1-9-2). Removed once the catalogue is on main.
_MANUAL = {
    # code: Kt, Im, JA, ratio, ppr, max rpm, TM, R, (T1, T2, K1, K2, K3)
    "FHA-17C-50-US250": (21, 2.1, 0.17, 50, 500_000, 96, 39, 7.9, (7.0, 25, 1.1e4, 1.3e4, 2.0e4)),
    "FHA-17C-100-US250": (42, 1.6, 0.67, 100, 1_000_000, 48, 57, 7.9, (7.0, 25, 1.3e4, 1.7e4, 2.5e4)),
    "FHA-25C-50-US250": (22, 7.3, 0.81, 50, 500_000, 90, 150, 2.6, (29, 108, 4.7e4, 6.1e4, 8.4e4)),
    "FHA-25C-100-US250": (45, 5.6, 3.2, 100, 1_000_000, 45, 230, 2.6, (29, 108, 6.1e4, 7.7e4, 11e4)),
    "FHA-32C-50-US250": (27, 11.4, 1.8, 50, 500_000, 80, 281, 1.0, (54, 196, 8.8e4, 11e4, 15e4)),
    "FHA-32C-100-US250": (54, 8.0, 7.1, 100, 1_000_000, 40, 398, 1.0, (54, 196, 11e4, 14e4, 20e4)),
    "FHA-40C-50-US250": (31, 17.3, 4.9, 50, 500_000, 70, 500, 0.73, (108, 382, 17e4, 21e4, 30e4)),
    "FHA-40C-100-US250": (64, 11.8, 19.5, 100, 1_000_000, 35, 690, 0.73, (108, 382, 21e4, 29e4, 37e4)),
    "FHA-40C-160-US250": (102, 9.0, 50, 160, 1_600_000, 22, 820, 0.73, (108, 382, 21e4, 29e4, 37e4)),
}


def get_actuator(code: str):
    if hasattr(catalog, "get_actuator"):
        return catalog.get_actuator(code)
    kt, im, ja, ratio, ppr, rpm, tm, r, (t1, t2, k1, k2, k3) = _MANUAL[code]
    return SimpleNamespace(
        model_code=code, torque_constant_nm_per_a=kt, max_current_a=im, inertia_kgm2=ja, ratio=ratio,
        output_resolution_ppr=ppr, max_speed_rpm=rpm, max_torque_nm=tm, phase_resistance_ohm=r,
        friction_torque_nm=kt * im - tm,
        stiffness=SimpleNamespace(t1_nm=t1, t2_nm=t2, k1_nm_per_rad=k1, k2_nm_per_rad=k2, k3_nm_per_rad=k3),
    )


@pytest.fixture
def make_model():
    """make_model(code, load_inertia_kgm2=0.0, effects=None, **overrides) -> AxisModel of that actuator."""

    def make(code: str, load_inertia_kgm2: float = 0.0, effects: Effects | None = None,
             **overrides) -> AxisModel:
        return AxisModel.from_actuator(get_actuator(code), load_inertia_kgm2, effects, **overrides)

    return make
