"""Fixtures for every test. No Qt here: the core tests must run without it."""

from __future__ import annotations

import os
import threading
import time

import pytest

# GUI tests run headless; the environment can override (e.g. xcb under xvfb-run).
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


@pytest.fixture(autouse=True)
def _user_data_elsewhere(tmp_path_factory, monkeypatch):
    """No test reads or writes the user's data directory (the register, simulated EEPROMs): the
    per-user data directory is a temporary one, and no site register is chosen."""
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path_factory.mktemp("user-data")))
    monkeypatch.delenv("FHA_STUDIO_REGISTER", raising=False)


@pytest.fixture(autouse=True)
def _no_leaked_threads():
    """Fail a test that leaves a thread running (a link worker, a simulated drive, a reader)."""
    before = set(threading.enumerate())
    yield
    deadline = time.monotonic() + 2.0
    while True:
        leaked = [t for t in threading.enumerate() if t not in before and t.is_alive()]
        if not leaked or time.monotonic() > deadline:
            break
        time.sleep(0.01)
    assert not leaked, f"threads left running: {[t.name for t in leaked]}"
