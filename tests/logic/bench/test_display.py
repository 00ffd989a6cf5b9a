"""Display rows of a live stream: the same rows however the stream was cut into blocks, a short
pulse still shows, analog windows are averaged."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from fha_studio.hardware.bench.capture import SampleBlock, pack_logic
from fha_studio.logic.bench.display import CHANGED, Decimator, display_factor


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
    assert np.array_equal(rows[:, 1] == CHANGED, pulses) and pulses.sum() > 30  # high and low in it
    assert np.array_equal(rows[:, 2], np.repeat([0.0, 1.0], 50))


def test_a_line_toggling_faster_than_the_rows_is_busy_not_stuck_high():
    n = 10_000
    a = (np.arange(n) // 7) % 2 == 1  # an encoder line at 71 kHz, the rows at 10 kHz
    rows = Decimator(1e6, ("A", "HIGH"), 100).feed(SampleBlock(1e6, ("A", "HIGH"),
                                                               pack_logic([a, np.ones(n, bool)]), {}))
    assert np.all(rows[:, 1] == CHANGED)  # taken as high anywhere it read as a steady high
    assert np.all(rows[:, 2] == 1.0)


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


@pytest.mark.parametrize(("pulse_form", "multiplication"), [(0, 4), (1, 4), (2, 4), (2, 1)])
def test_live_command_pulses_across_blocks_equal_decoding_the_whole_stream(pulse_form, multiplication):
    from fha_studio.logic.bench.decode import command_pulses
    from fha_studio.logic.bench.display import LiveCommandPulses

    rng = np.random.default_rng(pulse_form * 10 + multiplication)
    a = rng.random(5000) < 0.3
    b = rng.random(5000) < 0.5
    if pulse_form == 2:  # a legal two-phase train that goes back and forth
        steps = np.repeat(rng.choice([-1, 0, 1], 250, p=[0.3, 0.2, 0.5]), 20)
        phase = np.cumsum(steps) % 4
        a, b = (phase == 1) | (phase == 2), phase >= 2
    whole = command_pulses(a, b, pulse_form, multiplication, 3, 2).counts
    live = LiveCommandPulses(pulse_form, multiplication, 3, 2)
    cuts = [0, 1, 2, 700, 701, 2500, 5000]
    parts = [live.feed(a[i:j], b[i:j]) for i, j in itertools.pairwise(cuts)]
    got = np.concatenate(parts)
    assert np.array_equal(got - got[0], whole - whole[0]) and np.count_nonzero(np.diff(whole))


def test_bench_move_figures_take_in_position_from_in_pos_and_following_error_in_counts():
    from fha_studio.logic.bench.move import bench_move_figures

    t = np.arange(0, 1.0, 1e-4)
    cmd = np.clip((t - 0.1) / 0.2, 0, 1) * 1000.0  # 1000 counts from 0.1 s to 0.3 s
    enc = np.clip((t - 0.12) / 0.2, 0, 1) * 1000.0  # 20 ms behind: following error 100 counts
    in_pos = (np.abs(cmd - enc) <= 10) & (t > 0.4)  # the drive says in-position at 0.4 s
    figures = bench_move_figures(t, cmd, enc, in_pos, counts_per_deg=100.0)
    assert figures.metrics.target - figures.metrics.start == pytest.approx(10.0)
    assert figures.in_position_time_s == pytest.approx(0.1, abs=2e-4)
    assert figures.following_error_peak_counts == pytest.approx(100.0, abs=1.0)
    assert figures.following_error_end_counts == 0.0
    assert bench_move_figures(t, cmd, enc, np.zeros(t.size), 100.0).in_position_time_s is None


def _windows(rng, sizes, k):
    """Each block's samples that end a window of ``k``, as the Decimator gives them."""
    m, out = 0, []
    for size in sizes:
        n = m + size
        out.append((k - m - 1) + np.arange(n // k) * k)
        m = n - (n // k) * k
    return out


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
@pytest.mark.parametrize("decoder", ["quadrature", "two-pulse", "two-pulse, A only", "pulse + sign",
                                     "two-phase x4", "two-phase x2", "two-phase x1"])
def test_counts_at_window_ends_from_every_sample_equal_the_changes_decoding(decoder, dtype):
    """feed_windows (every sample's step, summed per window) gives what feed_packed (the changes)
    gives at the windows' last samples, on lines that change at random (every transition, the
    illegal ones too), cut into blocks at random, and counts the same illegal transitions."""
    from fha_studio.logic.bench.display import LiveCommandPulses, LiveQuadrature

    rng = np.random.default_rng(len(decoder) + dtype().itemsize)
    n, k = 20_000, 7
    words = rng.integers(0, 1 << (8 * np.dtype(dtype).itemsize), n, dtype=dtype)
    words[5000:9000] = words[5000]  # a stretch where nothing changes
    bits = (3, 6) if dtype == np.uint8 else (12, 1)
    sizes = np.diff(np.concatenate(([0], np.sort(rng.choice(np.arange(1, n), 30, replace=False)), [n])))
    if decoder == "quadrature":
        by_changes, by_samples = LiveQuadrature(), LiveQuadrature()
        feed = (lambda d, block: d.feed_packed(block, *bits)), \
            (lambda d, block, e: d.feed_windows(block, *bits, e))
    else:
        form = {"two-pulse": 0, "two-pulse, A only": 0, "pulse + sign": 1}.get(decoder, 2)
        multiplication = int(decoder[-1]) if form == 2 else 4
        b = None if decoder.endswith("A only") else bits[1]
        by_changes, by_samples = (LiveCommandPulses(form, multiplication, 3, 2) for _ in range(2))
        feed = (lambda d, block: d.feed_packed(block, bits[0], b)), \
            (lambda d, block, e: d.feed_windows(block, bits[0], b, e))
    start = 0
    for size, ends in zip(sizes, _windows(rng, sizes, k), strict=True):
        block = words[start:start + size]
        start += size
        expected = feed[0](by_changes, block).sample(ends)
        assert np.array_equal(feed[1](by_samples, block, ends), expected)
    final = (by_changes.counts, by_samples.counts) if decoder == "quadrature" else \
        (by_changes.pulses, by_samples.pulses)
    assert final[0] == final[1] and by_changes.illegal_transitions == by_samples.illegal_transitions
