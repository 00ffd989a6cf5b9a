"""Fixtures of the simulated-drive tests: drives in stepped mode, closed after each test; the
clock of a stepped drive behind a client."""

from __future__ import annotations

import dataclasses
import weakref

import pytest

from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.protocol import Command, Request, UnknownRequest, decode_request
from fha_studio.hardware.sim import SimDrive, SimReply, SimResponder
from fha_studio.hardware.sim.constants import load_sim_constants

_RESPONDERS: weakref.WeakKeyDictionary[SimDrive, SimResponder] = weakref.WeakKeyDictionary()


def responder(drive: SimDrive) -> SimResponder:
    """The CN3 face of ``drive``, one per drive as a server holds it (so OWW's q comes to it)."""
    if drive not in _RESPONDERS:
        _RESPONDERS[drive] = SimResponder(drive)
    return _RESPONDERS[drive]


def ask(drive: SimDrive, command: Command | str, value: int = 0) -> SimReply | None:
    """One CN3 command by its name, decoded from its frame as the server does (a name that is no
    command comes as an unknown request)."""
    frame = f"{command}{'-' if value < 0 else '+'}{abs(value):05d}\r".encode("ascii")
    _, request = decode_request(frame)
    assert isinstance(request, Request | UnknownRequest), frame
    return responder(drive).respond(request)


@pytest.fixture
def make_drive(tmp_path):
    """``make_drive(actuator, **options)`` -> a stepped SimDrive with its EEPROM in tmp_path
    (``eeprom=`` overrides; ``constants={...}`` replaces some simulation constants)."""
    drives: list[SimDrive] = []

    def make(actuator: str = "FHA-25C-50-US250", constants: dict | None = None, **options) -> SimDrive:
        options.setdefault("eeprom", str(tmp_path / f"eeprom-{len(drives)}.json"))
        c = dataclasses.replace(load_sim_constants(), **(constants or {}))
        drive = SimDrive(actuator, constants=c, **options)
        drives.append(drive)
        return drive

    yield make
    for drive in drives:
        drive.close()


def jog_for(drive: SimDrive, speed_rpm: float, seconds: float, repeat_s: float = 0.05) -> None:
    """Jog as a client holding the button does: JOG repeated every ``repeat_s``."""
    t = 0.0
    while t < seconds - 1e-9:
        drive.jog(speed_rpm)
        step = min(repeat_s, seconds - t)
        drive.advance(step)
        t += step


def advance(client: DriveClient, seconds: float) -> None:
    """Let ``seconds`` of drive time pass on the stepped drive behind a client of
    ``sim://...?stepped=1`` (its time stands still otherwise, however loaded the machine)."""
    port = client.transaction.transport.inner
    port.sim_drive.advance(seconds)
