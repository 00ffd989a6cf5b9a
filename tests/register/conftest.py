"""Register fixtures: a register file in the test's temporary directory, never the user's."""

from __future__ import annotations

import pytest

from fha_studio.logic.register import Register


@pytest.fixture
def register(tmp_path):
    reg = Register(tmp_path / "register.sqlite")
    yield reg
    reg.close()


@pytest.fixture
def line3(register):
    """Machine 'Line 3 positioner' with a rotary table (two twin axes) and a tilt axis."""
    register.add_machine("Line 3 positioner", site="Plant A, hall 2")
    register.add_axis(
        "Line 3 positioner", "table", "FHA-25C-50-US250", "HA-655-2-200", "/dev/ttyUSB0", 1.5, who="ana"
    )
    register.add_axis(
        "Line 3 positioner", "table twin", "FHA-25C-50-US250", "HA-655-2-200", "/dev/ttyUSB1", 1.5
    )
    register.add_axis(
        "Line 3 positioner", "tilt", "FHA-32C-100-S248-B-L", "HA-655-2-200", "/dev/ttyUSB2", 4.0
    )
    return register
