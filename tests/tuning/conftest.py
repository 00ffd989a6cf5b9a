"""The tuning tests' drives: a simulated drive's servo switched on as a real axis has it."""

from __future__ import annotations

import pytest

from fha_studio.hardware.client import DriveClient


@pytest.fixture
def drives(monkeypatch):
    """The simulated drives the command line opens, their servo switched on by the controller
    (the CN2 servo-ON input, as on a real axis: the command line never switches it on)."""
    opened = DriveClient.open.__func__
    found = []

    def open_under_servo(cls, url, *args, **kwargs):
        client = opened(cls, url, *args, **kwargs)
        found.append(client.transaction.transport.inner.sim_drive)
        found[-1].set_servo(True)
        return client

    monkeypatch.setattr(DriveClient, "open", classmethod(open_under_servo))
    return found
