"""A live bench stream brought down to what a screen shows: rows ``[t_s, channel values...]`` at
about :data:`DISPLAY_RATE_HZ`, for the scope's ring buffer. No Qt.

A logic analyzer at 24 MS/s is far more than a plot draws (a few thousand points across), and far
more than a float64 ring holds. Each window of ``factor`` samples becomes one row: a logic
channel is high if it was high anywhere in the window (a pulse shorter than a window still
shows), an analog channel is the window's mean (noise averaged, not aliased). Windows run on
across blocks, so the rows of a stream are the same however sigrok-cli cut it.
"""

from __future__ import annotations

import math

import numpy as np

from fha_studio.hardware.bench.capture import SampleBlock
from fha_studio.logic.bench import decode

#: Rows per second that go to the scope (each channel).
DISPLAY_RATE_HZ = 10_000.0


def display_factor(sample_rate_hz: float, display_rate_hz: float = DISPLAY_RATE_HZ) -> int:
    """Samples per row: 1 when the instrument is slower than the display rate."""
    return max(1, math.ceil(sample_rate_hz / display_rate_hz - 1e-9))


class Decimator:
    """Cuts consecutive blocks of one stream into display rows (see the module's text)."""

    def __init__(self, sample_rate_hz: float, channels: tuple[str, ...], factor: int,
                 extra: tuple[str, ...] = ()):
        self.sample_rate_hz = sample_rate_hz
        self.channels = channels
        self.extra = extra  # columns computed per sample (encoder counts): a window's last value
        self.factor = factor
        self._carry: np.ndarray | None = None  # (m, n_channels) samples short of a window
        self._next_sample = 0  # index of the first sample in the carry (or of the next block)

    @property
    def row_rate_hz(self) -> float:
        return self.sample_rate_hz / self.factor

    def _columns(self, block: SampleBlock, extra: dict[str, np.ndarray]) -> np.ndarray:
        columns = np.empty((block.samples, len(self.channels) + len(self.extra)), np.float64)
        for i, name in enumerate(self.channels):
            columns[:, i] = block.bit(name) if name in block.logic_channels else block.analog[name]
        for i, name in enumerate(self.extra):
            columns[:, len(self.channels) + i] = extra[name]
        return columns

    def feed(self, block: SampleBlock, extra: dict[str, np.ndarray] | None = None) -> np.ndarray:
        """The rows the block completes: shape ``(rows, 1 + channels + extra)``, ``t_s`` first."""
        values = self._columns(block, extra or {})
        width = values.shape[1]
        if self._carry is not None and len(self._carry):
            values = np.concatenate([self._carry, values])
        k = self.factor
        whole = len(values) // k * k
        self._carry = values[whole:]
        windows = values[:whole].reshape(-1, k, width)
        rows = np.empty((len(windows), 1 + width))
        rows[:, 0] = (self._next_sample + np.arange(len(windows)) * k) / self.sample_rate_hz
        for i, name in enumerate(self.channels):
            if name in block.logic_channels:
                rows[:, 1 + i] = windows[:, :, i].max(axis=1)
            else:
                rows[:, 1 + i] = windows[:, :, i].mean(axis=1)
        for i in range(len(self.channels), width):
            rows[:, 1 + i] = windows[:, -1, i]
        self._next_sample += whole
        return rows


class LiveQuadrature:
    """Encoder A/B counted x4 as the blocks arrive: the counts of each sample carry on from the
    previous block (the last sample of one block is the first edge's reference of the next), so
    the counts are those of :func:`decode.quadrature` on the whole stream; illegal transitions are
    summed."""

    def __init__(self) -> None:
        self._last: tuple[bool, bool] | None = None
        self.counts = 0  # after the last sample fed
        self.illegal_transitions = 0

    def feed(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """The counts (int64) at each sample of the block."""
        if a.size == 0:
            return np.zeros(0, np.int64)
        if self._last is None:
            self._last = (bool(a[0]), bool(b[0]))
        result = decode.quadrature(np.concatenate([[self._last[0]], a]), np.concatenate([[self._last[1]], b]))
        counts = result.counts[1:] + self.counts
        self.counts = int(counts[-1])
        self.illegal_transitions += result.illegal_transitions
        self._last = (bool(a[-1]), bool(b[-1]))
        return counts


class LiveCommandPulses:
    """The command pulse lines decoded as the blocks arrive (parameter 1's form, parameter 2's
    multiplication, the electronic gear 3/4), carried across blocks as :class:`LiveQuadrature`
    carries the encoder: the counts are those of :func:`decode.command_pulses` on the whole
    stream."""

    def __init__(self, pulse_form: int, multiplication: int, gear_numerator: int, gear_denominator: int):
        # checked once, on an empty stream: a bad form or gear is refused before any block
        decode.command_pulses(np.zeros(1, bool), np.zeros(1, bool), pulse_form, multiplication,
                              gear_numerator, gear_denominator)
        self.pulse_form = pulse_form
        self.multiplication = multiplication
        self.gear = (gear_numerator, gear_denominator)
        self._last: tuple[bool, bool] | None = None
        self._edges = LiveQuadrature() if pulse_form == 2 else None
        self.pulses = 0  # after the last sample fed
        self.illegal_transitions = 0

    def feed(self, a: np.ndarray, b: np.ndarray | None) -> np.ndarray:
        """The commanded encoder counts (float64) at each sample of the block."""
        if a.size == 0:
            return np.zeros(0)
        numerator, denominator = self.gear
        if self._edges is not None:
            if b is None:
                raise decode.DecodeError("two-phase command pulses (parameter 1 = 2) need both lines")
            edges = self._edges.feed(a, b)
            self.illegal_transitions = self._edges.illegal_transitions
            pulses = np.floor_divide(edges, 4 // self.multiplication)
        else:
            b_line = b if b is not None else np.zeros(a.size, bool)
            if self._last is None:
                self._last = (bool(a[0]), bool(b_line[0]))
            line_b = np.concatenate([[self._last[1]], b_line]) if b is not None else None
            result = decode.command_pulses(np.concatenate([[self._last[0]], a]), line_b,
                                           self.pulse_form, self.multiplication, 1, 1)
            pulses = result.pulses[1:] + self.pulses
            self._last = (bool(a[-1]), bool(b_line[-1]))
        self.pulses = int(pulses[-1])
        counts: np.ndarray = pulses * (numerator / denominator)
        return counts
