"""The running simulated drive's CN2 as a live bench instrument (``sim-cn2``), as a logic analyzer
with one analog input clipped onto a real drive's CN2 streams it. No Qt.

An embedded simulated drive (``sim://``) that runs in real time is *plugged in* while its port is
open (:func:`plug` / :func:`unplug`, called by the port): :func:`devices` lists it beside what
sigrok-cli finds, as ``sim-cn2`` (the first) or ``sim-cn2:drive=N``. :class:`VirtualAcquisition`
streams it as :class:`~fha_studio.hardware.bench.sigrok.Acquisition` streams a device: every
``block_s`` it takes the servo's trace of the time that passed (under the drive's lock; the
drive's own thread advances it) and samples the CN2 outputs of :mod:`.cn2` at the instrument's
rate (ENC_A, ENC_B, ENC_Z, CMD_A, CMD_B, IN_POS, ALARM, ALM_A ... ALM_D as logic, the ones asked
for packed in their order as sigrok-cli's ``-C`` gives them; SPD_MON in volts). A drive
that is closed while it streams vanishes as an unplugged instrument does.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING

from fha_studio.hardware.bench.capture import SampleBlock
from fha_studio.hardware.bench.sigrok import Device, DeviceVanished, SigrokError
from fha_studio.hardware.sim.cn2 import (
    ANALOG_CHANNELS,
    LOGIC_CHANNELS,
    MonitorModel,
    settings_of_drive,
    signals_of_axis,
)

if TYPE_CHECKING:
    from fha_studio.hardware.sim.drive import SimDrive

DRIVER = "sim-cn2"
#: The instrument's rate when none is asked: the encoder's edges at 1000 r/min (motor) of a
#: 10000-count encoder are 167 kHz, the command pulses as many.
DEFAULT_RATE_HZ = 500e3
#: How much drive time one block holds [s].
BLOCK_S = 0.02

_lock = threading.Lock()
_plugged: dict[int, SimDrive] = {}
_next = [1]


def plug(drive: SimDrive) -> int:
    """A running drive's CN2 is on offer as an instrument; its number."""
    with _lock:
        number = _next[0]
        _next[0] += 1
        _plugged[number] = drive
        return number


def unplug(drive: SimDrive) -> None:
    with _lock:
        for number, plugged in list(_plugged.items()):
            if plugged is drive:
                del _plugged[number]


def devices() -> list[Device]:
    """The plugged drives as instruments (the first is plain ``sim-cn2``)."""
    with _lock:
        items = sorted(_plugged.items())
    found = []
    for index, (number, drive) in enumerate(items):
        options = "" if index == 0 else f"drive={number}"
        found.append(Device(DRIVER, options, f"FHA Studio simulated drive {drive.config.actuator} (CN2)",
                            LOGIC_CHANNELS + ANALOG_CHANNELS))
    return found


def is_virtual(device: str) -> bool:
    return device.split(":", 1)[0] == DRIVER


def _find(device: str) -> SimDrive:
    _, _, options = device.partition(":")
    with _lock:
        items = sorted(_plugged.items())
    if not items:
        raise SigrokError(f"{device}: no simulated drive is running (connect to a sim:// drive first)")
    if not options:
        return items[0][1]
    key, _, value = options.partition("=")
    if key != "drive" or not value.isdigit():
        raise SigrokError(f"{device}: the option is drive=N (the simulated drive's number)")
    for number, drive in items:
        if number == int(value):
            return drive
    raise SigrokError(f"{device}: no simulated drive {value} is running")


class VirtualAcquisition:
    """The plugged drive's CN2 streamed in real time (see the module docstring)."""

    def __init__(self, device: str, channels: Sequence[str], sample_rate_hz: float | None = None, *,
                 max_samples: int | None = None, monitor: MonitorModel | None = None,
                 block_s: float = BLOCK_S):
        self.device = device
        self.requested = tuple(channels)
        self.channels = tuple(channels)
        self.sample_rate_hz = float(sample_rate_hz or DEFAULT_RATE_HZ)
        self.max_samples = max_samples
        self.monitor = monitor
        self.block_s = block_s
        self.samples = 0
        self.units: dict[str, str] = {c: "V" for c in channels if c in ANALOG_CHANNELS}
        self._drive: SimDrive | None = None
        self._stop = threading.Event()

    def start(self) -> None:
        drive = _find(self.device)
        missing = [c for c in self.requested if c not in LOGIC_CHANNELS + ANALOG_CHANNELS]
        if missing:
            raise SigrokError(f"{self.device}: no channel {', '.join(missing)} (it has "
                              f"{', '.join(LOGIC_CHANNELS + ANALOG_CHANNELS)})")
        if not self.requested:
            raise SigrokError(f"{self.device}: no channels to record")
        self._drive = drive

    def stop(self) -> None:
        self._stop.set()

    def close(self) -> None:
        self.stop()
        drive = self._drive
        if drive is not None:
            with drive.lock:
                drive.axis.stop_trace()

    def __enter__(self) -> VirtualAcquisition:
        if self._drive is None:
            self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def blocks(self) -> Iterator[SampleBlock]:
        if self._drive is None:
            self.start()
        drive = self._drive
        assert drive is not None
        with drive.lock:
            logic = tuple(c for c in self.requested if c in LOGIC_CHANNELS)
            signals = signals_of_axis(drive.axis, self.sample_rate_hz, settings_of_drive(drive, self.monitor),
                                      alarm_table=drive.alarm_table, logic_channels=logic)
            drive.axis.start_trace(1)
        while not self._stop.wait(self.block_s):
            with drive.lock:
                if not drive.running:
                    raise DeviceVanished(f"{self.device}: the simulated drive was closed (after "
                                         f"{self.samples} samples)", self.samples)
                trace = drive.axis.read_trace(clear=True)
                alarm = drive.alarm
            if trace["t"].size == 0:
                continue
            try:
                block, _truth = signals.feed(trace, alarm)
            except ValueError as exc:  # the rate is too low for the edges
                raise SigrokError(f"{self.device}: {exc}") from None
            n = block.samples
            if self.max_samples is not None:
                n = min(n, self.max_samples - self.samples)
            if n <= 0:
                continue
            out = SampleBlock(block.sample_rate_hz, block.logic_channels, block.logic[:n],
                              {k: v[:n] for k, v in block.analog.items()}, self.samples)
            self.samples += n
            yield out
            if self.max_samples is not None and self.samples >= self.max_samples:
                return
