"""CN2 decoders: quadrature x4 with its faults, Z against the counts per turn, the three command
pulse forms through the electronic gear, SPD-MON with its offset, the edge-rate refusal."""

from __future__ import annotations

import numpy as np
import pytest

from fha_studio.logic.bench import decode


def _ab(counts):
    phase = np.mod(np.asarray(counts), 4)
    return (phase == 1) | (phase == 2), phase >= 2


def _walk(steps):
    return np.concatenate(([0], np.cumsum(steps)))


def test_quadrature_counts_x4_both_ways():
    counts = _walk([1] * 37 + [0] * 5 + [-1] * 12 + [1] * 3)
    a, b = _ab(np.repeat(counts, 3))
    result = decode.quadrature(a, b)
    assert np.array_equal(result.counts, np.repeat(counts, 3))
    assert result.total_counts == 28 and result.illegal_transitions == 0 and result.glitches == 0


def test_an_edge_of_both_phases_at_once_is_illegal_and_a_spike_is_a_glitch():
    counts = np.repeat(_walk([1] * 8), 10)
    a, b = _ab(counts)
    b = b.copy()
    a = a.copy()
    # both phases flip at one sample (two counts in one step): illegal, not counted as motion
    a[45:], b[45:] = _ab(counts[45:] + 2)
    # a one-sample spike on A while standing
    a2, b2 = _ab(np.zeros(50, int))
    a2[20] = True
    illegal = decode.quadrature(a, b)
    assert illegal.illegal_transitions == 1
    spike = decode.quadrature(a2, b2)
    assert spike.glitches == 1 and spike.total_counts == 0


def test_z_pulses_checked_against_the_counts_per_turn():
    per_turn = 40
    counts = np.repeat(_walk([1] * 130 + [-1] * 60), 2)
    z = np.mod(counts, per_turn) == 0
    good = decode.z_check(z, counts, per_turn)
    assert good.pulses >= 4 and good.count_errors == 0
    z_bad = z.copy()
    z_bad[np.flatnonzero(counts == 57)[0]] = True  # a Z where no turn ends
    assert decode.z_check(z_bad, counts, per_turn).count_errors == 1


STEPS = [1] * 30 + [0] * 4 + [-1] * 11


def _pulse_lines(form, multiplication=4):
    """The command lines of STEPS (one pulse each), four samples per line state."""
    if form == 2:  # two-phase: x4 counts every edge, x2 every second, x1 every fourth
        edges = _walk(np.repeat(STEPS, 4 // multiplication))
        return (*_ab(np.repeat(edges, 4)), np.repeat(np.floor_divide(edges, 4 // multiplication), 4))
    pulses = np.repeat(_walk(STEPS), 4)
    steps = np.diff(np.concatenate(([0], pulses)))
    if form == 0:
        return steps > 0, steps < 0, pulses
    sign = np.zeros(pulses.size, bool)
    direction = False
    for i, s in enumerate(steps):
        if s:
            direction = s < 0
        sign[i] = direction
    return steps != 0, sign, pulses


@pytest.mark.parametrize(("form", "multiplication"), [(0, 4), (1, 4), (2, 4), (2, 2), (2, 1)])
def test_command_pulses_by_form_multiplication_and_electronic_gear(form, multiplication):
    a, b, pulses = _pulse_lines(form, multiplication)
    result = decode.command_pulses(a, b, form, multiplication, 3, 2)
    assert result.pulses[-1] == 19 and result.counts[-1] == pytest.approx(19 * 1.5)
    assert np.array_equal(result.pulses, pulses)


def test_command_pulse_parameters_out_of_range_are_refused():
    a = np.zeros(10, bool)
    with pytest.raises(decode.DecodeError, match="parameter 1"):
        decode.command_pulses(a, a, 5, 4, 1, 1)
    with pytest.raises(decode.DecodeError, match="parameter 2"):
        decode.command_pulses(a, a, 2, 3, 1, 1)
    with pytest.raises(decode.DecodeError, match="need both lines"):
        decode.command_pulses(a, None, 2, 4, 1, 1)


def test_speed_monitor_by_parameter_9_with_the_offset_at_standstill():
    rate = 10_000.0
    counts = np.concatenate([np.zeros(1000, int), np.arange(3000) // 3, np.full(1000, 999)])
    volts = np.where((counts > 0) & (counts < 999), 5.0, 0.0) + 0.02
    still = decode.standstill_mask(counts, rate)
    result = decode.speed_from_monitor(volts, 3000.0, still)
    assert result.offset_v == pytest.approx(0.02)
    assert float(result.motor_rpm[2000]) == pytest.approx(1500.0)


def test_a_rate_that_cannot_resolve_the_edges_is_refused_with_both_figures():
    decode.check_edge_rate(2e6, 4500, 10000)  # 750 kHz of edges: 2 MHz is enough
    with pytest.raises(decode.DecodeError) as err:
        decode.check_edge_rate(1e6, 4500, 10000)
    text = str(err.value)
    assert "1 MHz" in text and "750 kHz" in text and "4500 r/min" in text and "1.5 MHz" in text
