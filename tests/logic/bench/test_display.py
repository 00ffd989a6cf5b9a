"""Display rows of a live stream: the same rows however the stream was cut into blocks, a short
pulse still shows, analog windows are averaged."""

from __future__ import annotations

import numpy as np

from fha_studio.hardware.bench.capture import SampleBlock, pack_logic
from fha_studio.logic.bench.display import Decimator, display_factor


def _stream(n: int = 10_007) -> SampleBlock:
    rng = np.random.default_rng(5)
    a = rng.random(n) < 0.01  # rare one-sample pulses
    b = np.zeros(n, bool)
    b[5000:] = True
    return SampleBlock(1e6, ("D0", "D1"), pack_logic([a, b]), {})


def _cut(block: SampleBlock, sizes: list[int]) -> list[SampleBlock]:
    out, start = [], 0
    for size in sizes:
        out.append(SampleBlock(block.sample_rate_hz, block.logic_channels, block.logic[start:start + size],
                               {}, start))
        start += size
    return out


def test_rows_do_not_depend_on_how_the_stream_was_cut():
    whole = _stream()
    one = Decimator(1e6, ("D0", "D1"), 100).feed(whole)
    decimator = Decimator(1e6, ("D0", "D1"), 100)
    pieces = np.concatenate([decimator.feed(b) for b in _cut(whole, [1, 99, 150, 3001, 6756])])
    assert one.shape == (100, 3) and np.array_equal(one, pieces)
    assert np.allclose(one[:, 0], np.arange(100) * 1e-4)  # t_s of each window's first sample


def test_a_pulse_shorter_than_a_window_shows_and_levels_stay_levels():
    block = _stream()
    rows = Decimator(1e6, ("D0", "D1"), 100).feed(block)
    pulses = block.bit("D0")[:10_000].reshape(100, 100).any(axis=1)
    assert np.array_equal(rows[:, 1] == 1.0, pulses) and pulses.sum() > 30
    assert np.array_equal(rows[:, 2], np.repeat([0.0, 1.0], 50))


def test_analog_windows_are_averaged_and_slow_instruments_are_not_decimated():
    values = np.arange(12, dtype=np.float32)
    rows = Decimator(1e3, ("A0",), 4).feed(SampleBlock(1e3, (), np.zeros(0, np.uint8), {"A0": values}))
    assert np.array_equal(rows[:, 1], [1.5, 5.5, 9.5])
    assert display_factor(24e6) == 2400 and display_factor(10e3) == 1 and display_factor(1e3) == 1
    assert display_factor(15e3) == 2


def test_encoder_counts_carry_on_across_blocks_as_on_the_whole_stream():
    from fha_studio.logic.bench.decode import quadrature
    from fha_studio.logic.bench.display import LiveQuadrature

    # an encoder forward 3 turns' worth of edges, then back: phase 0..3 as A/B levels
    rng = np.random.default_rng(7)
    steps = np.concatenate([np.ones(4000, int), -np.ones(1500, int)])
    phase = np.repeat(np.cumsum(steps) % 4, rng.integers(1, 6, steps.size))
    a = np.isin(phase, (1, 2))
    b = np.isin(phase, (2, 3))
    whole = quadrature(a, b).counts
    live = LiveQuadrature()
    cuts = np.sort(rng.choice(np.arange(1, a.size), 40, replace=False))
    pieces = zip(np.split(a, cuts), np.split(b, cuts), strict=True)
    counts = np.concatenate([live.feed(x, y) for x, y in pieces])
    # 4000 steps forward, 1500 back; the first sample is already one step on (the reference)
    assert np.array_equal(counts, whole) and live.counts == whole[-1] == 2499
    assert live.illegal_transitions == 0
