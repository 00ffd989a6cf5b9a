"""A multi-channel ring buffer between the acquisition side and the GUI timer that draws.

friture's pattern: the acquisition thread writes blocks, one GUI-thread timer drains whole
blocks; samples are never hidden, overflows are counted. Every sample is written twice into a
double-length array, so that any recent window is one contiguous view, with no copy.
"""

from __future__ import annotations

import threading

import numpy as np


class RingBuffer:
    """Holds the newest ``capacity`` rows of ``n_channels`` float64 samples.

    ``write`` may be called from any thread; ``drain`` and ``window`` from the consumer.
    """

    def __init__(self, n_channels: int, capacity: int):
        if n_channels < 1 or capacity < 1:
            raise ValueError(f"a ring buffer needs channels and capacity >= 1, got {n_channels}, {capacity}")
        self.n_channels = n_channels
        self.capacity = capacity
        self._data = np.zeros((2 * capacity, n_channels))
        self._lock = threading.Lock()
        self._written = 0  # rows written since creation
        self._drained = 0  # rows handed to drain() or dropped
        self.dropped = 0  # rows overwritten before anybody drained them

    @property
    def written(self) -> int:
        """Rows written since creation (or the last clear)."""
        return self._written

    def __len__(self) -> int:
        return min(self._written, self.capacity)

    def write(self, block: np.ndarray) -> None:
        """Append rows (shape ``(n, n_channels)`` or one row of ``n_channels``)."""
        block = np.asarray(block, dtype=float)
        if block.ndim == 1:
            block = block.reshape(1, -1)
        if block.shape[1] != self.n_channels:
            raise ValueError(f"block has {block.shape[1]} channels, the buffer {self.n_channels}")
        cap = self.capacity
        with self._lock:
            if len(block) > cap:  # only the newest capacity rows can be kept
                skipped = len(block) - cap
                self._written += skipped
                block = block[-cap:]
            start = self._written % cap
            first = min(len(block), cap - start)
            for offset in (0, cap):  # the double write
                self._data[start + offset : start + offset + first] = block[:first]
                self._data[offset : offset + len(block) - first] = block[first:]
            self._written += len(block)
            lost = self._written - self._drained - cap
            if lost > 0:
                self.dropped += lost
                self._drained += lost

    def drain(self) -> np.ndarray:
        """The rows written since the previous drain, oldest first (a copy)."""
        with self._lock:
            n = self._written - self._drained
            self._drained = self._written
            return self._tail(n).copy()

    def window(self, n: int | None = None, *, copy: bool = False) -> np.ndarray:
        """The newest ``n`` rows (all held rows when None), oldest first: a contiguous read-only
        view, or with ``copy`` a copy taken under the lock.

        A view is no snapshot: the writer's next rows overwrite its oldest ones (a view of the
        whole ring turns into newer rows at its start, out of time order, while it is read). A
        view is for a few newest rows; a reader of more than the writer may write meanwhile (up
        to the whole ring, from another thread) asks for the copy."""
        with self._lock:
            held = min(self._written, self.capacity)
            view = self._tail(held if n is None else min(n, held))
            if copy:
                return view.copy()
        view.flags.writeable = False
        return view

    def _tail(self, n: int) -> np.ndarray:
        end = self._written % self.capacity + self.capacity
        return self._data[end - n : end]

    def clear(self) -> None:
        with self._lock:
            self._written = self._drained = self.dropped = 0
