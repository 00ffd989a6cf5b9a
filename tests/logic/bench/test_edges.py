"""The decoders on the samples where lines change give what they give sample by sample: counts,
faults, Z, command pulses in every form, the peak speed, from packed words and from bool arrays."""

from __future__ import annotations

import numpy as np
import pytest

from fha_studio.hardware.bench.capture import pack_logic
from fha_studio.logic.bench import decode
from fha_studio.logic.bench.edges import Lines, Steps


def _dense_quadrature(a, b):
    """The sample-by-sample reference: phase by Gray code, step by the phase difference."""
    phase = np.array([0, 1, 3, 2])[a.astype(int) + 2 * b.astype(int)]
    delta = np.diff(phase) % 4
    steps = np.array([0, 1, 0, -1])[delta]
    return np.concatenate(([0], np.cumsum(steps))), int(np.count_nonzero(delta == 2))


@pytest.mark.parametrize("seed", range(6))
def test_counts_from_changes_equal_the_sample_by_sample_count(seed):
    rng = np.random.default_rng(seed)
    n = 5000
    walk = np.cumsum(rng.choice([-1, 0, 0, 0, 1], n))
    a, b = (walk % 4 == 1) | (walk % 4 == 2), walk % 4 >= 2
    a = a ^ (rng.random(n) < 0.003)  # spikes and both-phase jumps among them
    b = b ^ (rng.random(n) < 0.003)
    counts, illegal = _dense_quadrature(a, b)
    packed = pack_logic([rng.random(n) < 0.5, a, rng.random(n) < 0.5, b])
    for result in (decode.quadrature(a, b), decode.quadrature_lines(Lines.from_packed(packed, 1, 3)),
                   decode.quadrature_lines(Lines.merge(Lines.from_packed(packed, 1),
                                                       Lines.from_levels(b)))):
        assert np.array_equal(result.counts, counts)
        assert result.illegal_transitions == illegal
        assert np.array_equal(result.steps.sample(np.arange(n)), counts)
        assert result.total_counts == counts[-1]
        step = 1 + seed * 7
        assert decode.peak_rpm_from_steps(result.steps, 1e4, 400, step / 1e4) == pytest.approx(
            decode.peak_rpm_from_counts(counts, 1e4, 400, step / 1e4))
        assert np.array_equal(decode.standstill_mask_at(n, result.steps.at, 1e4, 0.001),
                              decode.standstill_mask(counts, 1e4, 0.001))


@pytest.mark.parametrize("form", [0, 1, 2])
def test_command_pulses_from_changes_equal_rising_edges_sample_by_sample(form):
    rng = np.random.default_rng(form)
    n = 4000
    a, b = rng.random(n) < 0.3, rng.random(n) < 0.5
    if form == 2:
        walk = np.cumsum(rng.choice([-1, 0, 1], n))
        a, b = (walk % 4 == 1) | (walk % 4 == 2), walk % 4 >= 2
    lines = Lines.from_packed(pack_logic([b, a]), 1, 0)
    result = decode.command_pulse_lines(lines, True, form, 2, 3, 2)
    up_a = np.concatenate(([False], a[1:] & ~a[:-1]))
    if form == 0:
        up_b = np.concatenate(([False], b[1:] & ~b[:-1]))
        expected = np.cumsum(up_a.astype(int) - up_b)
    elif form == 1:
        expected = np.cumsum(np.where(up_a, np.where(b, -1, 1), 0))
    else:
        expected = np.floor_divide(_dense_quadrature(a, b)[0], 2)
    assert np.array_equal(result.pulses, expected)
    assert np.allclose(result.counts, expected * 1.5)
    assert np.array_equal(decode.command_pulses(a, b, form, 2, 3, 2).pulses, expected)


def test_steps_sum_increments_at_one_sample_and_drop_those_that_cancel():
    steps = Steps.from_increments(10, np.array([5, 2, 5, 7, 7]), np.array([1, 1, 2, 1, -1]))
    assert list(steps.at) == [2, 5] and list(steps.values) == [1, 4]
    assert list(steps.dense()) == [0, 0, 1, 1, 1, 4, 4, 4, 4, 4] and steps.final == 4


def test_z_check_from_changes():
    per_turn = 40
    walk = np.repeat(np.concatenate(([0], np.cumsum([1] * 130 + [-1] * 60))), 2)
    z = walk % per_turn == 0
    z[np.flatnonzero(walk == 57)[0]] = True
    counts = Steps(walk.size, np.flatnonzero(np.diff(walk)) + 1, walk[np.flatnonzero(np.diff(walk)) + 1])
    assert decode.z_check_lines(Lines.from_levels(z), counts, per_turn) == decode.z_check(z, walk, per_turn)
