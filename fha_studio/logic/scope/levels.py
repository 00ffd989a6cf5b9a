"""Min/max levels of a growing multi-channel signal, for drawing a long window fast. No Qt.

A live view of 4 channels x 60 s at 1 kHz has 240 000 points, and a screen about 1400 pixels.
Re-decimating the whole window on every frame costs more than drawing it; instead each new
block of samples is appended to a pyramid of pre-decimated levels: level k holds, for every
2^k consecutive samples, their first and last time and each channel's minimum and maximum.
Drawing a window then reads the finest level with at most about one bin per pixel, two points a
bin (minimum, maximum), as pyqtgraph's "peak" downsampling would, for the cost of a slice.
"""

from __future__ import annotations

import numpy as np

from fha_studio.logic.scope.ring import RingBuffer

#: Coarsest level kept: bins of 2^16 samples (65 s at 1 kHz in one bin).
MAX_LEVEL = 16


class MinMaxLevels:
    """Rows ``[t_s, values...]`` in, min/max envelopes out (``window``).

    ``capacity``: samples kept at level 0 (older ones drop out of every level alike).
    """

    def __init__(self, n_channels: int, capacity: int):
        if n_channels < 1 or capacity < 2:
            raise ValueError(f"min/max levels need channels >= 1 and capacity >= 2, got {n_channels}, "
                             f"{capacity}")
        self.n_channels = n_channels
        self.capacity = capacity
        # a level row: [t_first, t_last, minimum per channel..., maximum per channel...]
        width = 2 + 2 * n_channels
        self._levels: list[RingBuffer] = []
        size = capacity
        while len(self._levels) <= MAX_LEVEL and size >= 2:
            self._levels.append(RingBuffer(width, size))
            size //= 2
        self._pending: list[np.ndarray] = [np.empty((0, width)) for _ in self._levels]

    @property
    def levels(self) -> int:
        return len(self._levels)

    def __len__(self) -> int:
        return len(self._levels[0])

    def append(self, rows: np.ndarray) -> None:
        """Add samples ``[t_s, values...]`` (oldest first, times rising)."""
        rows = np.asarray(rows, dtype=float)
        if rows.ndim != 2 or len(rows) == 0:
            return
        c = self.n_channels
        if rows.shape[1] != 1 + c:
            raise ValueError(f"rows have {rows.shape[1] - 1} channels, the levels {c}")
        block = np.empty((len(rows), 2 + 2 * c))
        block[:, 0] = block[:, 1] = rows[:, 0]
        block[:, 2 : 2 + c] = block[:, 2 + c :] = rows[:, 1:]
        for k, ring in enumerate(self._levels):
            ring.write(block)
            if k + 1 == len(self._levels):
                break
            joined = np.concatenate([self._pending[k], block]) if len(self._pending[k]) else block
            pairs = len(joined) // 2
            self._pending[k] = joined[2 * pairs :].copy()
            if pairs == 0:
                break
            a, b = joined[0 : 2 * pairs : 2], joined[1 : 2 * pairs : 2]
            block = np.empty((pairs, 2 + 2 * c))
            block[:, 0] = a[:, 0]
            block[:, 1] = b[:, 1]
            np.minimum(a[:, 2 : 2 + c], b[:, 2 : 2 + c], out=block[:, 2 : 2 + c])
            np.maximum(a[:, 2 + c :], b[:, 2 + c :], out=block[:, 2 + c :])

    def clear(self) -> None:
        for ring in self._levels:
            ring.clear()
        self._pending = [p[:0] for p in self._pending]

    def level_for(self, t0_s: float, t1_s: float, bins: int) -> int:
        """The finest level whose bins in [t0_s, t1_s] are at most ``bins``."""
        raw = self._levels[0].window()
        i0, i1 = np.searchsorted(raw[:, 0], [t0_s, t1_s])
        n = int(i1 - i0)
        level = 0
        while n > bins and level + 1 < len(self._levels):
            level += 1
            n //= 2
        return level

    def window(self, t0_s: float, t1_s: float, bins: int) -> tuple[np.ndarray, np.ndarray]:
        """(t, y) of the samples in [t0_s, t1_s] (one bin either side, so lines reach the edges):
        at level 0 the samples themselves, coarser the minimum at each bin's first time and the
        maximum at its last (at most ``2 * bins`` points). ``y`` has one column per channel."""
        level = self.level_for(t0_s, t1_s, bins)
        data = self._levels[level].window()
        i0 = int(np.searchsorted(data[:, 0], t0_s))
        i1 = int(np.searchsorted(data[:, 0], t1_s, side="right"))
        part = data[max(0, i0 - 1) : i1 + 1]
        c = self.n_channels
        if level == 0:
            return part[:, 0].copy(), part[:, 2 : 2 + c].copy()
        t = np.empty(2 * len(part))
        t[0::2], t[1::2] = part[:, 0], part[:, 1]
        y = np.empty((2 * len(part), c))
        y[0::2], y[1::2] = part[:, 2 : 2 + c], part[:, 2 + c :]
        return t, y
