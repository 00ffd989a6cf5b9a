"""Step 1 of the model check: from a recording to residual channels, at one analysis bandwidth.

Derivatives of quantised, noisy positions
-----------------------------------------
The acceleration comes from a Savitzky-Golay filter (cubic, second derivative) of the encoder
position. The *same bandwidth* is then applied to everything else, exactly: the SG second
derivative of a sampled signal equals a smoothing kernel ``g`` applied to its discrete second
difference, where ``g`` is the double cumulative sum of the SG derivative coefficients (a positive,
symmetric bump of unit sum, ``N - 2`` samples long). Smoothing the current, the velocity and every
candidate regressor with that ``g`` makes the equation of motion hold *exactly* after filtering:
the filter cannot create a residual from the inertial term (no derivative-filter bias at the
acceleration steps of a trapezoid), it only sets the analysis bandwidth, and fast effects (torque
ripple) are attenuated equally on both sides so their amplitudes stay unbiased.

Window: the acceleration noise falls as ``N^-2.5`` while the smoothed current noise falls only as
``N^-0.5``. We take the shortest window at which the acceleration noise (estimated from the
position's own high-frequency noise, i.e. its quantisation, times the declared inertia) has
fallen to the current monitor's smoothed noise (times Kt): a shorter one lets quantisation
dominate the residual. That window (clamped to 11 samples .. 0.12 s) is the shortest one tried;
bandwidth.py then lengthens it where the data say the rigid model stops explaining the torque
(drive-train dynamics). A window given by the user must lie within `window_bounds()`.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.signal import savgol_coeffs

ARCSEC_PER_RAD = 180.0 / math.pi * 3600.0
POLYORDER = 3
MIN_WINDOW = 11
MAX_WINDOW_S = 0.12


@dataclass(frozen=True)
class AnalysisFilter:
    """The Savitzky-Golay window and its matching smoothing kernel."""

    window: int  # samples (odd)
    dt_s: float
    d2: np.ndarray  # SG second-derivative coefficients (per sample^2), dot form
    d1: np.ndarray  # SG first-derivative coefficients
    smooth: np.ndarray  # g: unit-sum kernel (len window - 2) with smooth * second_difference == d2 * x

    @property
    def half(self) -> int:
        """Samples lost at each end of the recording (where the window does not fit)."""
        return self.window // 2

    @property
    def bandwidth_hz(self) -> float:
        """Rough -3 dB frequency of the smoothing (informative)."""
        return bandwidth_of_window(self.window, self.dt_s)

    @property
    def noise_gain(self) -> float:
        """What the smoothing leaves of white noise: sqrt(sum g^2) (std after / std before)."""
        return float(math.sqrt(np.sum(self.smooth**2)))

    def accel(self, x: np.ndarray) -> np.ndarray:
        """SG second derivative (x units per s^2) on the valid part (length len(x) - 2 half)."""
        return np.convolve(x, self.d2[::-1], "valid") / self.dt_s**2

    def speed(self, x: np.ndarray) -> np.ndarray:
        """SG first derivative (x units per s) on the valid part."""
        return np.convolve(x, self.d1[::-1], "valid") / self.dt_s

    def apply(self, x: np.ndarray) -> np.ndarray:
        """The smoothing kernel g on the valid part (same samples as accel())."""
        x = np.asarray(x, dtype=float)
        if x.ndim == 2:
            return np.column_stack([self.apply(c) for c in x.T]) if x.shape[1] else x[self.half : -self.half]
        return np.convolve(x[1:-1], self.smooth[::-1], "valid")

    def apply_every(self, x: np.ndarray, step: int) -> np.ndarray:
        """apply(x)[::step], computed at those samples only: the kernel and the record split into
        step phases, step convolutions each 1/step as long with 1/step of the kernel (a decimated
        fit rebuilds a searched column at every trial; this is step times less work)."""
        x = np.asarray(x, dtype=float)
        if step == 1:
            return self.apply(x)
        if x.ndim == 2:
            return np.column_stack([self.apply_every(c, step) for c in x.T])
        a, g = x[1:-1], self.smooth
        n_out = -(-(len(a) - len(g) + 1) // step)
        out = np.zeros(n_out)
        for phase in range(min(step, len(g))):
            out += np.convolve(a[phase::step], g[phase::step][::-1], "valid")[:n_out]
        return out


def make_filter(window: int, dt_s: float) -> AnalysisFilter:
    """The analysis filter of an odd window length (samples)."""
    window = int(window) | 1
    d2 = savgol_coeffs(window, POLYORDER, deriv=2, delta=1.0, use="dot")
    d1 = savgol_coeffs(window, POLYORDER, deriv=1, delta=1.0, use="dot")
    g = np.cumsum(np.cumsum(d2))[: window - 2]
    g = g / g.sum()
    return AnalysisFilter(window, dt_s, d2, d1, g)


MIN_WINDOWS_PER_RECORD = 8  # the record must hold at least this many analysis windows


def window_bounds(n_samples: int) -> tuple[int, int]:
    """The odd window lengths (samples) a recording of n_samples supports: (shortest, longest).

    The longest keeps MIN_WINDOWS_PER_RECORD windows within the record: a longer one leaves too few
    independent stretches for the cross-validation blocks and smooths moves into each other.
    """
    longest = max(MIN_WINDOW, ((n_samples // MIN_WINDOWS_PER_RECORD) - 1) | 1)
    return MIN_WINDOW, longest


def check_window(window: int, n_samples: int) -> int:
    """The window as used (odd), or ValueError naming the bounds this recording supports."""
    lo, hi = window_bounds(n_samples)
    if not lo <= window <= hi:
        raise ValueError(
            f"window {window} samples: this recording ({n_samples} samples) supports {lo} to {hi} "
            f"(at least {MIN_WINDOWS_PER_RECORD} windows must fit in it)"
        )
    return int(window) | 1


def bandwidth_of_window(window: int, dt_s: float) -> float:
    """The analysis bandwidth (Hz, rough -3 dB) of a window of that many samples."""
    return 1.0 / (1.7 * (window - 2) * dt_s)


def window_for_bandwidth(bandwidth_hz: float, n_samples: int, dt_s: float) -> int:
    """The odd window (samples) nearest an analysis bandwidth, within what the recording supports."""
    lo, hi = window_bounds(n_samples)
    window = round(1.0 / (1.7 * bandwidth_hz * dt_s)) + 2
    return min(max(window, lo), hi) | 1  # hi is odd: the result stays within the bounds


def bandwidth_bounds_hz(n_samples: int, dt_s: float) -> tuple[float, float]:
    """The lowest and highest analysis bandwidth (Hz) a recording of n_samples at dt_s supports."""
    lo, hi = window_bounds(n_samples)
    return bandwidth_of_window(hi, dt_s), bandwidth_of_window(lo, dt_s)


def noise_sigma(x: np.ndarray) -> float:
    """Standard deviation of the white-ish noise on x: robust, from the residual of a local cubic."""
    if len(x) < 16:
        return 0.0
    c = savgol_coeffs(7, 3, use="dot")
    r = x[3:-3] - np.convolve(x, c[::-1], "valid")
    # residual of a 7-point cubic fit: r = (1 - h0) e - ...; its variance is (1 - c[3]) sigma^2
    mad = np.median(np.abs(r - np.median(r)))
    return (
        float(1.4826 * mad / math.sqrt(1.0 - c[3])) if mad > 0 else float(np.std(r) / math.sqrt(1.0 - c[3]))
    )


def choose_window(
    dt_s: float,
    pos_noise_rad: float,
    current_noise_a: float,
    inertia_kgm2: float,
    kt_nm_per_a: float,
    n_samples: int,
) -> int:
    """The shortest odd window where inertia x acceleration noise <= Kt x smoothed current noise."""
    max_window = max(MIN_WINDOW, int(MAX_WINDOW_S / dt_s) | 1)
    max_window = min(max_window, window_bounds(n_samples)[1])
    pos_noise = max(pos_noise_rad, 1e-12)
    for window in range(MIN_WINDOW, max_window + 1, 2):
        f = make_filter(window, dt_s)
        acc_noise = inertia_kgm2 * pos_noise * math.sqrt(np.sum(f.d2**2)) / dt_s**2
        cur_noise = kt_nm_per_a * current_noise_a * math.sqrt(np.sum(f.smooth**2))
        if acc_noise <= cur_noise:
            return window
    return max_window


@dataclass
class Signals:
    """The analysis signals on the valid, uniformly sampled part of a recording (full rate).

    Angles in rad (output side unless named), speeds rad/s, accelerations rad/s^2, torques N m.
    ``*_f`` arrays are smoothed with the analysis filter (same samples as ``accel_rad_s2``).
    """

    t_s: np.ndarray
    pos_rad: np.ndarray  # measured position on the valid part (unsmoothed)
    speed_rad_s: np.ndarray  # SG first derivative
    accel_rad_s2: np.ndarray  # SG second derivative
    torque_f_nm: np.ndarray  # Kt x current, smoothed
    current_raw_a: np.ndarray  # the monitor's current on the valid part (unsmoothed)
    filt: AnalysisFilter
    raw_pos_rad: np.ndarray  # whole uniformly sampled position (for regressors needing history)
    load_diff_f_rad: np.ndarray | None = None  # load_pos - pos, smoothed (position channel)
    cmd_pos_rad: np.ndarray | None = None  # whole uniform command (for re-simulation)
    raw_t_s: np.ndarray = field(default_factory=lambda: np.empty(0))
    raw_current_a: np.ndarray = field(default_factory=lambda: np.empty(0))
    raw_load_pos_rad: np.ndarray | None = None
    ratio: float | None = None
    pos_noise_rad: float = 0.0
    current_noise_a: float = 0.0
    resampled: bool = False
    window_reason: str = ""  # why this analysis window (bandwidth) was used

    @property
    def jerk_rad_s3(self) -> np.ndarray:
        """Derivative of the (smoothed) acceleration: the regressor of a current/position time offset."""
        return np.gradient(self.accel_rad_s2, self.filt.dt_s)

    @property
    def motor_angle_rad(self) -> np.ndarray | None:
        """Motor angle = ratio x output position (None when the ratio is unknown)."""
        return None if self.ratio is None else self.ratio * self.pos_rad

    def regressor(self, full_rate_column: np.ndarray) -> np.ndarray:
        """A regressor computed on the whole uniform record, smoothed onto the valid part."""
        return self.filt.apply(full_rate_column)

    @functools.cached_property
    def speed_f_rad_s(self) -> np.ndarray:
        """Speed for linear (viscous) terms: the central difference, smoothed with g (consistent)."""
        x = self.raw_pos_rad
        v = np.empty_like(x)
        v[1:-1] = (x[2:] - x[:-2]) / (2.0 * self.filt.dt_s)
        v[0], v[-1] = v[1], v[-2]
        return self.filt.apply(v)

    @functools.cached_property
    def full_speed_rad_s(self) -> np.ndarray:
        """SG speed padded to the whole uniform record (edges held), for nonlinear regressors (once:
        a searched Stribeck speed asks for it at every trial)."""
        h = self.filt.half
        return np.concatenate(
            [np.full(h, self.speed_rad_s[0]), self.speed_rad_s, np.full(h, self.speed_rad_s[-1])]
        )


def uniform(t: np.ndarray, *columns: np.ndarray | None) -> tuple[np.ndarray, list[np.ndarray | None], bool]:
    """Resample onto a uniform time grid when the sampling jitters by more than 5 %."""
    steps = np.diff(t)
    dt = float(np.median(steps))
    if np.max(np.abs(steps - dt)) <= 0.05 * dt:
        return t, list(columns), False
    n = math.floor((t[-1] - t[0]) / dt) + 1
    grid = t[0] + dt * np.arange(n)
    return grid, [None if c is None else np.interp(grid, t, c) for c in columns], True


def build_signals(
    t_s: np.ndarray,
    pos_rad: np.ndarray,
    current_a: np.ndarray,
    *,
    kt_nm_per_a: float,
    inertia_kgm2: float,
    ratio: float | None,
    load_pos_rad: np.ndarray | None = None,
    cmd_pos_rad: np.ndarray | None = None,
    window: int | None = None,
) -> Signals:
    """Step 1: derivatives and smoothed channels. ``window`` overrides the automatic choice."""
    t, (pos, cur, load, cmd), resampled = uniform(t_s, pos_rad, current_a, load_pos_rad, cmd_pos_rad)
    assert pos is not None and cur is not None  # given, so resampled too
    dt = float(np.median(np.diff(t)))
    pos_noise = noise_sigma(pos)
    cur_noise = noise_sigma(cur)
    # quantisation of a slowly moving encoder is not white: never assume less than 1/sqrt(12) step
    steps = np.abs(np.diff(pos))
    nonzero = steps[steps > 0]
    if nonzero.size:
        pos_noise = max(pos_noise, float(np.percentile(nonzero, 5)) / math.sqrt(12.0))
    if window is not None:
        window = check_window(window, len(t))
        reason = "given by the user"
    else:
        window = choose_window(dt, pos_noise, max(cur_noise, 1e-6), inertia_kgm2, kt_nm_per_a, len(t))
        reason = "the shortest window where the acceleration noise falls to the current monitor's noise"
    f = make_filter(window, dt)
    h = f.half
    sig = Signals(
        t_s=t[h:-h],
        pos_rad=pos[h:-h],
        speed_rad_s=f.speed(pos),
        accel_rad_s2=f.accel(pos),
        torque_f_nm=kt_nm_per_a * f.apply(cur),
        current_raw_a=cur[h:-h],
        filt=f,
        raw_pos_rad=pos,
        load_diff_f_rad=None if load is None else f.apply(load - pos),
        cmd_pos_rad=cmd,
        raw_t_s=t,
        raw_current_a=cur,
        raw_load_pos_rad=load,
        ratio=ratio,
        pos_noise_rad=pos_noise,
        current_noise_a=cur_noise,
        resampled=resampled,
        window_reason=reason,
    )
    return sig
