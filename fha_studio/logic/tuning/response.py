"""Frequency response from measured signals, the gear's resonance in it, the inertia, the margins.

- ``estimate_response``: H1 = Pxy / Pxx and the coherence |Pxy|^2 / (Pxx Pyy) from the
  records' cross-spectra (Welch's with one rectangular segment per record), averaged over
  records. A record of exactly one period of a periodic excitation is leakage-free with a
  rectangular window, which is how the excitation and the trace are sized
  (protocol.excitation_period_periods).
- ``find_resonance``: on the plant (current -> speed) normalised by the rigid body's 1/s slope,
  the anti-resonance is the dip and the resonance the peak above it (parabolic interpolation
  between the bins).
- ``fit_two_mass``: the plant (torque -> speed) fitted with the two-mass shape
  1/(J s + B) x (1 + 2 za s/wa + s^2/wa^2)/(1 + 2 zr s/wr + s^2/wr^2): the total inertia from the
  low-frequency gain, the viscous friction B apart from it (at the lowest bins it would otherwise
  pass for inertia), and the resonance and anti-resonance between the bins;
  ``inertia_from_move``: least squares of torque against
  acceleration (with Coulomb and viscous friction) over a move, as the HA-800A estimates it.
- ``loop_figures``: gain margin, phase margin, crossover, -3 dB bandwidth (python-control).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import control
import numpy as np
from scipy import optimize

TWO_PI = 2.0 * math.pi
#: bins of at least this coherence are trusted
COHERENCE_TRUSTED = 0.9


@dataclass(frozen=True)
class FrequencyResponse:
    """A measured (or predicted) response: frequency (Hz), magnitude (dB), phase (deg), coherence."""

    freq_hz: np.ndarray
    magnitude_db: np.ndarray
    phase_deg: np.ndarray
    coherence: np.ndarray

    @property
    def complex(self) -> np.ndarray:
        return np.asarray(10.0 ** (self.magnitude_db / 20.0) * np.exp(1j * np.radians(self.phase_deg)))

    def trusted(self) -> np.ndarray:
        return np.asarray(self.coherence >= COHERENCE_TRUSTED)

    def to_dict(self) -> dict[str, list[float]]:
        return {
            "freq_hz": [round(float(v), 4) for v in self.freq_hz],
            "magnitude_db": [round(float(v), 3) for v in self.magnitude_db],
            "phase_deg": [round(float(v), 2) for v in self.phase_deg],
            "coherence": [round(float(v), 4) for v in self.coherence],
        }


def estimate_response(records: Sequence[tuple[np.ndarray, np.ndarray]], sample_rate_hz: float,
                      f_min_hz: float = 0.0, f_max_hz: float | None = None) -> FrequencyResponse:
    """H1 and coherence from (input, output) records of equal length (one period each)."""
    if not records:
        raise ValueError("frequency response: no records")
    n = min(len(x) for x, _ in records)
    if n < 16:
        raise ValueError(f"frequency response: records of {n} samples are too short")
    # Welch's estimates with one segment per record, a rectangular window and the mean taken out
    # (scipy.signal.welch / csd with nperseg = n) are these sums of periodograms up to one scale,
    # which H1 and the coherence cancel; the FFTs directly are several times faster
    xs = np.asarray([np.asarray(x[:n], float) for x, _y in records])
    ys = np.asarray([np.asarray(y[:n], float) for _x, y in records])
    fx = np.fft.rfft(xs - xs.mean(axis=1, keepdims=True), axis=1)
    fy = np.fft.rfft(ys - ys.mean(axis=1, keepdims=True), axis=1)
    freq = np.fft.rfftfreq(n, 1.0 / sample_rate_hz)
    pxx_a = np.sum(np.abs(fx) ** 2, axis=0)
    pyy_a = np.sum(np.abs(fy) ** 2, axis=0)
    pxy_a = np.sum(np.conj(fx) * fy, axis=0)
    top = sample_rate_hz / 2.0 if f_max_hz is None else f_max_hz
    keep = (freq > max(f_min_hz, 0.0)) & (freq <= top) & (pxx_a > 0) & (pyy_a > 0)
    h = pxy_a[keep] / pxx_a[keep]
    coh = np.abs(pxy_a[keep]) ** 2 / (pxx_a[keep] * pyy_a[keep]) if len(records) > 1 else np.ones(keep.sum())
    return FrequencyResponse(freq[keep], 20.0 * np.log10(np.abs(h)), np.degrees(np.unwrap(np.angle(h))),
                             np.clip(coh, 0.0, 1.0))


def bandwidth_hz(closed: FrequencyResponse) -> float | None:
    """The -3 dB frequency of a measured closed loop: the first trusted bin 3 dB below the first."""
    mag, f, ok = closed.magnitude_db, closed.freq_hz, closed.trusted()
    below = [i for i in range(len(f)) if ok[i] and mag[i] < mag[0] - 3.0103]
    return float(f[below[0]]) if below else None


@dataclass(frozen=True)
class Resonance:
    resonance_hz: float | None
    antiresonance_hz: float | None


def _interpolated(freq: np.ndarray, values: np.ndarray, i: int) -> float:
    if 0 < i < len(values) - 1:
        a, b, c = values[i - 1], values[i], values[i + 1]
        den = a - 2.0 * b + c
        if den != 0.0:
            shift = 0.5 * (a - c) / den
            if abs(shift) <= 1.0:
                step = freq[i + 1] - freq[i] if shift > 0 else freq[i] - freq[i - 1]
                return float(freq[i] + shift * step)
    return float(freq[i])


def find_resonance(plant: FrequencyResponse, min_depth_db: float = 3.0) -> Resonance:
    """The anti-resonance (deepest dip) and resonance (highest peak above it) of the plant
    magnitude x frequency (the rigid body's 1/s taken out), over trusted bins; None where no dip
    or peak stands ``min_depth_db`` out of the rigid line."""
    ok = plant.trusted()
    f = plant.freq_hz[ok]
    if len(f) < 5:
        return Resonance(None, None)
    norm = plant.magnitude_db[ok] + 20.0 * np.log10(f)  # flat for a rigid body
    base = float(np.median(norm[: max(3, len(norm) // 10)]))
    i_dip = int(np.argmin(norm))
    if base - norm[i_dip] < min_depth_db:
        return Resonance(None, None)
    above = norm[i_dip:]
    i_peak = i_dip + int(np.argmax(above))
    # the peak stands out of the high-frequency level (the motor side alone: base + 20 log(J/Jm))
    if norm[i_peak] - norm[i_dip] < 2.0 * min_depth_db or i_peak == i_dip:
        return Resonance(None, _interpolated(f, norm, i_dip))
    return Resonance(_interpolated(f, norm, i_peak), _interpolated(f, norm, i_dip))


@dataclass(frozen=True)
class TwoMassFit:
    """The plant (torque -> speed) fitted with 1/(J s + B) x (anti-resonance pair)/(resonance
    pair): the total inertia J (kg m^2), the two frequencies (Hz; None for a rigid-looking axis)
    and the viscous friction B (N m s/rad)."""

    total_inertia_kgm2: float
    resonance_hz: float | None
    antiresonance_hz: float | None
    viscous_nm_s_per_rad: float = 0.0


def _rigid_factor(w: np.ndarray, dt: float) -> np.ndarray:
    # the trace's speed at the end of a period of held torque: a sampled integrator's shape
    x = w * dt / 2.0
    return np.asarray(np.where(x > 0, x / np.sin(x), 1.0) * np.exp(1j * x))


def fit_two_mass(plant: FrequencyResponse, sample_rate_hz: float) -> TwoMassFit | None:
    """Least squares (scipy.optimize) of the two-mass shape to the trusted bins of ``plant``
    (torque -> speed), started from the dip and peak ``find_resonance`` finds; a rigid body's
    1/(J s + B) when there is no dip. None without trusted bins."""
    ok = plant.trusted()
    f = plant.freq_hz[ok]
    if len(f) < 3:
        return None
    h = plant.complex[ok]
    w = TWO_PI * f
    dt = 1.0 / sample_rate_hz
    rigid = _rigid_factor(w, dt) / (1j * w)
    guess = find_resonance(plant)
    j0 = float(np.median(np.abs(rigid[: max(3, len(f) // 10)]) / np.abs(h[: max(3, len(f) // 10)])))
    if guess.antiresonance_hz is None or guess.resonance_hz is None:
        use = f <= 0.1 * sample_rate_hz
        if np.count_nonzero(use) < 3:
            return TwoMassFit(j0, None, None)
        # rigid / h = J + B x rigid: linear in J and B (real), least squares over both parts
        a = np.column_stack([np.ones(np.count_nonzero(use)), rigid[use]])
        a2 = np.vstack([a.real, a.imag])
        y = rigid[use] / h[use]
        (j, b), *_ = np.linalg.lstsq(a2, np.concatenate([y.real, y.imag]), rcond=None)
        return TwoMassFit(float(j), None, None, max(float(b), 0.0))
    wa0, wr0 = TWO_PI * guess.antiresonance_hz, TWO_PI * guess.resonance_hz
    use = f <= 3.0 * guess.resonance_hz
    wu, hu, ru = w[use], h[use], rigid[use]

    def model(x: np.ndarray) -> np.ndarray:
        j, wa, wr, za, zr, b = math.exp(x[0]), math.exp(x[1]), math.exp(x[2]), x[3], x[4], x[5]
        num = 1.0 - (wu / wa) ** 2 + 2j * za * wu / wa
        den = 1.0 - (wu / wr) ** 2 + 2j * zr * wu / wr
        return np.asarray(ru / (j + b * ru) * num / den)

    def residual(x: np.ndarray) -> np.ndarray:
        r = np.log(hu / model(x))
        return np.concatenate([r.real, r.imag])

    x0 = np.array([math.log(j0), math.log(wa0), math.log(wr0), 0.05, 0.05, 0.0])
    fit = optimize.least_squares(residual, x0, bounds=([-np.inf, -np.inf, -np.inf, 0.0, 0.0, 0.0],
                                                       [np.inf, np.inf, np.inf, 1.0, 1.0, np.inf]))
    j, wa, wr = (math.exp(v) for v in fit.x[:3])
    return TwoMassFit(j, wr / TWO_PI, wa / TWO_PI, float(fit.x[5]))


def inertia_from_move(t_s: np.ndarray, speed_rad_s: np.ndarray, torque_nm: np.ndarray) -> float:
    """Total inertia (kg m^2) from a move: least squares of the motor torque against
    acceleration, sign of speed (Coulomb friction) and speed (viscous friction)."""
    t, v, tq = (np.asarray(a, float) for a in (t_s, speed_rad_s, torque_nm))
    if len(t) < 10:
        raise ValueError("inertia from a move: fewer than 10 samples")
    accel = np.gradient(v, t)
    a = np.column_stack([accel, np.sign(v), v])
    solution, *_ = np.linalg.lstsq(a, tq, rcond=None)
    return float(solution[0])


@dataclass(frozen=True)
class LoopFigures:
    """Margins and bandwidth of a loop (None where the curve never crosses)."""

    gain_margin_db: float | None
    phase_margin_deg: float | None
    crossover_hz: float | None
    bandwidth_hz: float | None


def loop_figures(open_loop: Any, closed_loop: Any, f_max_hz: float, f_min_hz: float = 0.1) -> LoopFigures:
    """Gain and phase margin and the crossover of ``open_loop``, the -3 dB bandwidth of
    ``closed_loop`` (python-control on a dense frequency grid up to ``f_max_hz``)."""
    w = TWO_PI * np.logspace(math.log10(f_min_hz), math.log10(f_max_hz), 400)
    open_tf, closed_loop = control.tf(open_loop), control.tf(closed_loop)  # evaluated much faster
    gm, pm, _sm, _wg, wp, _ws = control.stability_margins(control.frd(open_tf, w))
    gm_db = 20.0 * math.log10(gm) if gm is not None and math.isfinite(gm) and gm > 0 else None
    closed = control.frequency_response(closed_loop, w)
    mag = np.abs(np.asarray(closed.complex).reshape(-1))
    below = np.nonzero(mag < mag[0] / math.sqrt(2.0))[0]
    bw_hz = float(w[below[0]]) / TWO_PI if len(below) else None
    return LoopFigures(
        gain_margin_db=gm_db,
        phase_margin_deg=float(pm) if pm is not None and math.isfinite(pm) else None,
        crossover_hz=float(wp) / TWO_PI if wp is not None and math.isfinite(wp) and wp > 0 else None,
        bandwidth_hz=bw_hz,
    )


def measured_loop_figures(open_loop: Any, plant_model: Any, plant: FrequencyResponse) -> LoopFigures:
    """Margins and crossover of the loop with the plant as measured: the model's loop gain times
    measured / modelled plant at the trusted bins (the controller and the feedback are the drive's
    own, known parts), then python-control's margins on that frequency response."""
    ok = plant.trusted()
    w = TWO_PI * plant.freq_hz[ok]
    if len(w) < 3:
        return LoopFigures(None, None, None, None)
    model_l = np.asarray(control.frequency_response(control.tf(open_loop), w).complex).reshape(-1)
    model_p = np.asarray(control.frequency_response(control.tf(plant_model), w).complex).reshape(-1)
    measured = model_l * plant.complex[ok] / model_p
    gm, pm, _sm, _wg, wp, _ws = control.stability_margins(control.frd(measured, w))
    return LoopFigures(
        gain_margin_db=20.0 * math.log10(gm) if gm is not None and math.isfinite(gm) and gm > 0 else None,
        phase_margin_deg=float(pm) if pm is not None and math.isfinite(pm) else None,
        crossover_hz=float(wp) / TWO_PI if wp is not None and math.isfinite(wp) and wp > 0 else None,
        bandwidth_hz=None,
    )
