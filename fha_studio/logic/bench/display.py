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

#: Rows per second that go to the scope (each channel).
DISPLAY_RATE_HZ = 10_000.0


def display_factor(sample_rate_hz: float, display_rate_hz: float = DISPLAY_RATE_HZ) -> int:
    """Samples per row: 1 when the instrument is slower than the display rate."""
    return max(1, math.ceil(sample_rate_hz / display_rate_hz - 1e-9))


class Decimator:
    """Cuts consecutive blocks of one stream into display rows (see the module's text)."""

    def __init__(self, sample_rate_hz: float, channels: tuple[str, ...], factor: int):
        self.sample_rate_hz = sample_rate_hz
        self.channels = channels
        self.factor = factor
        self._carry: np.ndarray | None = None  # (m, n_channels) samples short of a window
        self._next_sample = 0  # index of the first sample in the carry (or of the next block)

    @property
    def row_rate_hz(self) -> float:
        return self.sample_rate_hz / self.factor

    def _columns(self, block: SampleBlock) -> np.ndarray:
        columns = np.empty((block.samples, len(self.channels)), np.float64)
        for i, name in enumerate(self.channels):
            columns[:, i] = block.bit(name) if name in block.logic_channels else block.analog[name]
        return columns

    def feed(self, block: SampleBlock) -> np.ndarray:
        """The rows the block completes: shape ``(rows, 1 + channels)``, ``t_s`` first."""
        values = self._columns(block)
        if self._carry is not None and len(self._carry):
            values = np.concatenate([self._carry, values])
        k = self.factor
        whole = len(values) // k * k
        self._carry = values[whole:]
        windows = values[:whole].reshape(-1, k, len(self.channels))
        rows = np.empty((len(windows), 1 + len(self.channels)))
        rows[:, 0] = (self._next_sample + np.arange(len(windows)) * k) / self.sample_rate_hz
        for i, name in enumerate(self.channels):
            if name in block.logic_channels:
                rows[:, 1 + i] = windows[:, :, i].max(axis=1)
            else:
                rows[:, 1 + i] = windows[:, :, i].mean(axis=1)
        self._next_sample += whole
        return rows
