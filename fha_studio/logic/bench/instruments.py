"""Every bench instrument FHA Studio streams, behind one face (no Qt):

- ``DRIVER[:OPTIONS]``: a device through sigrok-cli
  (:class:`fha_studio.hardware.bench.sigrok.Acquisition`);
- ``file:PATH``: a capture file played through sigrok-cli's input modules
  (:class:`fha_studio.hardware.bench.sigrok_input.FileAcquisition`);
- ``sim-cn2[:drive=N]``: a running simulated drive's CN2
  (:class:`fha_studio.hardware.sim.cn2_live.VirtualAcquisition`).

Each has ``start()``, ``blocks()`` (:class:`~.capture.SampleBlock` as they come, ending after
``stop()`` or raising ``sigrok.DeviceVanished``), ``stop()`` from any thread, ``close()``,
``sample_rate_hz``, ``samples``, ``units`` and ``max_samples``.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Protocol

from fha_studio.hardware.bench import sigrok
from fha_studio.hardware.bench.capture import SampleBlock
from fha_studio.hardware.bench.sigrok_input import FileAcquisition
from fha_studio.hardware.sim import cn2_live
from fha_studio.hardware.sim.cn2 import LOGIC_CHANNELS

FILE_PREFIX = "file:"


class Instrument(Protocol):
    device: str
    sample_rate_hz: float
    samples: int
    units: dict[str, str]
    max_samples: int | None

    def start(self) -> None: ...
    def blocks(self) -> Iterator[SampleBlock]: ...
    def stop(self) -> None: ...
    def close(self) -> None: ...


def open_instrument(device: str, channels: Sequence[str], sample_rate_hz: float | None = None) -> Instrument:
    """The instrument a device text names (not started)."""
    if device.startswith(FILE_PREFIX):
        return FileAcquisition(device[len(FILE_PREFIX):], channels)
    if cn2_live.is_virtual(device):
        return cn2_live.VirtualAcquisition(device, channels, sample_rate_hz)
    return sigrok.Acquisition(device, channels, sample_rate_hz)


def scan(driver: str | None = None) -> tuple[list[sigrok.Device], str]:
    """The instruments on offer: the running simulated drives' CN2, then what sigrok-cli finds;
    and why sigrok-cli found none ("" when it answered)."""
    virtual = [] if driver and not cn2_live.is_virtual(driver) else cn2_live.devices()
    if driver and cn2_live.is_virtual(driver):
        return virtual, ""
    try:
        return virtual + sigrok.scan(driver), ""
    except sigrok.SigrokError as exc:
        return virtual, str(exc)


def logic_channels(instrument: Instrument, channels: Sequence[str]) -> tuple[str, ...]:
    """Which of ``channels`` the instrument gives as logic levels (the rest are analog)."""
    if isinstance(instrument, sigrok.Acquisition):
        return tuple(channels) if instrument.is_logic else ()
    if isinstance(instrument, FileAcquisition):
        return tuple(c for c in channels if c in instrument.logic)
    if isinstance(instrument, cn2_live.VirtualAcquisition):
        return tuple(c for c in channels if c in LOGIC_CHANNELS)
    return tuple(c for c in channels if sigrok.is_logic_channel(c))
