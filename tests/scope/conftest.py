"""Fixtures of the scope tests: a client on a scripted drive."""

from __future__ import annotations

import pytest
from scope_fakes import FAST

from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.transport import pipe_pair
from tests.support.scripted import ScriptedDrive


@pytest.fixture
def client_on():
    """Factory: client_on(handler) -> DriveClient attached to a ScriptedDrive running handler."""
    made = []

    def make(handler):
        host, drive_end = pipe_pair("scope-test")
        drive = ScriptedDrive(drive_end, handler)
        client = DriveClient.attach(host, FAST)
        made.append((client, drive, host, drive_end))
        return client

    yield make
    for client, drive, host, drive_end in made:
        client.close()
        drive.close()
        host.close()
        drive_end.close()
