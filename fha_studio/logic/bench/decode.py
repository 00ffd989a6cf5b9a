"""Decoding the drive's CN2 signals from sampled levels and volts (numpy, vectorised).

- :func:`quadrature`: encoder A/B counted x4 (A leading B = forward, + counts); an edge where
  both phases changed at once is an *illegal transition* (counted, not counted as motion); a
  state that returns within :data:`GLITCH_SAMPLES` samples is a *glitch* (counted; its counts
  cancel). An encoder resting on an edge can dither as fast (the simulated one does, having no
  comparator hysteresis): such glitches at standstill are not lost counts.
- :func:`z_check`: every Z pulse must come at the same count modulo the counts per motor turn
  (within :data:`Z_TOLERANCE_COUNTS`).
- :func:`command_pulses`: the command pulse lines by parameter 1 (0 two-pulse: FWD pulses on
  line A, REV pulses on line B; 1 pulse + sign: pulses on A, B low = FWD; 2 two-phase: A leading
  B = FWD, counted x1/x2/x4 by parameter 2), then through the electronic gear (parameter 3 /
  parameter 4) to commanded encoder counts.
- :func:`speed_from_monitor`: SPD-MON volts to motor r/min by parameter 9 (+10 V = parameter 9),
  the offset taken where the axis stands.
- :func:`check_edge_rate`: the capture's sample rate against the encoder's edge rate at the
  speed reached (two samples per edge at least), refused with both figures.

Counts are per sample: ``counts[i]`` is the position after sample ``i``, 0 at the first sample.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from fha_studio.logic.bench.edges import Lines, Steps, changes

#: A state that reverts within this many samples is a glitch (a spike on one phase).
GLITCH_SAMPLES = 2
#: Z pulses may come this many counts off the counts-per-turn grid (a Z edge is not tied to one
#: A/B edge on every encoder) before they count as an error.
Z_TOLERANCE_COUNTS = 1
#: The sample rate must be at least this many times the encoder's edge rate.
SAMPLES_PER_EDGE = 2.0
#: SPD-MON: volts at the speed in parameter 9.
MONITOR_FULL_SCALE_V = 10.0

PULSE_FORMS = {0: "two-pulse", 1: "pulse + sign", 2: "two-phase"}

# Gray phase of (A, B): 00 -> 0, A=1 B=0 -> 1, 11 -> 2, A=0 B=1 -> 3 (A leads B going forward)
_PHASE = np.array([0, 1, 3, 2], np.int8)  # index: A + 2 B
# phase step (mod 4) -> count step; 2 is illegal (both phases changed)
_STEP = np.array([0, 1, 0, -1], np.int8)
# (code before << 2 | code after) -> count step and illegal (both phases changed): the lookup table
_DELTA16 = np.array([(int(_PHASE[new]) - int(_PHASE[old])) % 4 for old in range(4) for new in range(4)])
_STEP16 = _STEP[_DELTA16]
_ILLEGAL16 = _DELTA16 == 2


class DecodeError(ValueError):
    """The signals cannot be decoded as asked (one line: what, and the figures)."""


@dataclass(frozen=True)
class QuadratureResult:
    """Encoder counts per sample (held where they change) and what was wrong with the edges."""

    steps: Steps  # the counts, 0 at the first sample
    edges: int
    glitches: int
    illegal_transitions: int
    edge_samples: np.ndarray  # sample index of each counted edge

    @cached_property
    def counts(self) -> np.ndarray:
        """int64 per sample."""
        return self.steps.dense().astype(np.int64)

    @property
    def total_counts(self) -> int:
        return int(self.steps.final) if self.steps.n else 0


def _changes(state: np.ndarray) -> np.ndarray:
    """Indices i >= 1 where state[i] != state[i-1]."""
    return changes(state)


def quadrature(a: np.ndarray, b: np.ndarray) -> QuadratureResult:
    """Count A/B x4; see the module docstring."""
    return quadrature_lines(Lines.from_levels(a, b))


def quadrature_lines(lines: Lines, glitches: bool = True) -> QuadratureResult:
    """Count A (line 0) / B (line 1) x4 from the samples where they change: each change's step
    from a 16-entry table of (code before, code after). ``glitches`` False: not counted (0; a
    live stream's counts do not need them)."""
    at = lines.at
    key = _transitions(lines, 3)
    illegal = int(np.count_nonzero(_ILLEGAL16[key]))
    steps = _STEP16[key]
    # a glitch: a step undone by the next one within GLITCH_SAMPLES samples
    undone_count = 0
    if glitches and at.size > 1:
        undone = (steps[1:] == -steps[:-1]) & (steps[1:] != 0) & (np.diff(at) <= GLITCH_SAMPLES)
        undone_count = int(np.count_nonzero(undone))
    counted = steps != 0
    edges = at[counted]
    counts = Steps(lines.n, edges, np.cumsum(steps[counted], dtype=np.int64))
    return QuadratureResult(counts, int(at.size), undone_count, illegal, edges)


def _transitions(lines: Lines, mask: int) -> np.ndarray:
    """Per change: (code before << 2) | code after, of the lines in ``mask`` (uint8)."""
    codes = lines.codes & np.uint8(mask)
    previous = np.empty_like(codes)
    if codes.size:
        previous[0] = lines.first & mask
        previous[1:] = codes[:-1]
    key: np.ndarray = (previous << np.uint8(2)) | codes
    return key


def rising_edges(level: np.ndarray) -> np.ndarray:
    """Sample indices where a line goes from low to high."""
    lv = level.astype(bool)
    return np.flatnonzero(lv[1:] & ~lv[:-1]) + 1


@dataclass(frozen=True)
class ZCheck:
    pulses: int
    count_errors: int
    counts_per_turn: int


def z_check(z: np.ndarray, counts: np.ndarray, counts_per_turn: int) -> ZCheck:
    """Z pulses against the counts per motor turn: each one at the first one's count modulo it."""
    return _z_check_at(rising_edges(z), np.asarray(counts)[rising_edges(z)], counts_per_turn)


def z_check_lines(z: Lines, counts: Steps, counts_per_turn: int) -> ZCheck:
    """:func:`z_check` from Z's changes and the counts held where they change."""
    at = z.rising()
    return _z_check_at(at, counts.sample(at), counts_per_turn)


def _z_check_at(at: np.ndarray, where: np.ndarray, counts_per_turn: int) -> ZCheck:
    if at.size == 0:
        return ZCheck(0, 0, counts_per_turn)
    off = (where - where[0]) % counts_per_turn
    off = np.minimum(off, counts_per_turn - off)
    return ZCheck(int(at.size), int(np.count_nonzero(off > Z_TOLERANCE_COUNTS)), counts_per_turn)


@dataclass(frozen=True)
class CommandPulseResult:
    pulse_steps: Steps  # input pulses after the x1/x2/x4 multiplication
    count_steps: Steps  # commanded encoder counts (through the electronic gear)
    illegal_transitions: int

    @cached_property
    def pulses(self) -> np.ndarray:
        """int64 per sample."""
        return self.pulse_steps.dense().astype(np.int64)

    @cached_property
    def counts(self) -> np.ndarray:
        """float64 per sample."""
        return self.count_steps.dense().astype(np.float64)


def command_pulses(
    a: np.ndarray,
    b: np.ndarray | None,
    pulse_form: int,
    multiplication: int,
    gear_numerator: int,
    gear_denominator: int,
) -> CommandPulseResult:
    """Commanded counts from the command pulse lines; see the module docstring."""
    _check_command(pulse_form, multiplication, gear_numerator, gear_denominator, b is not None)
    lines = Lines.from_levels(a) if b is None else Lines.from_levels(a, b)
    return command_pulse_lines(lines, b is not None, pulse_form, multiplication, gear_numerator,
                               gear_denominator)


def _check_command(pulse_form: int, multiplication: int, gear_numerator: int, gear_denominator: int,
                   has_b: bool) -> None:
    if pulse_form not in PULSE_FORMS:
        raise DecodeError(f"parameter 1 (command pulse form) is {pulse_form}; 0, 1 or 2 expected")
    if gear_numerator <= 0 or gear_denominator <= 0:
        raise DecodeError(f"electronic gear {gear_numerator}/{gear_denominator}: both must be at least 1")
    if pulse_form == 2:
        if not has_b:
            raise DecodeError(
                "two-phase command pulses (parameter 1 = 2) need both lines, command_a and command_b"
            )
        if multiplication not in (1, 2, 4):
            raise DecodeError(f"parameter 2 (multiplication) is {multiplication}; 1, 2 or 4 expected")


def command_pulse_lines(
    lines: Lines,
    has_b: bool,
    pulse_form: int,
    multiplication: int,
    gear_numerator: int,
    gear_denominator: int,
) -> CommandPulseResult:
    """:func:`command_pulses` from the lines' changes (line 0 = A, line 1 = B where ``has_b``)."""
    _check_command(pulse_form, multiplication, gear_numerator, gear_denominator, has_b)
    n = lines.n
    illegal = 0
    if pulse_form == 2:
        q = quadrature_lines(lines)
        illegal = q.illegal_transitions
        s = q.steps
        pulses = Steps(n, s.at, np.floor_divide(s.values, 4 // multiplication)).compressed()
    else:
        # per change of the lines: line A rising, and B rising (two-pulse) or B's level (the sign)
        key = _transitions(lines, 3 if has_b else 1)
        a_rises = (key & 0b0101) == 0b0001  # A low before, high after
        if pulse_form == 0:
            inc = a_rises.astype(np.int8) - ((key & 0b1010) == 0b0010) if has_b else a_rises.astype(np.int8)
        else:
            inc = a_rises.astype(np.int8)
            if has_b:
                inc[a_rises & ((key & 0b0010) != 0)] = -1  # the sign line high (ON) = REV
        moved = inc != 0
        pulses = Steps(n, lines.at[moved], np.cumsum(inc[moved], dtype=np.int64))
    counts = pulses.scaled(gear_numerator / gear_denominator)
    return CommandPulseResult(pulses, counts, illegal)


def standstill_mask(counts: np.ndarray, rate_hz: float, window_s: float = 0.01) -> np.ndarray:
    """Samples inside a stretch of at least ``window_s`` in which the encoder did not move."""
    return standstill_mask_at(counts.shape[0], _changes(counts), rate_hz, window_s)


def standstill_mask_at(n: int, at: np.ndarray, rate_hz: float, window_s: float = 0.01) -> np.ndarray:
    """:func:`standstill_mask` from the samples ``at`` where the counts change."""
    bounds = np.concatenate(([0], at, [n]))
    lengths = np.diff(bounds)
    still = lengths >= max(1, int(window_s * rate_hz))
    return np.repeat(still, lengths)


@dataclass(frozen=True)
class SpeedResult:
    motor_rpm: np.ndarray  # float32 per sample
    offset_v: float
    offset_from: str  # where the offset was taken, in words


def speed_from_monitor(
    volts: np.ndarray, speed_conversion_rpm: float, still: np.ndarray | None
) -> SpeedResult:
    """SPD-MON volts to motor r/min (+10 V = parameter 9), less the offset at standstill.

    ``still``: samples where the axis stands (from the encoder); without it, or when it marks
    none, the first 20 ms are taken as standing."""
    v = volts.astype(np.float64)
    if still is not None and np.count_nonzero(still) >= 16:
        offset = float(np.median(v[still]))
        where = "the median where the encoder stood still"
    else:
        head = v[: max(16, v.size // 50)]
        offset = float(np.median(head))
        where = "the median of the capture's first samples (no encoder to show standstill)"
    rpm = ((v - offset) * (speed_conversion_rpm / MONITOR_FULL_SCALE_V)).astype(np.float32)
    return SpeedResult(rpm, offset, where)


def edge_rate_hz(motor_rpm: float, counts_per_turn: int) -> float:
    """Encoder edges per second (x4 counts) at a motor speed."""
    return abs(motor_rpm) / 60.0 * counts_per_turn


def check_edge_rate(sample_rate_hz: float, peak_motor_rpm: float, counts_per_turn: int) -> None:
    """Refuses a capture whose rate cannot resolve the encoder's edges at the speed reached."""
    edges = edge_rate_hz(peak_motor_rpm, counts_per_turn)
    needed = SAMPLES_PER_EDGE * edges
    if sample_rate_hz < needed:
        raise DecodeError(
            f"the capture's sample rate of {_hz(sample_rate_hz)} cannot resolve the encoder at the "
            f"{peak_motor_rpm:.0f} r/min (motor) reached: {counts_per_turn} counts per motor turn give "
            f"{_hz(edges)} of edges, which needs at least {_hz(needed)}; capture faster or move slower"
        )


def peak_rpm_from_counts(
    counts: np.ndarray, rate_hz: float, counts_per_turn: int, window_s: float = 1e-3
) -> float:
    """The highest motor speed the encoder shows, over windows of ``window_s``."""
    step = max(1, int(window_s * rate_hz))
    if counts.size <= step:
        return 0.0
    moved = np.abs(counts[step:] - counts[:-step])
    return float(moved.max()) / (step / rate_hz) / counts_per_turn * 60.0


def peak_rpm_from_steps(
    counts: Steps, rate_hz: float, counts_per_turn: int, window_s: float = 1e-3
) -> float:
    """:func:`peak_rpm_from_counts` from the counts held where they change: ``c[i + w] - c[i]``
    changes only where ``i`` or ``i + w`` is a change, so those starts are all it is read at."""
    step = max(1, int(window_s * rate_hz))
    if counts.n <= step:
        return 0.0
    n, at, values = counts.n, counts.at, counts.values
    moved = [abs(counts.sample([step])[0] - counts.initial)]  # from sample 0
    if at.size:
        ahead = at < n - step  # i = a change: c[i] is its value
        moved.append(np.max(np.abs(counts.sample(at[ahead] + step) - values[ahead]), initial=0))
        behind = at >= step  # i + w = a change (sorted needles: searchsorted runs along)
        moved.append(np.max(np.abs(values[behind] - counts.sample(at[behind] - step)), initial=0))
    return float(max(moved)) / (step / rate_hz) / counts_per_turn * 60.0


def _hz(value: float) -> str:
    for factor, unit in ((1e9, "GHz"), (1e6, "MHz"), (1e3, "kHz")):
        if abs(value) >= factor:
            return f"{value / factor:.3g} {unit}"
    return f"{value:.3g} Hz"
