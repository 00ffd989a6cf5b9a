"""Samples as a bench instrument gives them: blocks (live) and whole captures (files).

:class:`SampleBlock` is the one type that moves samples between an instrument and the decoders:
the virtual instrument of the simulated drive yields them, ``sigrok-cli``'s stream is cut into
them, and a file reads as one :class:`Capture` (a block with a source and units). Logic channels
are packed one bit each into an unsigned integer per sample (bit ``i`` = ``logic_channels[i]``,
as sigrok packs them); analog channels are float32 in their unit (volts for a probe).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

#: The packed logic word for up to 8, 16, 32 and 64 channels.
_LOGIC_DTYPES = ((8, np.uint8), (16, np.uint16), (32, np.uint32), (64, np.uint64))


class CaptureError(ValueError):
    """A capture that cannot be used as asked; ``str()`` is one line naming the file and what."""


def logic_dtype(channels: int) -> type[np.unsignedinteger]:
    """The smallest unsigned integer type holding ``channels`` bits (sigrok's unit size)."""
    for bits, dtype in _LOGIC_DTYPES:
        if channels <= bits:
            return dtype
    raise ValueError(f"{channels} logic channels: at most 64 are packed in one sample")


@dataclass(frozen=True)
class SampleBlock:
    """Consecutive samples of an instrument, all channels at one rate.

    ``logic``: shape ``(n,)``, one unsigned integer per sample, bit ``i`` = ``logic_channels[i]``
    (uint8 for up to 8 channels, uint16 up to 16, ...). ``analog``: name -> float32 ``(n,)``.
    ``first_sample``: index of the block's first sample since the acquisition began, so blocks
    can be checked for gaps and joined.
    """

    sample_rate_hz: float
    logic_channels: tuple[str, ...] = ()
    logic: np.ndarray = field(default_factory=lambda: np.zeros(0, np.uint8))
    analog: Mapping[str, np.ndarray] = field(default_factory=dict)
    first_sample: int = 0

    def __post_init__(self) -> None:
        if not (self.sample_rate_hz > 0 and np.isfinite(self.sample_rate_hz)):
            raise ValueError(f"sample rate {self.sample_rate_hz!r}: must be a positive number of Hz")
        n = self.samples
        if self.logic_channels and self.logic.shape != (n,):
            raise ValueError(f"logic array of shape {self.logic.shape}, expected ({n},)")
        for name, values in self.analog.items():
            if values.shape != (n,):
                raise ValueError(f"analog channel {name}: {values.shape} samples, expected ({n},)")
        names = list(self.logic_channels) + list(self.analog)
        if len(set(names)) != len(names):
            raise ValueError(f"channel names given twice: {', '.join(names)}")

    @property
    def samples(self) -> int:
        """Number of samples in the block."""
        if self.logic_channels:
            return int(self.logic.shape[0])
        for values in self.analog.values():
            return int(values.shape[0])
        return 0

    @property
    def channels(self) -> tuple[str, ...]:
        """Every channel's name: the logic channels, then the analog ones."""
        return tuple(self.logic_channels) + tuple(self.analog)

    @property
    def duration_s(self) -> float:
        """The time the block covers [s] (samples / rate)."""
        return self.samples / self.sample_rate_hz

    def bit(self, name: str) -> np.ndarray:
        """A logic channel as a bool array."""
        index = self.logic_channels.index(name)
        return ((self.logic >> index) & 1).astype(bool)


def join_blocks(blocks: Sequence[SampleBlock]) -> SampleBlock:
    """Consecutive blocks of one acquisition as one block (same rate and channels, no gap)."""
    if not blocks:
        raise ValueError("no blocks to join")
    first = blocks[0]
    expected = first.first_sample
    for block in blocks:
        if (block.sample_rate_hz, block.logic_channels, tuple(block.analog)) != (
                first.sample_rate_hz, first.logic_channels, tuple(first.analog)):
            raise ValueError("blocks of different rates or channels cannot be joined")
        if block.first_sample != expected:
            raise ValueError(f"a gap between blocks: sample {expected} expected, {block.first_sample} came")
        expected += block.samples
    logic = (np.concatenate([b.logic for b in blocks]) if first.logic_channels
             else np.zeros(0, np.uint8))
    analog = {name: np.concatenate([b.analog[name] for b in blocks]) for name in first.analog}
    return SampleBlock(first.sample_rate_hz, first.logic_channels, logic, analog, first.first_sample)


@dataclass(frozen=True)
class Capture:
    """A whole capture read from one file: its samples, where it came from and the analog units.

    ``units``: analog channel -> unit as the file states it (``"V"`` when it does not).
    ``start_s``: the time of the first sample in the file's own time base.
    ``changes``: the file holds changes (VCD, a logic analyzer's export of changes), each state
    held until the next, so it may be sampled at another rate without losing anything.
    """

    source: str
    block: SampleBlock
    units: Mapping[str, str] = field(default_factory=dict)
    start_s: float = 0.0
    form: str = ""  # "sigrok session", "VCD", "sigrok CSV", "CSV", "Rigol CSV", ...
    changes: bool = False

    @property
    def sample_rate_hz(self) -> float:
        return self.block.sample_rate_hz

    @property
    def samples(self) -> int:
        return self.block.samples

    @property
    def channels(self) -> tuple[str, ...]:
        return self.block.channels

    def has(self, name: str) -> bool:
        """True if the capture has a channel of this name."""
        return name in self.block.channels

    def _missing(self, name: str) -> CaptureError:
        return CaptureError(f"{self.source}: no channel '{name}' (the {self.form or 'file'} has "
                            f"{', '.join(self.channels) or 'no channels'})")

    def analog(self, name: str) -> np.ndarray:
        """An analog channel's samples (float32, in ``units[name]``)."""
        if name not in self.block.analog:
            if name in self.block.logic_channels:
                return self.block.bit(name).astype(np.float32)
            raise self._missing(name)
        return self.block.analog[name]

    def logic(self, name: str) -> np.ndarray:
        """A channel as logic levels (bool): a logic channel as it is, an analog one (an
        oscilloscope's trace of a line driver) through a Schmitt trigger between its low and high
        levels, so noise on a level does not make edges."""
        if name in self.block.logic_channels:
            return self.block.bit(name)
        if name not in self.block.analog:
            raise self._missing(name)
        return schmitt(self.block.analog[name])


def schmitt(values: np.ndarray, hysteresis: float = 0.2) -> np.ndarray:
    """Logic levels of an analog trace: high above ``mid + h``, low below ``mid - h``, else as
    before, where ``mid`` is halfway between its low and high levels (1st and 99th percentile)
    and ``h`` is ``hysteresis`` x their difference."""
    v = np.asarray(values, dtype=np.float32)
    if v.size == 0:
        return np.zeros(0, bool)
    low, high = np.percentile(v, [1.0, 99.0])
    mid = 0.5 * (low + high)
    h = hysteresis * (high - low)
    state = np.full(v.shape, -1, np.int8)
    state[v > mid + h] = 1
    state[v < mid - h] = 0
    decided = np.flatnonzero(state >= 0)
    if decided.size == 0:
        return np.zeros(v.shape, bool)
    # forward-fill the undecided samples with the last decided level (the first ones take the first)
    last = np.zeros(v.shape, np.int64)
    last[decided] = decided
    np.maximum.accumulate(last, out=last)
    last[: decided[0]] = decided[0]
    levels: np.ndarray = state[last] == 1
    return levels


def pack_logic(bits: Mapping[str, np.ndarray] | Sequence[np.ndarray]) -> np.ndarray:
    """Bool arrays (channel 0 first) packed into one unsigned integer per sample."""
    arrays = list(bits.values()) if isinstance(bits, Mapping) else list(bits)
    dtype = logic_dtype(max(1, len(arrays)))
    if not arrays:
        return np.zeros(0, dtype)
    out = np.zeros(len(arrays[0]), dtype)
    for index, values in enumerate(arrays):
        out |= np.asarray(values, dtype=bool).astype(dtype) << dtype(index)
    return out
