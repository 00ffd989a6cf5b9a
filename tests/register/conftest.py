"""Register fixtures: a register file in the test's temporary directory, never the user's, and
the same register on a throw-away PostgreSQL server (a database of its own for each test): a
test that takes ``register`` (or ``line3``) runs on both stores."""

from __future__ import annotations

import pytest

from fha_studio.logic.register import Register


@pytest.fixture(params=["sqlite", "postgresql"])
def register_target(request, tmp_path):
    """Where the test's register is: a file, or a ``postgresql://`` URL of a new database."""
    if request.param == "sqlite":
        return tmp_path / "register.sqlite"
    return request.getfixturevalue("postgres_cluster").new_database()


@pytest.fixture
def register(register_target):
    reg = Register(register_target)
    yield reg
    reg.close()


@pytest.fixture
def register_file(tmp_path):
    """A register in an SQLite file only (what only a file has: WAL, its path)."""
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
