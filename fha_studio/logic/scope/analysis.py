"""What the scope computes from a capture: move metrics, spectrum, cursor deltas.

Units follow the channel: positions in the same unit as the command (deg or pulses), times in s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True)
class MoveMetrics:
    """Figures of one commanded move (a step or a profiled move) and its response."""

    start: float  # position before the move [channel unit]
    target: float  # final command [channel unit]
    command_end_s: float  # when the command reached its final value [s]
    rise_time_s: float | None  # 10 % -> 90 % of the step by the feedback [s]
    overshoot_percent: float  # largest travel past the target, in % of the step
    overshoot: float  # the same in the channel unit
    settling_time_s: float | None  # from command start until the feedback stays within the band [s]
    settling_band: float  # the band used [channel unit]
    in_position_time_s: float | None  # from command end until |error| stays <= in-position range [s]
    final_error: float  # target - feedback at the end of the capture [channel unit]

    def describe(self, unit: str = "") -> str:
        u = f" {unit}" if unit else ""

        def ms(value: float | None) -> str:
            return "not reached" if value is None else f"{value * 1000:.1f} ms"

        return (
            f"step {self.target - self.start:+.4g}{u}; overshoot {self.overshoot_percent:.2f} % "
            f"({self.overshoot:.4g}{u}); rise {ms(self.rise_time_s)}; "
            f"settling (±{self.settling_band:.3g}{u}) {ms(self.settling_time_s)}; "
            f"in-position {ms(self.in_position_time_s)} after the command ended; "
            f"final error {self.final_error:.4g}{u}"
        )


def _stays_within(t: np.ndarray, inside: np.ndarray, after_index: int) -> float | None:
    """Time from which ``inside`` stays true until the end (searching from after_index), or None."""
    if not inside[-1]:
        return None
    outside = np.flatnonzero(~inside[after_index:])
    first = after_index if len(outside) == 0 else after_index + outside[-1] + 1
    return float(t[first])


def move_metrics(t_s: ArrayLike, command: ArrayLike, feedback: ArrayLike, *,
                 in_position_range: float | None = None, settling_fraction: float = 0.02) -> MoveMetrics:
    """Overshoot, rise, settling and in-position time of a move captured with its command.

    The move starts where the command first leaves its initial value and ends where it reaches
    its final value. The settling band is ``settling_fraction`` of the step, or the in-position
    range when that is larger. Raises ValueError for captures without a move.
    """
    t = np.asarray(t_s, dtype=float)
    cmd = np.asarray(command, dtype=float)
    fb = np.asarray(feedback, dtype=float)
    if not (len(t) == len(cmd) == len(fb)) or len(t) < 3:
        raise ValueError("move metrics need time, command and feedback of the same length (>= 3 samples)")
    start, target = cmd[0], cmd[-1]
    step = target - start
    if step == 0:
        raise ValueError("the command does not move in this capture")
    moving = np.flatnonzero(cmd != start)
    i_start = int(moving[0])
    i_end = int(np.flatnonzero(cmd != target)[-1] + 1) if np.any(cmd != target) else i_start
    direction = np.sign(step)
    progress = (fb - start) / step  # 0 at start, 1 at target
    rise_time = None
    above10 = np.flatnonzero(progress >= 0.1)
    above90 = np.flatnonzero(progress >= 0.9)
    if len(above10) and len(above90):
        rise_time = float(t[above90[0]] - t[above10[0]])
    past = (fb - target) * direction
    overshoot = float(max(0.0, past[i_start:].max()))
    band = abs(step) * settling_fraction
    if in_position_range is not None:
        band = max(band, in_position_range)
    err = np.abs(target - fb)
    settled_at = _stays_within(t, err <= band, i_start)
    in_pos_at = None
    if in_position_range is not None:
        in_pos_at = _stays_within(t, err <= in_position_range, i_end)
    return MoveMetrics(
        start=float(start),
        target=float(target),
        command_end_s=float(t[i_end]),
        rise_time_s=rise_time,
        overshoot_percent=100.0 * overshoot / abs(step),
        overshoot=overshoot,
        settling_time_s=None if settled_at is None else settled_at - float(t[i_start]),
        settling_band=band,
        in_position_time_s=None if in_pos_at is None else max(0.0, in_pos_at - float(t[i_end])),
        final_error=float(target - fb[-1]),
    )


@dataclass(frozen=True)
class Spectrum:
    frequency_hz: np.ndarray
    amplitude: np.ndarray  # single-sided amplitude of a sine at that frequency [channel unit]

    def peaks(self, count: int = 3, min_hz: float = 0.0) -> list[tuple[float, float]]:
        """The ``count`` largest local maxima above ``min_hz``: (frequency Hz, amplitude)."""
        a = self.amplitude
        is_peak = np.zeros(len(a), dtype=bool)
        is_peak[1:-1] = (a[1:-1] > a[:-2]) & (a[1:-1] >= a[2:])
        is_peak &= self.frequency_hz >= min_hz
        idx = np.flatnonzero(is_peak)
        idx = idx[np.argsort(a[idx])[::-1][:count]]
        return [(float(self.frequency_hz[i]), float(a[i])) for i in idx]

    def prominent_peaks(self, count: int = 3, min_hz: float = 0.0, window_bins: int = 25,
                        min_ratio: float = 4.0) -> list[tuple[float, float]]:
        """Peaks that stand out of their surroundings (a resonance, a kinematic error's line),
        not the slope of the low-frequency drift: local maxima ranked by amplitude over the
        higher of the medians of the ``window_bins`` on the left and on the right (so a slope is
        not a peak), kept when that ratio is >= ``min_ratio``. Peaks closer than 3 bins to
        either end are not judged. Returns (frequency Hz, amplitude), strongest ratio first."""
        a = self.amplitude
        n = len(a)
        if n < 3:
            return []
        is_peak = np.zeros(n, dtype=bool)
        is_peak[1:-1] = (a[1:-1] > a[:-2]) & (a[1:-1] >= a[2:])
        is_peak &= self.frequency_hz >= min_hz
        ranked = []
        for i in np.flatnonzero(is_peak):
            left = a[max(0, i - window_bins):max(0, i - 2)]
            right = a[i + 3:i + window_bins + 1]
            if len(left) < 3 or len(right) < 3:
                continue
            floor = max(float(np.median(left)), float(np.median(right)))
            ratio = a[i] / floor if floor > 0 else np.inf
            if ratio >= min_ratio:
                ranked.append((ratio, i))
        ranked.sort(reverse=True)
        return [(float(self.frequency_hz[i]), float(a[i])) for _, i in ranked[:count]]


def spectrum(t_s: ArrayLike, values: ArrayLike, *, detrend: str = "linear") -> Spectrum:
    """Amplitude spectrum of a uniformly sampled channel (Hann window, amplitude-corrected).

    ``detrend`` removes a mean ("constant") or a ramp ("linear", right for a position during a
    constant-speed move, where the kinematic error rides on the ramp). Raises ValueError when the
    sampling is not uniform within 1 %.
    """
    from scipy.signal import detrend as _detrend  # scipy is heavy; import on use

    t = np.asarray(t_s, dtype=float)
    x = np.asarray(values, dtype=float)
    if len(t) != len(x) or len(t) < 8:
        raise ValueError("a spectrum needs time and values of the same length (>= 8 samples)")
    dt = np.diff(t)
    period = float(np.median(dt))
    if period <= 0 or np.max(np.abs(dt - period)) > 0.01 * period:
        raise ValueError("the capture is not uniformly sampled; a spectrum needs a fixed sample period")
    x = _detrend(x, type=detrend)
    window = np.hanning(len(x))
    amp = np.abs(np.fft.rfft(x * window)) * 2.0 / window.sum()
    freq = np.fft.rfftfreq(len(x), period)
    return Spectrum(freq, amp)


@dataclass(frozen=True)
class CursorDelta:
    """A channel between two cursors: the time between them [s], the change of the value (its
    unit), the slope [unit/s], and the values at the first (A) and second (B) cursor."""

    dt_s: float
    dvalue: float
    slope_per_s: float | None  # dvalue / dt, None when dt == 0
    value_a: float = float("nan")
    value_b: float = float("nan")


def cursor_delta(t_s: ArrayLike, values: ArrayLike, t1_s: float, t2_s: float) -> CursorDelta:
    """Difference between two cursors on a channel (values interpolated at the cursor times)."""
    t = np.asarray(t_s, dtype=float)
    y = np.asarray(values, dtype=float)
    y1, y2 = np.interp([t1_s, t2_s], t, y)
    dt = t2_s - t1_s
    return CursorDelta(dt, float(y2 - y1), None if dt == 0 else float((y2 - y1) / dt), float(y1), float(y2))
