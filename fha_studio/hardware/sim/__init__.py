"""The simulated HA-655 / HA-675 drive with an FHA-C actuator.

- :class:`SimDrive`: the drive (parameters in an EEPROM file, servo, jog with watchdog, moves,
  alarms, I/O, brake, option-L sensors, absolute / incremental encoder, trace capture); stepped
  (``advance(seconds)``) or real time (``start()`` ... ``close()``).
- :class:`SimProtocolServer`: CN3 bytes in, bytes out, through the codec, paced like the line.
- ``sim://ACTUATOR?options``: the pyserial URL handler (:mod:`.protocol_sim`), options in
  :mod:`.options`.
- ``fha-studio sim --pty`` / ``--tcp PORT`` (fha_studio.cli.sim) serve it to other processes.
"""

from __future__ import annotations

from fha_studio.hardware.sim.drive import AlarmRecord, Reply, SimDrive, SimRefused
from fha_studio.hardware.sim.eeprom import EepromError
from fha_studio.hardware.sim.options import SimConfig, SimConfigError, config_from_url, parse_effects
from fha_studio.hardware.sim.server import SimProtocolServer


def register_url_handler() -> None:
    """Make ``serial.serial_for_url("sim://...")`` find the simulated drive (idempotent)."""
    import serial

    if __name__ not in serial.protocol_handler_packages:
        serial.protocol_handler_packages.append(__name__)


__all__ = [
    "AlarmRecord",
    "EepromError",
    "Reply",
    "SimConfig",
    "SimConfigError",
    "SimDrive",
    "SimProtocolServer",
    "SimRefused",
    "config_from_url",
    "parse_effects",
    "register_url_handler",
]
