"""Models of catalogue actuators for the physics tests."""

from __future__ import annotations

import pytest

from fha_studio.physics import AxisModel, Effects


@pytest.fixture
def make_model():
    """make_model(code, load_inertia_kgm2=0.0, effects=None, **overrides) -> AxisModel from the catalogue."""

    def make(code: str, load_inertia_kgm2: float = 0.0, effects: Effects | None = None,
             **overrides) -> AxisModel:
        return AxisModel.from_code(code, load_inertia_kgm2, effects, **overrides)

    return make
