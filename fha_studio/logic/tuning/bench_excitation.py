"""The excitation of a real HA-655's speed loop from a bench instrument's analog output.

In speed mode (parameter 0 = speed) the drive takes its speed command from SPD-CMD (CN2-31/32,
+/-10 V; +10 V = the motor speed of parameter 9): a DAQ's or a generator's output playing a file
excites the speed loop while SPD-MON (CN2-23, scaled by the same parameter 9) is recorded.

The excitation is periodic (one period is one record of the frequency response, leakage-free), in
one of three forms, each with its band [f_lo, f_hi] (f_lo = 1 / period):

- ``multisine`` (the default): every bin of the band at equal amplitude with Schroeder's phases
  (a low crest factor), nothing outside the band (nothing to alias when the drive samples SPD-CMD);
- ``prbs``: a maximum-length sequence (scipy.signal.max_len_seq) of +/- the amplitude, each bit held
  so that the band reaches f_hi (0.4 x the bit rate);
- ``chirp``: a linear sweep from f_lo to f_hi over each period (its power as flat as the
  multisine's over the band).

The excitation rides on a bias speed (a constant on SPD-CMD, ramped up in ``BIAS_RAMP_S`` before
the periods and down after them): ``excitation.BIAS_MARGIN`` x the largest speed the excitation
itself reaches, so the axis turns one way throughout and never sticks on its friction at a
reversal (``excitation`` says why; the analysis takes each record's mean out, the constant Coulomb
friction with it), FWD (SPD-CMD positive) or REV (negative), as the axis has room. ``bias``
``BiasDirection.NONE`` (or False): about standstill.

The band reaches 5 x the resonance the catalogue's stiffness and the declared load predict (or
500 Hz without one), at most 0.2 x the drive's servo rate; the period resolves the anti-resonance
with 40 bins below it (1 ... 8 s). The file starts and ends at 0 V (a DAQ holds its last value:
the axis stops with the file). Its bounds are stated before it is played, from the linearised
speed loop driven by the file itself (python-control): the angle the output travels, the peak
current and speed, the gear's torque; the amplitude is the largest within the shares of
:mod:`.excitation` (current, speed, the gear's first slope) unless a lower one is asked.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import control
import numpy as np
from scipy import signal

from fha_studio.hardware.bench.waveform import Waveform
from fha_studio.logic.tuning.bench_names import EXCITATION_FORMS
from fha_studio.logic.tuning.excitation import (
    BIAS_MARGIN,
    BIAS_SHARE,
    CURRENT_SHARE,
    GEAR_TORQUE_SHARE,
    RPM,
    SPEED_SHARE,
    BiasDirection,
)
from fha_studio.logic.tuning.linear import LoopModel, two_mass_prediction
from fha_studio.logic.tuning.propose import Tuner

FORMS = EXCITATION_FORMS
#: SPD-CMD takes +/-10 V
SPD_CMD_MAX_V = 10.0
#: the zero-volt lead-in and tail of the file [s]
LEAD_S = 0.05
#: periods played (the first is the loop settling, the rest are records)
PERIODS = 6
#: the band's top at most this share of the servo rate (the drive samples SPD-CMD at it)
SERVO_SHARE = 0.2
#: bins below the predicted anti-resonance
BINS_BELOW_ANTIRESONANCE = 40
PERIOD_LIMITS_S = (1.0, 8.0)
#: the bias speed is ramped up (and down) in this long, before (after) the periods [s]
BIAS_RAMP_S = 0.2


class NotInSpeedMode(ValueError):
    """The drive's parameter 0 is not speed: SPD-CMD does nothing (the CLI's exit 4)."""


@dataclass(frozen=True)
class BenchExcitation:
    """A designed excitation: its waveform and its bounds."""

    form: str
    amplitude_rpm: float  # the speed command's peak (output r/min)
    volts_per_rpm: float  # SPD-CMD volts per output r/min (parameter 9, the ratio)
    waveform: Waveform  # volts at the file's rate
    f_lo_hz: float
    f_hi_hz: float
    travel_bound_deg: float  # the largest angle from the start the linear loop travels
    peak_current_a: float
    max_current_a: float
    peak_speed_rpm: float  # output
    peak_gear_torque_nm: float | None
    drift_rpm_per_mv: float  # output speed of 1 mV of offset on SPD-CMD
    top_rpm: float  # the largest amplitude the shares allow
    bias_rpm: float = 0.0  # the constant speed the excitation rides on (output; 0: none)
    bias_sign: int = 1  # its direction: +1 FWD (SPD-CMD positive), -1 REV

    @property
    def peak_v(self) -> float:
        return self.waveform.peak_v

    @property
    def period_s(self) -> float:
        return self.waveform.period_samples / self.waveform.rate_hz

    def describe(self, manual_units: bool = False) -> str:
        """The excitation in a line; ``manual_units``: "°" as the manual prints it (a page), else
        "deg" (a terminal)."""
        w = self.waveform
        travel = f"{self.travel_bound_deg:.3g}" + ("°" if manual_units else " deg")
        periods = (len(w.volts) - 2 * w.start_sample) // max(1, w.period_samples)
        way = "FWD" if self.bias_sign > 0 else "REV"
        bias = (f" on a bias of {self.bias_rpm:.3g} r/min {way} (so the axis never reverses and sticks on "
                "its friction)" if self.bias_rpm > 0 else "")
        travels = f"at most {travel} {way}" if self.bias_rpm > 0 else f"at most ±{travel}"
        return (f"excitation on SPD-CMD: {self.form} of ±{self.amplitude_rpm:.3g} r/min at the output{bias} "
                f"(peak {self.peak_v:.3g} V), {self.f_lo_hz:.3g} ... {self.f_hi_hz:.3g} Hz, "
                f"{periods} periods of {self.period_s:.3g} s at {w.rate_hz:g} samples/s "
                f"({w.duration_s:.1f} s); the output travels {travels}, "
                f"current at most {self.peak_current_a:.3g} A of {self.max_current_a:g} A, speed at most "
                f"{self.peak_speed_rpm:.3g} r/min; 1 mV of offset on SPD-CMD turns the output at "
                f"{self.drift_rpm_per_mv:.2g} r/min (tune item 5 cancels it)")

    def to_dict(self) -> dict[str, Any]:
        return {"form": self.form, "amplitude_rpm": self.amplitude_rpm, "peak_v": self.peak_v,
                "f_lo_hz": self.f_lo_hz, "f_hi_hz": self.f_hi_hz, "period_s": self.period_s,
                "rate_hz": self.waveform.rate_hz, "duration_s": self.waveform.duration_s,
                "travel_bound_deg": self.travel_bound_deg, "peak_current_a": self.peak_current_a,
                "peak_speed_rpm": self.peak_speed_rpm, "peak_gear_torque_nm": self.peak_gear_torque_nm,
                "drift_rpm_per_mv": self.drift_rpm_per_mv, "bias_rpm": self.bias_rpm,
                "bias_direction": ("fwd" if self.bias_sign > 0 else "rev") if self.bias_rpm > 0 else "none"}


def volts_per_output_rpm(tuner: Tuner) -> float:
    """SPD-CMD (and SPD-MON) volts per output r/min: 10 V = parameter 9's motor r/min."""
    ratio = float(tuner.model.ratio or 1)
    return SPD_CMD_MAX_V * ratio / float(tuner.items["speed_conversion_factor"])


def speed_mode_loop(tuner: Tuner) -> LoopModel:
    """The speed loop as the drive runs it in speed mode; NotInSpeedMode when parameter 0 says
    position (SPD-CMD then does nothing)."""
    if int(tuner.items.get("control_mode", 0)) != 1:
        raise NotInSpeedMode("parameter 0 (control mode) is position: SPD-CMD drives the axis in speed "
                             "mode only; set parameter 0 to speed (1), cycle the control power, and "
                             "give the parameter file that says so")
    return tuner.loop({})


def band(lm: LoopModel, rate_hz: float) -> tuple[float, float]:
    """(period [s], the band's top [Hz]) for the axis of ``lm`` (see the module docstring)."""
    pred = two_mass_prediction(lm.model)
    top = 5.0 * pred.resonance_hz if pred.resonance_hz else 500.0
    top = min(top, SERVO_SHARE * lm.settings.servo_rate_hz, 0.4 * rate_hz)
    anti = pred.antiresonance_hz or 10.0
    period = min(max(BINS_BELOW_ANTIRESONANCE / anti, PERIOD_LIMITS_S[0]), PERIOD_LIMITS_S[1])
    return period, top


def unit_cycle(form: str, n: int, rate_hz: float, f_hi_hz: float) -> tuple[np.ndarray, float]:
    """One period of ``n`` samples of the form, peak 1, and the band's actual top [Hz]."""
    df = rate_hz / n
    if form == "multisine":
        k = np.arange(1, int(f_hi_hz / df) + 1)
        spectrum = np.zeros(n // 2 + 1, complex)
        spectrum[k] = np.exp(-1j * math.pi * k * (k - 1) / len(k))  # Schroeder's phases
        x = np.fft.irfft(spectrum, n)
        return x / np.max(np.abs(x)), float(k[-1] * df)
    if form == "chirp":
        t = np.arange(n) / rate_hz
        x = signal.chirp(t, df, n / rate_hz, f_hi_hz, method="linear", phi=-90.0)
        return x / np.max(np.abs(x)), f_hi_hz
    if form == "prbs":
        hold = max(1, int(0.4 * rate_hz / f_hi_hz))
        bits = max(4, min(18, int(math.log2(n / hold + 1))))
        seq = signal.max_len_seq(bits)[0].astype(float) * 2.0 - 1.0
        return np.repeat(seq, hold), 0.4 * rate_hz / hold
    raise ValueError(f"excitation form '{form}': one of {', '.join(FORMS)}")


def _at_servo_rate(volts: np.ndarray, rate_hz: float, servo_rate_hz: float) -> np.ndarray:
    """The file as the drive samples it: the value held at each servo period's start."""
    n = int(len(volts) * servo_rate_hz / rate_hz)
    idx = np.minimum(np.floor(np.arange(n) * rate_hz / servo_rate_hz + 1e-9).astype(int), len(volts) - 1)
    return np.asarray(volts[idx], float)


def discrete_filter(sys: Any, u: np.ndarray) -> np.ndarray:
    """A discrete-time SISO system (python-control) run on ``u`` by scipy's lfilter: its transfer
    function in z, the numerator padded to the denominator's length (z^-1 powers)."""
    tf = control.tf(sys)
    num, den = np.asarray(tf.num[0][0], float), np.asarray(tf.den[0][0], float)
    num = np.concatenate([np.zeros(len(den) - len(num)), num])
    return np.asarray(signal.lfilter(num / den[0], den / den[0], np.asarray(u, float)))


def linear_run(lm: LoopModel, speed_rad_s: np.ndarray) -> dict[str, np.ndarray]:
    """The linearised speed loop driven by a speed command at the servo rate (rad/s, output):
    the mean speed (rad/s), the current (A), the gear's torque (N m), the angle from the start
    (rad). Each output's transfer function (python-control) filtered by scipy's lfilter: a file of
    a minute at the servo rate in milliseconds."""
    u = np.asarray(speed_rad_s, float)

    def out(i: int) -> np.ndarray:
        return discrete_filter(lm.speed_loop()[i, 0], u)

    speed = out(1)
    return {"speed": speed, "current": out(3), "gear_torque": out(4),
            "angle": np.cumsum(speed) * lm.servo_period_s}


def design_excitation(tuner: Tuner, form: str = "multisine", amplitude_rpm: float | None = None,
                      rate_hz: float = 10000.0, periods: int = PERIODS,
                      period_s: float | None = None,
                      bias: BiasDirection | bool | str = BiasDirection.FWD) -> BenchExcitation:
    """The excitation for ``tuner``'s axis (its items say speed mode), on a bias speed FWD or REV
    (``BiasDirection.NONE`` or False: about standstill). ValueError for an amplitude above what the
    axis allows, an absurd rate or period count."""
    sign = BiasDirection.of(bias).sign
    biased = sign != 0
    lm = speed_mode_loop(tuner)
    if not (math.isfinite(rate_hz) and 1000.0 <= rate_hz <= 1e6):
        raise ValueError(f"rate {rate_hz:g} samples/s: 1000 ... 1000000")
    if not 3 <= periods <= 100:
        raise ValueError(f"{periods} periods: 3 ... 100 (the first is the loop settling)")
    auto_period, top = band(lm, rate_hz)
    period = auto_period if period_s is None else float(period_s)
    if not (math.isfinite(period) and 0.1 <= period <= 60.0):
        raise ValueError(f"period {period:g} s: 0.1 ... 60 s")
    n = round(period * rate_hz)
    cycle, f_hi = unit_cycle(form, n, rate_hz, top)
    n = len(cycle)
    lead = round(LEAD_S * rate_hz)
    servo = lm.settings.servo_rate_hz
    unit = np.concatenate([np.zeros(lead), np.tile(cycle, periods), np.zeros(lead)])
    # the loop driven by the file at 1 r/min, scaled (linear): the excitation's own speed
    own = linear_run(lm, _at_servo_rate(unit, rate_hz, servo) * RPM)
    per_speed = float(np.max(np.abs(own["speed"]))) / RPM
    model = tuner.model
    bias_unit, friction_a = 0.0, 0.0
    if biased:  # a constant under the periods, ramped: the speed never crosses zero (REV: negative)
        bias_unit = sign * BIAS_MARGIN * per_speed
        ramp = round(BIAS_RAMP_S * rate_hz)
        up = np.linspace(0.0, bias_unit, ramp, endpoint=False)
        unit = np.concatenate([np.zeros(lead), up, np.tile(cycle, periods) + bias_unit, up[::-1],
                               np.zeros(lead)])
        lead += ramp
        # the friction the bias turns against is drawn too: TF (2-4-4) kept in reserve
        friction_a = (model.friction_torque_nm or 0.0) / model.torque_constant_nm_per_a
    vpr = volts_per_output_rpm(tuner)
    run = linear_run(lm, _at_servo_rate(unit, rate_hz, servo) * RPM)
    per_current = float(np.max(np.abs(run["current"])))
    limits = [max(CURRENT_SHARE * model.max_current_a - friction_a, 0.0) / per_current,
              SPEED_SHARE * (model.max_speed_rpm or 60.0) / per_speed,
              SPD_CMD_MAX_V / vpr / float(np.max(np.abs(unit)))]
    if biased:
        limits.append(BIAS_SHARE * (model.max_speed_rpm or 60.0) / abs(bias_unit))
    per_speed = float(np.max(np.abs(run["speed"]))) / RPM  # the bias with it
    per_torque = None
    if model.stiffness is not None:
        per_torque = float(np.max(np.abs(run["gear_torque"])))
        limits.append(GEAR_TORQUE_SHARE * model.stiffness.t1_nm / per_torque)
    top_rpm = min(limits)
    amplitude = top_rpm if amplitude_rpm is None else float(amplitude_rpm)
    if not (math.isfinite(amplitude) and 0.0 < amplitude <= top_rpm * (1 + 1e-9)):
        raise ValueError(f"excitation amplitude {amplitude:g} r/min: allowed 0 ... {top_rpm:.3g} r/min for "
                         f"this axis (current within {CURRENT_SHARE:.0%} of {model.max_current_a:g} A, speed "
                         f"within {SPEED_SHARE:.0%} of the maximum, the gear on its first slope, SPD-CMD "
                         f"within ±{SPD_CMD_MAX_V:g} V" + (f", the bias within {BIAS_SHARE:.0%} of the "
                                                          "maximum speed)" if biased else ")"))
    wave = Waveform(rate_hz, unit * amplitude * vpr,
                    f"{form}, ±{amplitude:.4g} r/min at the output, period {n / rate_hz:.6g} s",
                    period_samples=n, start_sample=lead)
    return BenchExcitation(
        form=form, amplitude_rpm=amplitude, volts_per_rpm=vpr, waveform=wave,
        f_lo_hz=rate_hz / n, f_hi_hz=f_hi,
        # the run's angle is already in rad per r/min of amplitude
        travel_bound_deg=math.degrees(amplitude * float(np.max(np.abs(run["angle"])))),
        peak_current_a=amplitude * per_current + friction_a, max_current_a=model.max_current_a,
        peak_speed_rpm=amplitude * per_speed,
        peak_gear_torque_nm=None if per_torque is None else amplitude * per_torque,
        drift_rpm_per_mv=1e-3 / vpr, top_rpm=top_rpm, bias_rpm=amplitude * abs(bias_unit),
        bias_sign=sign or 1,
    )
