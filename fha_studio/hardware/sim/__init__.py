"""The simulated HA-655 / HA-675 drive with an FHA-C actuator.

- :class:`SimDrive` (:mod:`.drive`): the drive (servo, jog with watchdog, moves, positions,
  monitors, absolute / incremental encoder); stepped (``advance(seconds)``) or real time
  (``start()`` ... ``close()``). Its other jobs: items and EEPROM (:mod:`.memory`, :mod:`.eeprom`),
  I/O, brake and option-L sensors (:mod:`.io`), alarms and supervision (:mod:`.supervision`),
  trace capture (:mod:`.trace`), recording (:mod:`.recorder`).
- :class:`SimResponder` (:mod:`.responder`): its face on CN3: a decoded request in, a reply out;
  the command table and its narrowing by profile, CAP, deferred replies, the training journal.
- :class:`SimProtocolServer`: CN3 bytes in, bytes out, through the codec, paced like the line.
- ``sim://ACTUATOR?options``: the pyserial URL handler (:mod:`.protocol_sim`), options in
  :mod:`.options`.
- ``fha-studio sim --pty`` / ``--tcp PORT`` (fha_studio.cli.sim) serve it to other processes.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from fha_studio.hardware.sim.drive import SimDrive
from fha_studio.hardware.sim.eeprom import EepromError
from fha_studio.hardware.sim.options import SimConfig, SimConfigError, config_from_url, parse_effects
from fha_studio.hardware.sim.reply import SimRefused, SimReply
from fha_studio.hardware.sim.responder import SimResponder
from fha_studio.hardware.sim.server import SimProtocolServer
from fha_studio.hardware.sim.supervision import SimAlarmRecord


def stepped_clock(client: Any) -> tuple[Callable[[float], None], Callable[[], float]] | None:
    """The drive's own clock behind a client of ``sim://...?stepped=1``: (advance by seconds, the
    drive's time), for a caller that waits on the drive (its time stands still otherwise); None
    for any other drive, which runs by itself."""
    port = getattr(getattr(getattr(client, "transaction", None), "transport", None), "inner", None)
    drive = getattr(port, "sim_drive", None)
    if not isinstance(drive, SimDrive) or not drive.config.stepped:
        return None
    return drive.advance, lambda: drive.clock_s


def register_url_handler() -> None:
    """Make ``serial.serial_for_url("sim://...")`` find the simulated drive (idempotent)."""
    import serial

    if __name__ not in serial.protocol_handler_packages:
        serial.protocol_handler_packages.append(__name__)


__all__ = [
    "EepromError",
    "SimAlarmRecord",
    "SimConfig",
    "SimConfigError",
    "SimDrive",
    "SimProtocolServer",
    "SimRefused",
    "SimReply",
    "SimResponder",
    "config_from_url",
    "parse_effects",
    "register_url_handler",
    "stepped_clock",
]
