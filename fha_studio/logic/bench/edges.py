"""Logic lines and counts held where they change (numpy, vectorised): what makes a capture of
millions of samples decode in less than its own time.

A logic analyzer's capture is mostly samples in which nothing changes: 8 channels at 24 MS/s are
24 million samples a second, while an encoder at 3000 r/min (motor) makes 500 000 edges. The
decoders therefore find the samples where the packed logic word changes once (one pass of
``np.flatnonzero`` over the packed bytes) and work on those changes only:

- :class:`Lines`: up to 8 logic lines as the samples where any of them changes and the lines'
  code from there on (bit ``j`` = line ``j``);
- :class:`Steps`: a per-sample series (encoder counts, command pulses) as the samples where it
  changes and its value from there on; :meth:`Steps.sample` reads it at any samples and
  :meth:`Steps.dense` gives it per sample where one is wanted.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@functools.lru_cache(maxsize=64)
def _code_table(bits: tuple[int, ...]) -> np.ndarray:
    """Byte -> the code of its bits ``bits`` (bit j of the code = bit ``bits[j]`` of the byte)."""
    byte = np.arange(256)
    code = np.zeros(256, np.uint8)
    for j, bit in enumerate(bits):
        code |= (((byte >> bit) & 1) << j).astype(np.uint8)
    return code


def changes(values: np.ndarray) -> np.ndarray:
    """Indices i >= 1 where values[i] != values[i-1] (int64)."""
    at: np.ndarray = np.flatnonzero(values[1:] != values[:-1]) + 1
    return at


@dataclass(frozen=True)
class Steps:
    """A series of ``n`` samples: ``initial`` before ``at[0]``, ``values[k]`` from sample ``at[k]``
    until ``at[k + 1]``; ``at`` strictly increasing within 1 ... n - 1."""

    n: int
    at: np.ndarray
    values: np.ndarray
    initial: float = 0

    @classmethod
    def from_increments(cls, n: int, at: np.ndarray, increments: np.ndarray) -> Steps:
        """The running sum of ``increments`` added at samples ``at`` (sorted, repeats summed,
        samples where they cancel dropped), starting from 0."""
        at = np.asarray(at, np.int64)
        inc = np.asarray(increments)
        if at.size == 0:
            return cls(n, at, inc[:0].astype(np.int64))
        if at.size > 1 and np.any(at[1:] <= at[:-1]):
            order = np.argsort(at, kind="stable")
            at, inc = at[order], inc[order]
            first = np.concatenate(([True], at[1:] != at[:-1]))
            starts = np.flatnonzero(first)
            inc = np.add.reduceat(inc, starts)
            at = at[starts]
        keep = inc != 0
        return cls(n, at[keep], np.cumsum(inc[keep]))

    def compressed(self) -> Steps:
        """The same series without the changes that change nothing."""
        if self.at.size == 0:
            return self
        previous = np.concatenate(([self.initial], self.values[:-1]))
        keep = self.values != previous
        return Steps(self.n, self.at[keep], self.values[keep], self.initial)

    def scaled(self, factor: float) -> Steps:
        return Steps(self.n, self.at, self.values * factor, self.initial * factor)

    def sample(self, idx: np.ndarray | Sequence[int]) -> np.ndarray:
        """The values at sample indices ``idx``."""
        k = np.searchsorted(self.at, np.asarray(idx), side="right") - 1
        table = np.concatenate(([self.initial], self.values)).astype(
            np.result_type(self.values, type(self.initial)))
        out: np.ndarray = table[k + 1]
        return out

    def dense(self) -> np.ndarray:
        """The value at every sample."""
        lengths = np.diff(np.concatenate(([0], self.at, [self.n])))
        table = np.concatenate(([self.initial], self.values)).astype(
            np.result_type(self.values, type(self.initial)))
        out: np.ndarray = np.repeat(table, lengths)
        return out

    @property
    def final(self) -> float:
        """The value at the last sample."""
        return self.values[-1].item() if self.values.size else self.initial


@dataclass(frozen=True)
class Lines:
    """Up to 8 logic lines of ``n`` samples: ``first`` (bit ``j`` = line ``j``) at sample 0, then
    ``codes[k]`` from sample ``at[k]`` (every ``at`` a sample where the code changes)."""

    n: int
    first: int
    at: np.ndarray  # int64
    codes: np.ndarray  # uint8

    @classmethod
    def from_packed(cls, packed: np.ndarray, *bits: int) -> Lines:
        """Bits ``bits`` of a packed logic word (sigrok's packing) as lines 0, 1, ...: the word
        masked to those bits is compared with itself one sample on, once."""
        mask = packed.dtype.type(sum(1 << bit for bit in bits))
        masked = packed & mask
        at = changes(masked)
        n = int(packed.shape[0])
        words = masked[at]
        first = 0
        for j, bit in enumerate(bits):
            first |= (int(masked[0]) >> bit & 1) << j if n else 0
        if packed.dtype == np.uint8:  # one byte a sample: the code of each word by a table
            return cls(n, first, at, _code_table(tuple(bits))[words])
        codes = np.zeros(at.size, np.uint8)
        for j, bit in enumerate(bits):
            codes |= ((words >> packed.dtype.type(bit)) & 1).astype(np.uint8) << np.uint8(j)
        return cls(n, first, at, codes)

    @classmethod
    def from_levels(cls, *levels: np.ndarray) -> Lines:
        """Lines from bool arrays of one length (line 0 first)."""
        n = int(levels[0].shape[0])
        code = np.zeros(n, np.uint8)
        for j, level in enumerate(levels):
            code |= np.asarray(level, bool).view(np.uint8) << np.uint8(j)
        at = changes(code)
        return cls(n, int(code[0]) if n else 0, at, code[at])

    @classmethod
    def merge(cls, *lines: Lines) -> Lines:
        """Single lines (each line 0 of its own) as lines 0, 1, ... of one."""
        n = min(line.n for line in lines)
        at = np.sort(np.concatenate([line.at[line.at < n] for line in lines]))
        if at.size > 1:
            at = at[np.concatenate(([True], at[1:] != at[:-1]))]
        code = np.zeros(at.size, np.uint8)
        first = 0
        for j, line in enumerate(lines):
            code |= line.level_at(at).view(np.uint8) << np.uint8(j)
            first |= (line.first & 1) << j
        previous = np.concatenate(([first], code[:-1])).astype(np.uint8)
        keep = code != previous
        return cls(n, first, at[keep], code[keep])

    def code_at(self, idx: np.ndarray | Sequence[int]) -> np.ndarray:
        """The code at sample indices ``idx``."""
        k = np.searchsorted(self.at, np.asarray(idx), side="right") - 1
        table = np.concatenate(([self.first], self.codes)).astype(np.uint8)
        out: np.ndarray = table[k + 1]
        return out

    def level_at(self, idx: np.ndarray | Sequence[int], line: int = 0) -> np.ndarray:
        """Line ``line``'s level (bool) at sample indices ``idx``."""
        out: np.ndarray = (self.code_at(idx) >> np.uint8(line)) & np.uint8(1) == 1
        return out

    def rising(self, line: int = 0) -> np.ndarray:
        """Samples where line ``line`` goes from low to high."""
        level = (self.codes >> np.uint8(line)) & np.uint8(1)
        previous = np.concatenate(([(self.first >> line) & 1], level[:-1]))
        rises: np.ndarray = self.at[(level == 1) & (previous == 0)]
        return rises

    def level(self, line: int = 0) -> np.ndarray:
        """Line ``line`` at every sample (bool)."""
        lengths = np.diff(np.concatenate(([0], self.at, [self.n])))
        table = (np.concatenate(([self.first], self.codes)).astype(np.uint8) >> np.uint8(line)) & 1
        out: np.ndarray = np.repeat(table.astype(bool), lengths)
        return out
