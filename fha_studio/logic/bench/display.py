"""A live bench stream brought down to what a screen shows: rows ``[t_s, channel values...]`` at
about :data:`DISPLAY_RATE_HZ`, for the scope's ring buffer. No Qt.

A logic analyzer at 24 MS/s is far more than a plot draws (a few thousand points across), and far
more than a float64 ring holds. Each window of ``factor`` samples becomes one row: a logic
channel is 1 where it was high all through the window, 0 where it was low all through, and
:data:`CHANGED` (0.5) where it was both (a pulse shorter than a window still shows, and an
encoder line toggling far faster than the rows is a busy line, not a steady level: taken as
high-anywhere it read as stuck high all through a move); an analog channel is the window's mean
(noise averaged, not aliased). Windows run on
across blocks, so the rows of a stream are the same however sigrok-cli cut it.

The encoder's counts and the commanded counts of a row are those at its window's last sample.
A live stream needs no more of them, so :meth:`LiveQuadrature.feed_windows` and
:meth:`LiveCommandPulses.feed_windows` take them from every sample's step with a few bit
operations and one sum per window, instead of finding each change of the lines first: the
same counts for a third of the CPU where the lines change often (sigrok's demo changes its
D0/D1 in 42 % of the samples; a real encoder at speed in a few %).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

import numpy as np

from fha_studio.hardware.bench.capture import SampleBlock, pack_logic
from fha_studio.logic.bench import decode
from fha_studio.logic.bench.edges import Lines, Steps

#: Rows per second that go to the scope (each channel).
DISPLAY_RATE_HZ = 10_000.0
#: A logic channel's row value where it was high and low within the window (high anywhere is
#: ``>= CHANGED``, high throughout is ``> CHANGED``).
CHANGED = 0.5


def display_factor(sample_rate_hz: float, display_rate_hz: float = DISPLAY_RATE_HZ) -> int:
    """Samples per row: 1 when the instrument is slower than the display rate."""
    return max(1, math.ceil(sample_rate_hz / display_rate_hz - 1e-9))


class Decimator:
    """Cuts consecutive blocks of one stream into display rows (see the module's text).

    A block's logic channels are taken as the packed word (one OR over each window's bytes, then
    each channel's bit of the row), never one array per channel: 24 MS/s stay a few passes over
    one byte a sample."""

    def __init__(self, sample_rate_hz: float, channels: tuple[str, ...], factor: int,
                 extra: tuple[str, ...] = ()):
        self.sample_rate_hz = sample_rate_hz
        self.channels = channels
        self.extra = extra  # columns computed per sample (encoder counts): a window's last value
        self.factor = factor
        self._carry_logic: np.ndarray | None = None  # the samples short of a window (packed)
        self._carry_analog: dict[str, np.ndarray] = {}
        self._carried = 0
        self._next_sample = 0  # index of the first sample in the carry (or of the next block)

    @property
    def row_rate_hz(self) -> float:
        return self.sample_rate_hz / self.factor

    def feed(self, block: SampleBlock,
             extra: Mapping[str, np.ndarray | Steps | Callable[[np.ndarray], np.ndarray]] | None = None
             ) -> np.ndarray:
        """The rows the block completes: shape ``(rows, 1 + channels + extra)``, ``t_s`` first.
        ``extra``: per sample of the block, an array or :class:`Steps`; or a function that is
        given the block's samples that end a window (maybe none) and returns the values there."""
        extra = extra or {}
        k, m = self.factor, self._carried
        n = m + block.samples
        count = n // k
        whole = count * k
        rows = np.empty((count, 1 + len(self.channels) + len(self.extra)))
        rows[:, 0] = (self._next_sample + np.arange(count) * k) / self.sample_rate_hz
        logic = block.logic
        if m and self._carry_logic is not None:
            logic = np.concatenate([self._carry_logic, logic])
        anywhere = throughout = None
        for i, name in enumerate(self.channels):
            if name in block.logic_channels:
                if anywhere is None or throughout is None:
                    shaped = logic[:whole].reshape(count, k)
                    anywhere = np.bitwise_or.reduce(shaped, axis=1) if count else logic[:0]
                    throughout = np.bitwise_and.reduce(shaped, axis=1) if count else logic[:0]
                bit = logic.dtype.type(block.logic_channels.index(name))
                rows[:, 1 + i] = (((anywhere >> bit) & 1) + ((throughout >> bit) & 1)) * CHANGED
            else:
                values = block.analog[name]
                if m:
                    values = np.concatenate([self._carry_analog[name], values])
                rows[:, 1 + i] = values[:whole].reshape(count, k).mean(axis=1, dtype=np.float64)
                self._carry_analog[name] = values[whole:]
        ends = (k - m - 1) + np.arange(count) * k  # each window's last sample, in the block
        for i, name in enumerate(self.extra):
            column = extra[name]
            if isinstance(column, Steps):
                rows[:, 1 + len(self.channels) + i] = column.sample(ends)
            elif callable(column):
                rows[:, 1 + len(self.channels) + i] = column(ends)
            else:
                rows[:, 1 + len(self.channels) + i] = column[ends]
        self._carry_logic = logic[whole:] if block.logic_channels else None
        self._carried = n - whole
        self._next_sample += whole
        return rows


class LiveQuadrature:
    """Encoder A/B counted x4 as the blocks arrive: the counts of each sample carry on from the
    previous block (the last sample of one block is the first edge's reference of the next), so
    the counts are those of :func:`decode.quadrature` on the whole stream; illegal transitions are
    summed."""

    def __init__(self) -> None:
        self._last: np.ndarray | None = None  # the previous block's last sample (levels or word)
        self.counts = 0  # after the last sample fed
        self.illegal_transitions = 0

    def feed(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """The counts (int64) at each sample of the block."""
        if a.size == 0:
            return np.zeros(0, np.int64)
        return self.feed_packed(pack_logic([a, b]), 0, 1).dense().astype(np.int64)

    def feed_packed(self, logic: np.ndarray, bit_a: int, bit_b: int) -> Steps:
        """The counts at each sample of a block of packed logic words (A and B at those bits),
        held where they change."""
        lines = _with_last(self, logic, bit_a, bit_b)
        if lines is None:
            return Steps(0, np.zeros(0, np.int64), np.zeros(0, np.int64), self.counts)
        result = decode.quadrature_lines(lines, glitches=False)
        counts = _shifted(result.steps, self.counts)
        self.counts = int(counts.final)
        self.illegal_transitions += result.illegal_transitions
        return counts

    def feed_windows(self, logic: np.ndarray, bit_a: int, bit_b: int, ends: np.ndarray) -> np.ndarray:
        """The counts (int64) at the block's samples ``ends`` (sorted), as
        ``feed_packed(...).sample(ends)`` gives them, from every sample's step (see the module's
        text); the whole block is counted whatever ``ends`` holds."""
        levels = _levels(self, logic, bit_a, bit_b)
        if levels is None:
            return np.full(len(ends), self.counts, np.int64)
        a, b = levels
        assert b is not None
        ap, ac, bp, bc = a[:-1], a[1:], b[:-1], b[1:]
        # Gray code steps: +1 where A leads B, -1 where B leads A, 0 where nothing or both changed
        step = (bp ^ ac).view(np.int8) - (ap ^ bc).view(np.int8)
        self.illegal_transitions += int(np.count_nonzero((ap ^ ac) & (bp ^ bc)))
        values, self.counts = _running(step, ends, self.counts)
        return values


def _with_last(owner: LiveQuadrature | LiveCommandPulses, logic: np.ndarray, *bits: int) -> Lines | None:
    """The block's lines with the previous block's last sample before its first (the reference
    of the block's first change)."""
    if logic.size == 0:
        return None
    if owner._last is None or owner._last.dtype != logic.dtype:
        owner._last = logic[:1]
    lines = Lines.from_packed(np.concatenate([owner._last, logic]), *bits)
    owner._last = logic[-1:].copy()
    return lines


def _levels(owner: LiveQuadrature | LiveCommandPulses, logic: np.ndarray, bit_a: int,
            bit_b: int | None) -> tuple[np.ndarray, np.ndarray | None] | None:
    """Bits A and B's levels (uint8 0/1) at the previous block's last sample and every sample of
    this one (B None: None), or None for an empty block."""
    if logic.size == 0:
        return None
    if owner._last is None or owner._last.dtype != logic.dtype:
        owner._last = logic[:1]
    words = np.empty(logic.size + 1, logic.dtype)
    words[0] = owner._last[0]
    words[1:] = logic
    owner._last = logic[-1:].copy()
    one = logic.dtype.type(1)

    def level(bit: int) -> np.ndarray:
        out: np.ndarray = ((words >> logic.dtype.type(bit)) & one).astype(np.uint8, copy=False)
        return out

    return level(bit_a), None if bit_b is None else level(bit_b)


def _running(step: np.ndarray, ends: np.ndarray, start: int) -> tuple[np.ndarray, int]:
    """The running sum of ``step`` from ``start`` at samples ``ends`` (sorted), and at the end:
    one sum per stretch up to each end, then their running sum."""
    starts = np.empty(len(ends) + 1, np.intp)
    starts[0] = 0
    starts[1:] = np.asarray(ends) + 1
    if starts[-1] >= step.size:  # the last window ends with the block
        starts = starts[:-1]
    run = start + np.cumsum(np.add.reduceat(step, starts, dtype=np.int64))
    return run[: len(ends)], int(run[-1])


def _shifted(steps: Steps, offset: float) -> Steps:
    """Steps of the previous sample and a block, as the block's alone, carried on from ``offset``."""
    return Steps(steps.n - 1, steps.at - 1, steps.values + offset, offset)


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
        self._last: np.ndarray | None = None
        self._edges = LiveQuadrature() if pulse_form == 2 else None
        self.pulses = 0  # after the last sample fed
        self.illegal_transitions = 0

    def feed(self, a: np.ndarray, b: np.ndarray | None) -> np.ndarray:
        """The commanded encoder counts (float64) at each sample of the block."""
        if a.size == 0:
            return np.zeros(0)
        if b is None:
            return self.feed_packed(pack_logic([a]), 0, None).dense().astype(np.float64)
        return self.feed_packed(pack_logic([a, b]), 0, 1).dense().astype(np.float64)

    def feed_packed(self, logic: np.ndarray, bit_a: int, bit_b: int | None) -> Steps:
        """The commanded encoder counts at each sample of a block of packed logic words, held
        where they change."""
        numerator, denominator = self.gear
        if self._edges is not None:
            if bit_b is None:
                raise decode.DecodeError("two-phase command pulses (parameter 1 = 2) need both lines")
            edges = self._edges.feed_packed(logic, bit_a, bit_b)
            self.illegal_transitions = self._edges.illegal_transitions
            divisor = 4 // self.multiplication
            pulses = Steps(edges.n, edges.at, np.floor_divide(edges.values, divisor),
                           edges.initial // divisor).compressed()
        else:
            lines = _with_last(self, logic, bit_a) if bit_b is None else _with_last(self, logic, bit_a, bit_b)
            if lines is None:
                return Steps(0, np.zeros(0, np.int64), np.zeros(0), self.pulses * numerator / denominator)
            result = decode.command_pulse_lines(lines, bit_b is not None, self.pulse_form,
                                                self.multiplication, 1, 1)
            pulses = _shifted(result.pulse_steps, self.pulses)
        self.pulses = int(pulses.final)
        return pulses.scaled(numerator / denominator)

    def feed_windows(self, logic: np.ndarray, bit_a: int, bit_b: int | None, ends: np.ndarray) -> np.ndarray:
        """The commanded counts at the block's samples ``ends`` (sorted), as
        ``feed_packed(...).sample(ends)`` gives them, from every sample (see the module's text)."""
        numerator, denominator = self.gear
        if self._edges is not None:
            if bit_b is None:
                raise decode.DecodeError("two-phase command pulses (parameter 1 = 2) need both lines")
            divisor = 4 // self.multiplication
            edges = self._edges.feed_windows(logic, bit_a, bit_b, ends)
            self.illegal_transitions = self._edges.illegal_transitions
            self.pulses = self._edges.counts // divisor
            out: np.ndarray = np.floor_divide(edges, divisor) * (numerator / denominator)
            return out
        levels = _levels(self, logic, bit_a, bit_b)
        if levels is None:
            return np.full(len(ends), self.pulses * numerator / denominator)
        a, b = levels
        rises = a[1:] & (a[:-1] ^ 1)  # A low before, high now
        inc = rises.view(np.int8)
        if b is not None and self.pulse_form == 0:  # two-pulse: REV pulses on B
            inc = inc - (b[1:] & (b[:-1] ^ 1)).view(np.int8)
        elif b is not None:  # pulse + sign: B high (ON) at the pulse = REV
            inc = inc - 2 * (rises & b[1:]).view(np.int8)
        values, self.pulses = _running(inc, ends, self.pulses)
        return values * (numerator / denominator)


def peak_rows(rows: np.ndarray, buckets: int) -> np.ndarray:
    """At most ``2 x buckets`` rows for a plot ``buckets`` pixels wide: each bucket of
    consecutive rows as its first row's time with each column's least value, then its last row's
    time with the largest (a pulse or a dip narrower than a pixel still shows). Fewer rows than
    that come back as they are."""
    n = len(rows)
    if buckets <= 0 or n <= 2 * buckets:
        return rows
    size = math.ceil(n / buckets)
    count = n // size
    whole = rows[: count * size].reshape(count, size, rows.shape[1])
    out = np.empty((2 * count, rows.shape[1]))
    out[0::2, 1:] = whole[:, :, 1:].min(axis=1)
    out[1::2, 1:] = whole[:, :, 1:].max(axis=1)
    out[0::2, 0] = whole[:, 0, 0]
    out[1::2, 0] = whole[:, -1, 0]
    tail = rows[count * size :]
    return np.concatenate([out, tail]) if len(tail) else out
