"""A live bench recording (``fha-studio bench record``): the drive's CN2 signals streamed from an
instrument through sigrok-cli for a set time, then decoded as an imported capture is.

The technician maps roles to the instrument's channels (``ROLE=CHANNEL``). The stream is held in
memory as it arrives and made into one :class:`Capture` named after the instrument, so the same
decoding (:func:`fha_studio.logic.bench.importer.import_bench`) makes the recording. An
instrument that vanishes mid-stream leaves what it sent: the recording is made from that.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from fha_studio.hardware.bench import sigrok
from fha_studio.hardware.bench.capture import Capture, SampleBlock, join_blocks, pack_logic
from fha_studio.logic.bench.importer import ROLES, BenchImportError


@dataclass(frozen=True)
class LiveSignal:
    """``ROLE=CHANNEL``: a drive signal and the instrument's channel it is wired to."""

    role: str
    channel: str


def parse_live_signal(text: str) -> LiveSignal:
    """``ROLE=CHANNEL`` -> LiveSignal; BenchImportError naming what is wrong."""
    role, sep, channel = (part.strip() for part in text.partition("="))
    if not sep or not role or not channel:
        raise BenchImportError(f"--signal '{text}': expected ROLE=CHANNEL (e.g. encoder_a=D0)")
    if role not in ROLES:
        raise BenchImportError(f"--signal '{text}': unknown role '{role}' (roles: {', '.join(ROLES)})")
    return LiveSignal(role, channel)


def check_signals(signals: Sequence[LiveSignal]) -> dict[str, str]:
    """role -> channel, each role once; BenchImportError otherwise."""
    roles: dict[str, str] = {}
    for signal in signals:
        if signal.role in roles:
            raise BenchImportError(f"--signal {signal.role}: given twice ({roles[signal.role]} and "
                                   f"{signal.channel})")
        roles[signal.role] = signal.channel
    if not roles:
        raise BenchImportError("no --signal given: map at least one ROLE=CHANNEL")
    return roles


@dataclass(frozen=True)
class LiveCapture:
    """What an instrument sent: the capture (the mapped channels only) and, when it went away
    before the time was up, why (``vanished``, one line)."""

    capture: Capture
    seconds_asked: float
    vanished: str | None = None

    @property
    def complete(self) -> bool:
        return self.vanished is None


def _only(block: SampleBlock, channels: Sequence[str]) -> SampleBlock:
    """The block with only ``channels`` (each once, in their order)."""
    wanted = list(dict.fromkeys(channels))
    logic = [c for c in wanted if c in block.logic_channels]
    analog = {c: block.analog[c] for c in wanted if c in block.analog}
    packed = pack_logic([block.bit(c) for c in logic]) if logic else np.zeros(0, np.uint8)
    return SampleBlock(block.sample_rate_hz, tuple(logic), packed, analog, block.first_sample)


def record_live(device: str, roles: Mapping[str, str], seconds: float, sample_rate_hz: float | None = None,
                *, on_block: Callable[[SampleBlock], None] | None = None,
                program: str = sigrok.SIGROK_CLI) -> LiveCapture:
    """Stream the mapped channels of ``device`` for ``seconds``.

    :class:`sigrok.SigrokError` (bad device, channel or rate: nothing was recorded) is raised;
    an instrument that vanishes after sending samples gives a LiveCapture with ``vanished`` set.
    """
    channels = list(dict.fromkeys(roles.values()))
    acquisition = sigrok.Acquisition(device, channels, sample_rate_hz, program=program)
    acquisition.start()
    acquisition.max_samples = max(2, round(seconds * acquisition.sample_rate_hz))
    blocks: list[SampleBlock] = []
    vanished = None
    try:
        for block in acquisition.blocks():
            blocks.append(block)
            if on_block is not None:
                on_block(block)
    except sigrok.DeviceVanished as exc:
        vanished = str(exc)
        if not blocks:
            raise
    finally:
        acquisition.close()
    if not blocks:
        raise sigrok.SigrokError(f"{device}: sigrok-cli sent no samples")
    whole = _only(join_blocks(blocks), channels)
    units = {name: acquisition.units.get(name, "V") for name in whole.analog}
    capture = Capture(device, whole, units, 0.0, "sigrok-cli stream")
    return LiveCapture(capture, seconds, vanished)
