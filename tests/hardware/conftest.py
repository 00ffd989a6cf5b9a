"""Fixtures of the hardware tests: the mini drive (the pipe pair, the scripted drive on it and
the client attached are tests/support/links.py's, for every test)."""

from __future__ import annotations

import pytest
from drive_fakes import MiniDrive


@pytest.fixture
def mini():
    return MiniDrive()
