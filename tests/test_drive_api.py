"""Every drive stand-in is a DriveApi: checked by mypy (scripts/test runs it over this module) and at
run time (``typing.runtime_checkable``)."""

from __future__ import annotations

from fha_studio.hardware.api import DriveApi
from fha_studio.hardware.client import DriveClient
from tests.gui.fake_drive import FakeDriveClient


def as_drive_apis(client: DriveClient, fake: FakeDriveClient) -> list[DriveApi]:
    """Never called: mypy rejects this module when either does not satisfy DriveApi."""
    return [client, fake]


def test_the_client_and_the_fakes_are_drive_apis():
    assert isinstance(FakeDriveClient(), DriveApi)
    with DriveClient.open("sim://FHA-25C-50-S248?paced=0") as client:
        assert isinstance(client, DriveApi)
