"""pyserial URL handler ``sim://ACTUATOR?options``: an embedded SimDrive reached through bytes.

``serial.serial_for_url("sim://FHA-25C-50-US250?load_inertia=1.5&paced=0")`` finds this module
once ``fha_studio.hardware.sim`` is in ``serial.protocol_handler_packages`` (the transport layer
registers it; :func:`fha_studio.hardware.sim.register_url_handler` does it too). Options: see
:mod:`fha_studio.hardware.sim.options`. The drive runs in real time in its own thread from
``open()`` to ``close()`` (with ``stepped=1`` its time stands still until the holder calls
``port.sim_drive.advance(seconds)``); every byte goes through the CN3 codec (no shortcut around
the protocol).

``port.sim_drive`` is the SimDrive (for a training GUI that wants to show the hidden state);
``port.sim_responder`` its CN3 face, whose panel actions a training drive journals.
"""

from __future__ import annotations

import time
from typing import Any

from serial.serialutil import PortNotOpenError, SerialBase, SerialException, to_bytes

from fha_studio.hardware.sim import cn2_live
from fha_studio.hardware.sim.drive import SimDrive
from fha_studio.hardware.sim.eeprom import EepromError
from fha_studio.hardware.sim.options import SimConfigError, config_from_url
from fha_studio.hardware.sim.responder import SimResponder
from fha_studio.hardware.sim.server import SimProtocolServer

_POLL_S = 0.005  # longest wait between looks at the drive (a deferred reply is not foreseen)


class Serial(SerialBase):
    """A serial port whose other end is a simulated HA-655 (see the module docstring)."""

    is_open: bool  # set by SerialBase

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.sim_drive: SimDrive | None = None
        self.sim_server: SimProtocolServer | None = None
        super().__init__(*args, **kwargs)

    def open(self) -> None:
        if self.is_open:
            raise SerialException("Port is already open.")
        if self._port is None:
            raise SerialException("Port must be configured before it can be used.")
        try:
            config = config_from_url(self._port)
            drive = SimDrive(config=config)
        except (SimConfigError, EepromError) as exc:
            raise SerialException(str(exc)) from exc
        self.sim_drive = drive
        # paced at the CN3 rate whatever the host asked for: the line is the drive's
        self.sim_server = SimProtocolServer(drive, paced=config.paced)
        if not config.stepped:
            drive.start()
            cn2_live.plug(drive)  # its CN2 on offer as a bench instrument while the port is open
        self.is_open = True

    def close(self) -> None:
        drive, self.sim_drive = self.sim_drive, None
        self.is_open = False
        if drive is not None:
            cn2_live.unplug(drive)
            drive.close()
        super().close()

    @property
    def sim_responder(self) -> SimResponder | None:
        """The drive's CN3 face (its command table, journal and panel actions), None when closed."""
        return self.sim_server.responder if self.sim_drive is not None and self.sim_server else None

    def from_url(self, url: str) -> str:
        config_from_url(url)
        return url

    def _reconfigure_port(self) -> None:
        # the line settings are those of CN3; pacing follows the baud rate given at open
        pass

    @property
    def in_waiting(self) -> int:
        if not self.is_open or self.sim_server is None:
            raise PortNotOpenError()
        return self.sim_server.in_waiting()

    def read(self, size: int = 1) -> bytes:
        if not self.is_open or self.sim_server is None:
            raise PortNotOpenError()
        server = self.sim_server
        deadline = None if self._timeout is None else time.monotonic() + self._timeout
        data = bytearray()
        while len(data) < size:
            data += server.read_ready(size - len(data))
            if len(data) >= size or not self.is_open:
                break
            now = time.monotonic()
            if deadline is not None and now >= deadline:
                break
            wait = server.next_event_s()
            wait = _POLL_S if wait is None else min(max(wait, 0.0002), _POLL_S)
            if deadline is not None:
                wait = min(wait, deadline - now)
            time.sleep(wait)
        return bytes(data)

    def write(self, data: bytes) -> int:
        if not self.is_open or self.sim_server is None:
            raise PortNotOpenError()
        data = to_bytes(data)
        self.sim_server.feed(data)
        return len(data)

    def reset_input_buffer(self) -> None:
        if not self.is_open or self.sim_server is None:
            raise PortNotOpenError()
        self.sim_server.reset_output()

    def reset_output_buffer(self) -> None:
        if not self.is_open:
            raise PortNotOpenError()

    @property
    def out_waiting(self) -> int:
        return 0

    def _update_break_state(self) -> None:
        pass

    def _update_rts_state(self) -> None:
        pass

    def _update_dtr_state(self) -> None:
        pass

    @property
    def cts(self) -> bool:
        return True

    @property
    def dsr(self) -> bool:
        return True

    @property
    def ri(self) -> bool:
        return False

    @property
    def cd(self) -> bool:
        return True
