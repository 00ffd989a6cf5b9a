"""The speed loop's frequency response from a bench capture: SPD-CMD driven by an instrument's
output while SPD-MON is recorded (a real HA-655 in speed mode, whose CN3 is silent while the servo
is on).

The input is SPD-CMD as recorded beside SPD-MON, or, when only SPD-MON was recorded, the
excitation file itself, put in the capture's time by cross-correlation with the response the
linearised loop predicts for it (its start and the two instruments' clock ratio, from the first
and the second half). The capture is cut into whole periods of the excitation (its period found
in the file, or by the input's autocorrelation), resampled to a whole number of samples per
period, the first period(s) left to the loop's settling; the rest are the records of
``response.estimate_response`` (H1 and coherence, the one path of every measurement), on the bins
the excitation drives.

SPD-MON / SPD-CMD is the closed speed loop (both are scaled by parameter 9: the ratio needs no
scale), the monitor's own bandwidth taken out when it is given. The drive's own parts are known
from its items (the PI controller and the speed feedback of the linearised loop), so the loop gain
follows from the closed loop, L = G T / (1 - G T) (G: the feedback's share, 1 with ideal speed
feedback), and the plant as measured is the model's plant times L / L_model. From there the
figures are ``session.response_figures``' as over CN3: the two-mass fit, the margins, the
bandwidth.

The load inertia follows from the resonance pair alone, J_L = J_motor x ((f_r / f_a)^2 - 1)
(FHA-C catalogue inertia on the motor side): a capture without current cannot tell the inertia
from the loop's gain (that rests on the unit of the speed loop gain, tune item 0, which the public
manual does not give). Its uncertainty is the jackknife's over the records.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import control
import numpy as np
from scipy import signal
from scipy.fft import next_fast_len

from fha_studio.hardware.bench.waveform import Waveform
from fha_studio.logic.tuning.bench_excitation import (
    _at_servo_rate,
    discrete_filter,
    speed_mode_loop,
    volts_per_output_rpm,
)
from fha_studio.logic.tuning.linear import LoopModel
from fha_studio.logic.tuning.propose import Tuner
from fha_studio.logic.tuning.response import FrequencyResponse, estimate_response, fit_two_mass
from fha_studio.logic.tuning.session import response_figures

TWO_PI = 2.0 * math.pi
#: a bin is driven when the input's power there is at least this share of the largest
DRIVEN_SHARE = 1e-3
#: the input counts as playing where it departs from its rest level by this share of its peak
ACTIVE_SHARE = 0.02
MIN_RECORDS = 2
#: the band ends at the last bin of at least this share of the largest (flat excitations)
BAND_SHARE = 0.3
#: ... and where at least this share of its power repeats from record to record
REPEATING_SHARE = 0.98
#: the plant (and the loop gain) is kept where the loop gain's random error is at most this share
LOOP_ERROR = 0.05
#: pieces of the file located in the capture to find its start and the clocks' ratio
ALIGN_SEGMENTS = 8


class BenchResponseError(ValueError):
    """A capture that gives no response: one line saying what and where."""


@dataclass(frozen=True)
class BenchCapture:
    """SPD-MON (and SPD-CMD when recorded) in volts at one rate, with where each came from."""

    rate_hz: float
    monitor_v: np.ndarray
    command_v: np.ndarray | None = None
    sources: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class Alignment:
    """Where the records lie in the capture (samples of the capture) and how they were found."""

    start: float  # the excitation's first periodic sample
    period: float  # capture samples per period (not a whole number in general)
    end: float  # the last sample the input plays
    how: str
    clock_ratio: float = 1.0  # the capture's clock / the file's


def _autocorrelation_peak(x: np.ndarray, lo: int, hi: int) -> float:
    """The lag in [lo, hi] (samples, sub-sample) of ``x``'s period: where its normalised
    autocorrelation first peaks as high as anywhere in the range."""
    x = x - np.mean(x)
    n = len(x)
    size = next_fast_len(2 * n, real=True)
    r = np.fft.irfft(np.abs(np.fft.rfft(x, size)) ** 2, size)[:n] / np.maximum(n - np.arange(n), 1)
    hi = min(hi, n - 2)
    if hi <= lo:
        raise BenchResponseError("the capture is too short to hold two periods of the excitation")
    # the first lag as high as the highest (a periodic signal correlates as well at 2, 3 ... periods)
    window = r[lo:hi + 1]
    i = lo + int(np.flatnonzero(window >= 0.9 * float(np.max(window)))[0])
    while i < hi and r[i + 1] > r[i]:
        i += 1
    return i + _parabola(r, i)


def _parabola(r: np.ndarray, i: int) -> float:
    if 0 < i < len(r) - 1:
        a, b, c = r[i - 1], r[i], r[i + 1]
        den = a - 2.0 * b + c
        if den < 0:
            return float(0.5 * (a - c) / den)
    return 0.0


def _cross_lag(y: np.ndarray, model: np.ndarray) -> float:
    """The lag (samples, sub-sample) by which ``model`` best matches ``y`` (model shifted later)."""
    n = next_fast_len(len(y) + len(model), real=True)
    r = np.fft.irfft(np.fft.rfft(y - y.mean(), n) * np.conj(np.fft.rfft(model - model.mean(), n)), n)
    i = int(np.argmax(r))
    lag = i + _parabola(r, i)
    return lag - n if lag > n / 2 else lag


def _active_span(u: np.ndarray) -> tuple[int, int]:
    rest = float(np.median(u[: max(1, len(u) // 50)]))
    dev = np.abs(u - rest)
    peak = float(np.max(dev))
    if peak <= 0:
        raise BenchResponseError("SPD-CMD does not move: nothing was played")
    on = np.flatnonzero(dev > ACTIVE_SHARE * peak)
    return int(on[0]), int(on[-1])


def _period_of_file(wave: Waveform) -> float:
    """The file's period in seconds: as its maker stated it, or by its autocorrelation."""
    if wave.period_samples > 0:
        return wave.period_samples / wave.rate_hz
    n = len(wave.volts)
    return _autocorrelation_peak(wave.volts, max(2, int(0.05 * wave.rate_hz)), n // 2) / wave.rate_hz


def _file_start_s(wave: Waveform) -> float:
    if wave.period_samples > 0:
        return wave.start_sample / wave.rate_hz
    first, _last = _active_span(wave.volts)
    return first / wave.rate_hz


def _predicted_monitor(lm: LoopModel, wave: Waveform, vpr: float, rate_hz: float,
                       monitor_bandwidth_hz: float | None) -> np.ndarray:
    """SPD-MON the linearised loop predicts for the file, at the capture's rate (volts), through
    the monitor's own first order when its bandwidth is given."""
    servo = lm.settings.servo_rate_hz
    command = _at_servo_rate(wave.volts, wave.rate_hz, servo) / vpr * TWO_PI / 60.0  # rad/s
    speed = discrete_filter(lm.speed_loop()[0, 0], command)
    t_servo = np.arange(len(speed)) / servo
    t = np.arange(int(len(speed) * rate_hz / servo)) / rate_hz
    volts = np.interp(t, t_servo, speed * 60.0 / TWO_PI * vpr)
    if monitor_bandwidth_hz:
        b, a = signal.bilinear([1.0], [1.0 / (TWO_PI * monitor_bandwidth_hz), 1.0], rate_hz)
        volts = signal.lfilter(b, a, volts)
    return np.asarray(volts)


def align(capture: BenchCapture, lm: LoopModel, vpr: float, wave: Waveform | None,
          monitor_bandwidth_hz: float | None = None) -> tuple[Alignment, Any]:
    """Where the excitation lies in the capture, and the input at any capture sample position
    (a function of fractional sample indices)."""
    rate = capture.rate_hz
    if capture.command_v is not None:
        u = np.asarray(capture.command_v, float)
        first, last = _active_span(u)
        if wave is not None:
            nominal = _period_of_file(wave) * rate
            period = _autocorrelation_peak(u[first:last], int(0.995 * nominal), math.ceil(1.005 * nominal))
        else:
            period = _autocorrelation_peak(u[first:last], max(2, int(0.05 * rate)), (last - first) // 2)
        positions = np.arange(len(u), dtype=float)
        return (Alignment(float(first), period, float(last), "SPD-CMD recorded beside SPD-MON"),
                lambda at: np.interp(at, positions, u))
    if wave is None:
        raise BenchResponseError("neither SPD-CMD recorded (--signal speed_command=...) nor the excitation "
                                 "file given (--excitation): the input is unknown")
    y = np.asarray(capture.monitor_v, float)
    model = _predicted_monitor(lm, wave, vpr, rate, monitor_bandwidth_hz)
    lag = _cross_lag(y, model)
    # the two clocks: where each of ALIGN_SEGMENTS pieces of the file lies in the capture, a line
    # through them (least squares): capture sample = offset + file sample (at the capture's rate) x ratio
    size = len(model) // ALIGN_SEGMENTS
    margin = int(0.02 * rate)
    centres, found = [], []
    for k in range(ALIGN_SEGMENTS):
        seg = slice(k * size, (k + 1) * size)
        lo = max(0, int(lag) + seg.start - margin)
        piece = y[lo: lo + size + 2 * margin]
        if len(piece) < size + 2 * margin:
            raise BenchResponseError("the capture does not hold the whole excitation file: record from "
                                     "before it starts until after it ends")
        centres.append(seg.start + size / 2.0)
        found.append(lo + _cross_lag(piece, model[seg]) + size / 2.0)
    ratio, offset = np.polyfit(np.asarray(centres), np.asarray(found), 1)
    ratio, offset = float(ratio), float(offset)
    volts = wave.volts
    file_rate = wave.rate_hz

    def played(at: np.ndarray) -> np.ndarray:
        t_file = (np.asarray(at, float) - offset) / ratio / rate
        index = np.floor(t_file * file_rate + 1e-6).astype(np.int64)
        return np.asarray(np.where(index < 0, 0.0, volts[np.clip(index, 0, len(volts) - 1)]))

    start = offset + _file_start_s(wave) * rate * ratio
    end = offset + wave.duration_s * rate * ratio
    how = (f"the excitation file aligned by cross-correlation with the predicted SPD-MON: it starts "
           f"{offset / rate:.4f} s into the capture, clocks {1e6 * (ratio - 1.0):+.0f} ppm apart")
    return Alignment(start, _period_of_file(wave) * rate * ratio, end, how, ratio), played


def _records(capture: BenchCapture, alignment: Alignment, played: Any, settle_periods: int,
             ) -> tuple[list[tuple[np.ndarray, np.ndarray]], float, int]:
    """Whole periods resampled to ``n`` samples each (a length the FFT takes fast, at least the
    capture's samples per period): (records, their rate, n)."""
    n = next_fast_len(math.ceil(alignment.period), real=True)
    step = alignment.period / n
    total = int((alignment.end - alignment.start) // alignment.period)
    use = total - settle_periods
    if use < MIN_RECORDS:
        raise BenchResponseError(
            f"the capture holds {max(total, 0)} whole period(s) of the excitation "
            f"({alignment.period / capture.rate_hz:.3g} s each); {settle_periods} settle the loop and at "
            f"least {MIN_RECORDS} more are needed: record the whole excitation")
    positions = np.arange(len(capture.monitor_v), dtype=float)
    y_all = np.asarray(capture.monitor_v, float)
    records = []
    for p in range(settle_periods, total):
        at = alignment.start + (p * n + np.arange(n)) * step
        records.append((np.asarray(played(at), float), np.interp(at, positions, y_all)))
    return records, capture.rate_hz / step, n


def _settle_periods(lm: LoopModel, period_s: float) -> int:
    """Periods left to the loop's settling: the slowest closed-loop mode decays 12 time constants."""
    poles = np.abs(control.poles(lm.speed_loop()))
    slowest = float(np.max(poles[poles < 1.0])) if np.any(poles < 1.0) else 0.0
    tau = -lm.servo_period_s / math.log(slowest) if 0.0 < slowest < 1.0 else 0.0
    return max(1, math.ceil(12.0 * tau / period_s))


def _subset(fr: FrequencyResponse, keep: np.ndarray) -> FrequencyResponse:
    return FrequencyResponse(fr.freq_hz[keep], fr.magnitude_db[keep], fr.phase_deg[keep], fr.coherence[keep])


def _from_complex(freq: np.ndarray, h: np.ndarray, coherence: np.ndarray) -> FrequencyResponse:
    return FrequencyResponse(freq, 20.0 * np.log10(np.abs(h)), np.degrees(np.unwrap(np.angle(h))), coherence)


def _at(sys: Any, freq_hz: np.ndarray) -> np.ndarray:
    resp = control.frequency_response(control.tf(sys), TWO_PI * np.asarray(freq_hz, float))
    return np.asarray(resp.complex).reshape(-1)


def monitor_response(freq_hz: np.ndarray, bandwidth_hz: float | None) -> np.ndarray:
    """SPD-MON's own response: first order at ``bandwidth_hz``, or 1 when not given."""
    if not bandwidth_hz:
        return np.ones(len(freq_hz), complex)
    return np.asarray(1.0 / (1.0 + 1j * np.asarray(freq_hz, float) / bandwidth_hz))


def closed_and_plant(lm: LoopModel, records: Sequence[tuple[np.ndarray, np.ndarray]], rate_hz: float,
                     monitor_bandwidth_hz: float | None) -> tuple[FrequencyResponse, FrequencyResponse]:
    """The closed speed loop (SPD-MON / SPD-CMD, the monitor taken out) on the driven bins, and the
    plant (torque -> speed, as ``lm.plant()``) it implies with the drive's own controller, on the
    bins where the closed loop determines it."""
    measured = estimate_response(records, rate_hz)
    n = len(records[0][0])
    # a bin is driven where the input repeats from record to record (a periodic excitation) with
    # power: noise on a recorded SPD-CMD does not repeat
    spectra = np.asarray([np.fft.rfft(u - np.mean(u)) for u, _y in records])
    repeating = np.abs(spectra.mean(axis=0)) ** 2
    power = np.mean(np.abs(spectra) ** 2, axis=0)
    bins = np.rint(measured.freq_hz * n / rate_hz).astype(int)
    top = float(np.max(repeating[1:]))
    driven = (repeating[bins] >= REPEATING_SHARE * power[bins]) & (repeating[bins] >= DRIVEN_SHARE * top)
    # the band is where the excitation puts its power (a PRBS's tail beyond it aliases when the
    # drive samples SPD-CMD, and the alias repeats as the excitation does: no coherence shows it)
    strong = np.flatnonzero(repeating[bins] >= BAND_SHARE * top)
    driven &= measured.freq_hz <= (measured.freq_hz[strong[-1]] if len(strong) else 0.0) * 1.02
    driven &= measured.freq_hz < 0.45 * lm.settings.servo_rate_hz
    closed = _subset(measured, driven)
    if len(closed.freq_hz) < 5:
        raise BenchResponseError(f"the excitation drives {len(closed.freq_hz)} frequency bins: at least 5 "
                                 "are needed (a broadband excitation: the file FHA Studio writes)")
    f = closed.freq_hz
    t = closed.complex / monitor_response(f, monitor_bandwidth_hz)
    t_model, l_model = _at(lm.speed_loop()[0, 0], f), _at(lm.speed_open_loop(), f)
    p_model = _at(lm.plant(), f)
    share = l_model / (t_model * (1.0 + l_model))  # the feedback's share of the speed the loop sees
    loop = share * t / (1.0 - share * t)
    # where the loop holds the speed (|L| >> 1) T is near 1 and L = T / (1 - T) is lost in T's
    # random error (from the coherence, Bendat & Piersol's for H1): the plant only where L is known
    # within LOOP_ERROR
    gamma = np.sqrt(np.clip(closed.coherence, 1e-12, 1.0))
    error_t = np.sqrt(1.0 - gamma**2) / (gamma * math.sqrt(2.0 * len(records)))
    known = error_t / np.abs(1.0 - share * t) <= LOOP_ERROR
    closed = _from_complex(f, t, closed.coherence)
    plant = _from_complex(f[known], (p_model * loop / l_model)[known], closed.coherence[known])
    return closed, plant


def _load_from_pair(lm: LoopModel, plant: FrequencyResponse, rate_hz: float) -> float | None:
    fit = fit_two_mass(plant, rate_hz)
    if fit is None or not fit.resonance_hz or not fit.antiresonance_hz:
        return None
    if fit.resonance_hz <= fit.antiresonance_hz:
        return None
    return lm.model.motor_side_inertia_kgm2 * ((fit.resonance_hz / fit.antiresonance_hz) ** 2 - 1.0) \
        - (lm.model.load_side_inertia_kgm2 - lm.model.load_inertia_kgm2)


def analyse_bench_response(tuner: Tuner, capture: BenchCapture, excitation: Waveform | None = None,
                           monitor_bandwidth_hz: float | None = None) -> dict[str, Any]:
    """``tune measure``'s figures from a bench capture (see the module docstring);
    NotInSpeedMode when the items say position, BenchResponseError for a capture that gives none."""
    lm = speed_mode_loop(tuner)
    vpr = volts_per_output_rpm(tuner)
    alignment, played = align(capture, lm, vpr, excitation, monitor_bandwidth_hz)
    settle = _settle_periods(lm, alignment.period / capture.rate_hz)
    records, grid_rate, _n = _records(capture, alignment, played, settle)
    closed, plant = closed_and_plant(lm, records, grid_rate, monitor_bandwidth_hz)
    servo = tuner.servo_rate_hz
    result = response_figures(tuner, lm, closed, plant, servo)
    load = _load_from_pair(lm, plant, servo)
    spread = None
    if load is not None and len(records) >= 3:
        others = []
        for i in range(len(records)):
            _c, p = closed_and_plant(lm, [r for j, r in enumerate(records) if j != i], grid_rate,
                                     monitor_bandwidth_hz)
            others.append(_load_from_pair(lm, p, servo))
        if all(v is not None for v in others):
            values = np.asarray(others, float)
            spread = float(math.sqrt((len(values) - 1) / len(values) * np.sum((values - values.mean()) ** 2)))
    f = closed.freq_hz
    predicted = _at(lm.speed_loop()[0, 0], f)
    ok = closed.trusted()
    dev_db = closed.magnitude_db - 20.0 * np.log10(np.abs(predicted))
    dev_deg = (closed.phase_deg - np.degrees(np.angle(predicted)) + 180.0) % 360.0 - 180.0
    amplitude_v = float(np.max(np.abs(np.concatenate([u for u, _y in records]))))
    notes = []
    if load is None:
        notes.append("load inertia: no resonance pair in the trusted band, so it cannot be told from this "
                     "capture (SPD-MON and SPD-CMD carry no current: the inertia and the speed loop gain's "
                     "unit trade off); the CN3 trace or a current probe measures it")
    if not monitor_bandwidth_hz:
        notes.append("SPD-MON's own bandwidth is not given: its lag is in the phase (give it when known)")
    result.update({
        "load_inertia_estimate_kgm2": load,
        "load_inertia_uncertainty_kgm2": spread,
        "predicted_response": {k: v for k, v in _from_complex(f, predicted, np.ones(len(f))).to_dict().items()
                               if k != "coherence"},
        "deviation": {"magnitude_db": float(np.max(np.abs(dev_db[ok]))) if ok.any() else None,
                      "phase_deg": float(np.max(np.abs(dev_deg[ok]))) if ok.any() else None,
                      "trusted_bins": int(ok.sum()), "bins": len(ok)},
        "excitation": {"amplitude_rpm": amplitude_v / vpr, "peak_v": amplitude_v,
                       "period_s": alignment.period / capture.rate_hz, "records": len(records),
                       "settle_periods": settle},
        "bench": {"sample_rate_hz": capture.rate_hz, "alignment": alignment.how,
                  "clock_ratio": alignment.clock_ratio, "monitor_bandwidth_hz": monitor_bandwidth_hz,
                  "sources": dict(capture.sources)},
        "notes": notes,
    })
    return result
