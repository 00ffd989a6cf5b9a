"""The analysis bandwidth, chosen from the recording: where the rigid model still explains the data.

A real drive train is not rigid: the gear and the load's mounting have a resonance, and above
some frequency the motor torque no longer equals (J_motor + J_load) x the motor-side acceleration.
A rigid-model fit at a bandwidth that lets that dynamics in biases its parameters (friction, the
implied inertia). The residual of the rigid model tells where that starts:

- for each window on a geometric grid (from the noise-limited shortest window up to the longest the
  recording supports), the torque channel is smoothed with that window's kernel and fitted with
  every rigid-body candidate at once (inertia, Coulomb and viscous friction, gravity, an offset,
  torque ripple at the searched cycles per motor turn, and the current's time offset);
- its held-out RMS (contiguous-block cross-validation) minus the smoothed noise the monitors
  explain (current monitor and encoder quantisation, in quadrature) is the *unexplained torque*;
- with a rigid drive train it stays flat across bandwidths; drive-train dynamics make it grow with
  the bandwidth. The chosen window is the shortest (highest bandwidth) whose unexplained torque
  stays within GROWTH_LIMIT x the smallest unexplained torque of all longer windows, or within
  the practical floor.

All kernels are applied to raw columns computed and transformed once (FFT convolution), so the
search costs a few full-rate passes, not one analysis per window.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from scipy.fft import irfft, next_fast_len, rfft

from fha_studio.logic.modelcheck.linalg import gram, solve_normal
from fha_studio.logic.modelcheck.signals import make_filter

GROWTH_LIMIT = 1.5  # unexplained torque may grow this much over the best of the longer windows
WINDOWS_TRIED = 12
MAX_WINDOW_S = 1.5  # never smooth over more than this (a move's whole acceleration)
CV_BLOCKS = 10
RIPPLE_CYCLES = (1.0, 2.0, 3.0, 4.0, 6.0, 8.0)


@dataclass(frozen=True)
class BandwidthPoint:
    """One window tried: its bandwidth and the rigid model's unexplained torque there (N m rms)."""

    window: int
    bandwidth_hz: float
    heldout_rms_nm: float
    noise_nm: float
    unexplained_nm: float


@dataclass(frozen=True)
class BandwidthChoice:
    window: int
    reason: str
    profile: tuple[BandwidthPoint, ...]


def candidate_windows(shortest: int, longest: int, dt_s: float) -> list[int]:
    """Odd windows on a geometric grid from shortest to longest (capped at MAX_WINDOW_S)."""
    longest = min(longest, max(shortest, int(MAX_WINDOW_S / dt_s) | 1))
    if longest <= shortest:
        return [shortest]
    grid = np.geomspace(shortest, longest, WINDOWS_TRIED)
    return sorted({round(float(w)) | 1 for w in grid} | {shortest})


def choose_bandwidth(
    *,
    pos_rad: np.ndarray,
    current_a: np.ndarray,
    dt_s: float,
    kt_nm_per_a: float,
    inertia_kgm2: float,
    ratio: float | None,
    pos_noise_rad: float,
    current_noise_a: float,
    shortest: int,
    longest: int,
    floor_nm: float,
) -> BandwidthChoice:
    """The shortest window where the rigid model still explains the torque (see the module doc)."""
    # every cross-validation block must hold a few windows, or the held-out test is not held out
    longest = min(longest, max(shortest, len(pos_rad) // (3 * CV_BLOCKS)))
    windows = candidate_windows(shortest, longest, dt_s)
    if len(windows) == 1:
        return BandwidthChoice(windows[0], "the only window this recording supports", ())
    raw = _raw_columns(pos_rad, current_a, dt_s, ratio, shortest)[1:-1]
    # every window's kernel is applied to the same columns: their transform is taken once
    m = len(raw)
    size = next_fast_len(m + max(windows) - 3, real=True)
    raw_f = rfft(raw, size, axis=0)
    profile = []
    for w in windows:
        f = make_filter(w, dt_s)
        # smoothed columns on the valid part (the same samples as the SG derivatives): the linear
        # convolution with the reversed kernel, its samples where the kernel lies within the record
        length = len(f.smooth)
        cols = irfft(raw_f * rfft(f.smooth[::-1], size)[:, None], size, axis=0)[length - 1 : m]
        accel = cols[:, 1] / dt_s**2
        jerk = np.gradient(accel, dt_s)  # at the full rate, then taken at the fitted rows
        step = max(1, min(len(accel) // 2500, (w - 2) // 2))
        rows = cols[::step]
        y = kt_nm_per_a * rows[:, 0] - inertia_kgm2 * accel[::step]
        x = np.column_stack([accel[::step], jerk[::step], rows[:, 2:]])
        rms = _heldout_rms(y, x, gap=w // (2 * step) + 1)
        acc_noise = inertia_kgm2 * pos_noise_rad * math.sqrt(float(np.sum(f.d2**2))) / dt_s**2
        noise = math.hypot(kt_nm_per_a * current_noise_a * f.noise_gain, acc_noise)
        unexplained = math.sqrt(max(rms**2 - noise**2, 0.0))
        profile.append(BandwidthPoint(w, f.bandwidth_hz, rms, noise, unexplained))
    chosen = profile[-1]
    best_longer = math.inf
    for point in reversed(profile):  # from the longest window down
        best_longer = min(best_longer, point.unexplained_nm)
        if point.unexplained_nm <= max(GROWTH_LIMIT * best_longer, floor_nm):
            chosen = point
        else:
            break
    first = profile[0]
    if chosen is first:
        reason = (
            "the shortest window where the acceleration noise falls to the current monitor's noise; "
            f"the rigid model explains the data up to there ({_fmt(first.unexplained_nm)} N·m rms "
            "unexplained)"
        )
    else:
        above = profile[profile.index(chosen) - 1]
        reason = (
            f"the highest bandwidth where the rigid model still explains the data: above it the "
            f"unexplained torque grows from {_fmt(chosen.unexplained_nm)} to {_fmt(above.unexplained_nm)} "
            f"N·m rms ({above.bandwidth_hz:.3g} Hz), drive-train dynamics the rigid model lacks"
        )
    return BandwidthChoice(chosen.window, reason, tuple(profile))


def _raw_columns(
    pos: np.ndarray, cur: np.ndarray, dt_s: float, ratio: float | None, window: int
) -> np.ndarray:
    """Full-rate columns whose smoothing gives the analysis signals: current, second difference of
    the position (smoothed / dt^2 = the SG acceleration), and the rigid candidates' raw columns."""
    n = len(pos)
    d2 = np.zeros(n)
    d2[1:-1] = pos[2:] - 2.0 * pos[1:-1] + pos[:-2]
    v = np.empty(n)
    v[1:-1] = (pos[2:] - pos[:-2]) / (2.0 * dt_s)
    v[0], v[-1] = v[1], v[-2]
    # direction of motion with memory (friction holds its last sign at standstill), from the speed
    # smoothed over the shortest window
    k = np.ones(window) / window
    vs = np.convolve(v, k, mode="same")
    threshold = 3.0 * max(float(np.std(np.diff(pos, 2))), 1e-12) / (window * dt_s)
    d = np.where(vs > threshold, 1.0, np.where(vs < -threshold, -1.0, np.nan))
    idx = np.where(~np.isnan(d), np.arange(n), 0)
    np.maximum.accumulate(idx, out=idx)
    sign = np.nan_to_num(d[idx])
    cols = [cur, d2, sign, v, np.sin(pos), np.cos(pos), np.ones(n)]
    if ratio is not None:
        for c in RIPPLE_CYCLES:
            angle = c * ratio * pos
            cols.extend([np.sin(angle), np.cos(angle)])
    return np.column_stack(cols)


def _heldout_rms(y: np.ndarray, x: np.ndarray, gap: int) -> float:
    """Contiguous-block cross-validated RMS of a least-squares fit (scaled columns, pseudo-inverse).

    The training set leaves out `gap` samples on each side of the held-out block: the smoothing
    spreads each sample over half a window, so neighbours would otherwise leak into the test.
    """
    n = len(y)
    scale = np.sqrt(np.sum(x * x, axis=0))
    scale[scale == 0] = 1.0
    xs = x / scale
    cuts = np.linspace(0, n, CV_BLOCKS + 1).round().astype(int)
    # normal equations: the training Gram matrix is the whole one minus the left-out rows'
    g_all, xty = gram(xs, y)
    sse = 0.0
    for a, b in itertools.pairwise(cuts):
        lo, hi = max(0, a - gap), min(n, b + gap)
        g_out, xty_out = gram(xs[lo:hi], y[lo:hi])
        beta = solve_normal(g_all - g_out, xty - xty_out)
        r = y[a:b] - xs[a:b] @ beta
        sse += float(r @ r)
    return math.sqrt(sse / max(n, 1))


def _fmt(x: float) -> str:
    return f"{x:.3g}"
