"""A ``DriveClient`` on a ``ScriptedDrive`` through an in-process pipe pair: the fixtures
``pipes``, ``scripted`` and ``client_for``, offered to every test (tests/conftest.py registers
this module as a plugin). The hardware and the scope tests use them; a test that needs its own
pair of another name defines its own ``pipes`` (test_hostile_lines.py).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pytest

from fha_studio.hardware.client import DriveClient, LinkSettings
from fha_studio.hardware.transport import PipeEnd, pipe_pair
from tests.support.scripted import Handler, ScriptedDrive

#: Short timeouts so that failure tests stay fast; still far above in-process latency.
FAST = LinkSettings(response_timeout_s=0.08, oww_timeout_s=1.0, eeprom_write_timeout_s=0.1)


@pytest.fixture
def pipes() -> Iterator[tuple[PipeEnd, PipeEnd]]:
    """The host's end and the drive's end of one pipe (``test:host``, ``test:drive``)."""
    host, drive = pipe_pair("test")
    yield host, drive
    host.close()
    drive.close()


@pytest.fixture
def scripted(pipes: tuple[PipeEnd, PipeEnd]) -> Iterator[Callable[[Handler], ScriptedDrive]]:
    """Factory: scripted(handler) -> ScriptedDrive on the drive's end (closed after the test)."""
    drives: list[ScriptedDrive] = []

    def start(handler: Handler) -> ScriptedDrive:
        drives.append(ScriptedDrive(pipes[1], handler))
        return drives[-1]

    yield start
    for drive in drives:
        drive.close()


@pytest.fixture
def client_for(
    pipes: tuple[PipeEnd, PipeEnd], scripted: Callable[[Handler], ScriptedDrive]
) -> Iterator[Callable[..., tuple[DriveClient, ScriptedDrive]]]:
    """Factory: client_for(handler, settings=FAST) -> (DriveClient attached to the host's end,
    the ScriptedDrive answering with ``handler``); the client is closed after the test."""
    clients: list[DriveClient] = []

    def make(handler: Handler, settings: LinkSettings = FAST) -> tuple[DriveClient, ScriptedDrive]:
        drive = scripted(handler)
        clients.append(DriveClient.attach(pipes[0], settings))
        return clients[-1], drive

    yield make
    for client in clients:
        client.close()
