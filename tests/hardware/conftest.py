"""Fixtures of the hardware tests: a pipe pair, a scripted drive on it, a client attached."""

from __future__ import annotations

import pytest
from drive_fakes import FAST, MiniDrive

from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.transport import pipe_pair
from tests.support.scripted import ScriptedDrive


@pytest.fixture
def pipes():
    host, drive = pipe_pair("test")
    yield host, drive
    host.close()
    drive.close()


@pytest.fixture
def mini():
    return MiniDrive()


@pytest.fixture
def scripted(pipes):
    """Factory: scripted(handler) -> ScriptedDrive on the drive end (closed after the test)."""
    drives = []

    def start(handler):
        drive = ScriptedDrive(pipes[1], handler)
        drives.append(drive)
        return drive

    yield start
    for drive in drives:
        drive.close()


@pytest.fixture
def client_for(pipes, scripted):
    """Factory: client_for(handler, settings=FAST) -> (DriveClient attached, ScriptedDrive)."""
    clients = []

    def make(handler, settings=FAST):
        drive = scripted(handler)
        client = DriveClient.attach(pipes[0], settings)
        clients.append(client)
        return client, drive

    yield make
    for client in clients:
        client.close()
