"""The excitation's bounds, stated before it starts: amplitude (r/min), the angle it may travel.

The drive adds a PRBS of +/- the amplitude to the speed command (docs/protocol.md, EXG). For a
linear loop the largest value any output can reach under an input bounded by A is A x the L1 norm
of its impulse response (``sum |h|``: the impulse response of the linearised loops from the added
speed command): so the amplitude is chosen to keep the current within ``CURRENT_SHARE`` of the
maximum current and the gear on its first slope (the speed loop's response: the position loop's
reaction to an excitation this small is slow and small), and the angle travelled is at most A x the
L1 norm from the added speed command to the position (the position loop closed: it holds the
axis). The drive stops the excitation if the output ever travels farther than that bound (with
a margin) from where it started.

The axis turns one way throughout (a bias speed, FWD or REV as the person chooses: the axis's
room decides, ``travel``): a real axis has friction, and Coulomb friction
flips at every reversal of the speed, where the axis sticks until the loop's torque breaks it away
again, so the torque -> speed response of an excitation about standstill loses its gain at low
frequency and what is fitted to it (inertia, resonance) is wrong. The excitation therefore runs
on top of a slow JOG whose speed is ``BIAS_MARGIN`` x the largest speed the excitation itself
can reach (A x the L1 norm from the added speed command to the motor-side speed), so the speed
never crosses zero: the Coulomb friction is then a constant torque (no part of the response) and
the viscous friction a linear damping (``linear`` models it and ``response.fit_two_mass`` fits
it). The axis then travels the bias speed x the duration besides the excitation's own bound, which
the plan states; the drive measures the travel limit from the jog's command path. The current
bound keeps the catalogue's friction torque (TF, FHA-C manual 2-4-4) in reserve. A bias of 0
excites about standstill (an axis that may not turn that far): where the output speed then
reverses, ``session`` warns (the coherence does not show it: the stick-slip repeats with the
periodic excitation).

Only a stable loop is excited: with the present tune items and the declared load the linearised
loops must be stable (:func:`check_stable`), or the drive is not excitable (the speed loop gain is
set on the actuator's own inertia, ``physics.PanelGains``: a heavy load can lower the speed
loop's crossover under the position loop's, and the axis then oscillates as soon as anything
moves it).

Before each record the loop settles: the excitation runs until what its start set going has
died away, i.e. until the impulse responses' tails beyond that time hold at most
``SETTLE_TAIL`` of their L1 norms (a slow pole that its zero nearly cancels does not count).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import StrEnum

import numpy as np

from fha_studio.hardware.protocol import JOG_HOLD_S, SPEED_STEP_RPM, excitation_period_periods
from fha_studio.logic.tuning.linear import LoopModel, LoopPolynomials, two_mass_prediction
from fha_studio.logic.wording import with_unit
from fha_studio.physics import PanelGains

RPM = 2.0 * math.pi / 60.0
#: the excitation's current stays below this share of the maximum current (linear bound)
CURRENT_SHARE = 0.7
#: the gear's torque stays below this share of T1 (the end of 1-9-2's first, linear slope)
GEAR_TORQUE_SHARE = 1.0
#: at most this share of the maximum speed
SPEED_SHARE = 0.05
#: the drive's travel limit is the linear bound times this
TRAVEL_MARGIN = 2.0
#: records (one PRBS period each) averaged
RECORDS = 5
#: before a record, what the excitation's start set going holds at most this share of the response
SETTLE_TAIL = 0.005
#: the impulse responses are followed this long at most (s)
HORIZON_S = 30.0
#: the bias speed is this many times the largest speed the excitation can reach (linear bound, a
#: worst case over every input: a PRBS reaches a fraction of it)
BIAS_MARGIN = 1.2
#: the bias speed at most this share of the maximum speed (the amplitude is lowered to keep it)
BIAS_SHARE = 0.05


class BiasDirection(StrEnum):
    """Which way the bias speed turns the axis (the JOG's FWD or REV command), or none: about
    standstill (an axis that may not turn that far; the friction then shows, and is warned of)."""

    FWD = "fwd"
    REV = "rev"
    NONE = "none"

    @property
    def sign(self) -> int:
        """+1 FWD, -1 REV, 0 about standstill: the sign of the JOG's speed (command sense)."""
        return {"fwd": 1, "rev": -1, "none": 0}[self.value]

    @classmethod
    def of(cls, bias: BiasDirection | bool | str) -> BiasDirection:
        """``True``: FWD (the default), ``False``: about standstill; a name as ``tune measure
        --bias`` takes it."""
        if isinstance(bias, bool):
            return cls.FWD if bias else cls.NONE
        return cls(str(bias).lower())


def rotation_words(sign: int, fwd_is_cw: bool | None) -> str:
    """The JOG's command and the rotation it gives in the manual's words (1-10: a FWD command turns
    the output CW seen from the flange with rotary direction 0, CCW with 1): "FWD (CW seen from
    the flange)"; the command alone where the rotary direction is not known."""
    command = "FWD" if sign > 0 else "REV"
    if fwd_is_cw is None:
        return command
    return f"{command} ({'CW' if (sign > 0) == fwd_is_cw else 'CCW'} seen from the flange)"


class NotExcitable(Exception):
    """The drive cannot be excited: the message says what is needed (the CLI's exit 4)."""


def check_stable(lm: LoopModel) -> None:
    """Raise NotExcitable unless ``lm``'s speed and position loops are stable: the message names
    the load, where the speed loop gain puts the crossover with it, and what to do."""
    poly = lm.polynomials()
    if poly.stable():
        return
    model = lm.model
    panel = PanelGains.of_settings(model, lm.settings)
    ratio = model.load_inertia_kgm2 / model.actuator_inertia_kgm2
    crossover = PanelGains.crossover_hz(model, panel.speed_loop_gain_hz)
    which = "speed loop" if not poly.speed_stable() else "position loop"
    raise NotExcitable(
        f"the present tune items make the {which} unstable with the declared load ({ratio:.3g} x the "
        f"actuator's own inertia: the speed loop gain of {panel.speed_loop_gain_hz:.4g} Hz crosses over "
        f"at about {crossover:.3g} Hz with it, position loop gain {panel.position_loop_gain_per_s:.4g} "
        "1/s): the axis would oscillate; propose gains and apply them (or lower the position loop "
        "gain) before measuring")


@dataclass(frozen=True)
class ExcitationPlan:
    amplitude_rpm: float
    hold_periods: int
    period_samples: int
    records: int
    travel_bound_deg: float  # the linear bound of the angle travelled (either way)
    travel_limit_deg: float  # where the drive stops it
    peak_current_a: float  # the linear bound of the current (and the friction the bias turns against)
    f_max_hz: float
    settle_s: float  # before each record: the slowest closed-loop mode decays (6 time constants)
    duration_s: float
    bias_rpm: float = 0.0  # the JOG's speed the excitation rides on (0: about standstill)
    speed_bound_rpm: float = 0.0  # the linear bound of the excitation's own speed (either way)
    bias_sign: int = 1  # the JOG's direction: +1 FWD, -1 REV (command sense)

    @property
    def bias_direction(self) -> BiasDirection:
        if self.bias_rpm <= 0:
            return BiasDirection.NONE
        return BiasDirection.FWD if self.bias_sign > 0 else BiasDirection.REV

    @property
    def jog_speed_rpm(self) -> float:
        """The JOG command's speed, signed (command sense: + FWD)."""
        return self.bias_sign * self.bias_rpm

    @property
    def bias_travel_deg(self) -> float:
        """The angle the bias speed turns the axis through during the measurement, at most: each
        record after a restart (a read-out longer than the jog watchdog, which the jog coasts on
        for): the jog's settling, the excitation's, the record (the jog's ramp is not counted: at
        the default JOG acceleration it takes milliseconds)."""
        return self.bias_rpm * 6.0 * (self.duration_s + self.records * (self.settle_s + JOG_HOLD_S))

    def describe(self, manual_units: bool = False, fwd_is_cw: bool | None = None) -> str:
        """The excitation in a line. ``manual_units``: "±" and "°" as the FHA-C manual prints them
        (what a person reads on a page); else plain ASCII ("+/-", "deg") for a terminal or a log.
        ``fwd_is_cw``: the rotary direction (1-10), so the jog's rotation is named too."""
        pm = "±" if manual_units else "+/-"

        def deg(value: float) -> str:
            return with_unit(f"{value:.3g}", "deg") if manual_units else f"{value:.3g} deg"

        periods = f"{self.hold_periods} servo period" + ("" if self.hold_periods == 1 else "s")
        if self.bias_rpm > 0:
            way = rotation_words(self.bias_sign, fwd_is_cw)
            where = (f" on a jog of {self.bias_rpm:.3g} r/min {way}, which turns the axis up to about "
                     f"{deg(self.bias_travel_deg)} {'FWD' if self.bias_sign > 0 else 'REV'} (so it never "
                     "reverses and sticks on its friction)")
            about = " about the jog's path"
        else:
            where = about = ""
        return (f"excitation: PRBS of {pm}{self.amplitude_rpm:.3g} r/min on the speed command{where}, bits "
                f"of {periods}, {self.records} records of {self.period_samples} "
                f"samples ({self.duration_s:.1f} s); the output travels at most "
                f"{pm}{deg(self.travel_bound_deg)}{about} (the drive stops at {deg(self.travel_limit_deg)}), "
                f"current at most {self.peak_current_a:.3g} A")


def _impulse(lm: LoopModel) -> np.ndarray:
    """Position, current and gear torque after 1 rad/s added to the speed command for one period
    (samples x 3), followed until the tails are negligible or ``HORIZON_S``."""
    poly = lm.polynomials()
    return _followed(poly, lm.settings.servo_rate_hz)


def _followed(poly: LoopPolynomials, rate: float) -> np.ndarray:
    seconds = 2.0
    while True:
        h = poly.impulse(int(seconds * rate))
        tail = np.abs(h[-int(0.1 * rate):]).sum(axis=0)
        if seconds >= HORIZON_S or np.all(tail <= 1e-4 * np.abs(h).sum(axis=0)):
            return h
        seconds = min(4.0 * seconds, HORIZON_S)


def _settle_s(h: np.ndarray, rate: float) -> float:
    """The time after which each response's tail holds at most ``SETTLE_TAIL`` of its L1 norm."""
    settle = 0.0
    for column in np.abs(h).T:
        total = column.sum()
        if total <= 0.0:
            continue
        tail = total - np.cumsum(column)  # what comes after each sample
        settle = max(settle, float(np.argmax(tail <= SETTLE_TAIL * total)) / rate)
    return settle


def plan_excitation(lm: LoopModel, requested_rpm: float | None = None,
                    bias: BiasDirection | bool | str = BiasDirection.FWD) -> ExcitationPlan:
    """The excitation for ``lm``'s axis: bits held so that the PRBS covers ~5 x the predicted
    resonance (or 2 x the speed loop's reach), the largest amplitude within the current and speed
    shares and the gear's torque on its first slope (or ``requested_rpm`` when lower; a higher
    request raises ValueError; an unstable loop NotExcitable), on a bias speed that keeps the axis
    turning one way, FWD or REV (``BiasDirection.NONE`` or False: about standstill)."""
    direction = BiasDirection.of(bias)
    sign = direction.sign
    biased = sign != 0
    check_stable(lm)
    model = lm.model
    rate = lm.settings.servo_rate_hz
    dt = 1.0 / rate
    pred = two_mass_prediction(model)
    want_hz = 5.0 * pred.resonance_hz if pred.resonance_hz else 500.0
    hold = 1
    while hold < 8 and 0.4 * rate / (2 * hold) >= want_hz:
        hold *= 2
    h = _impulse(lm)
    per_rad = float(np.abs(h[:, 0]).sum())
    per_speed = float(np.abs(np.diff(h[:, 0], prepend=0.0)).sum()) * rate  # motor-side speed per rad/s
    speed_loop = LoopModel(model, replace(lm.settings, position_loop_gain_per_s=0.0)).polynomials()
    per_a, per_nm = (float(v) for v in np.abs(_followed(speed_loop, rate)[:, 1:]).sum(axis=0))
    # the friction the bias speed turns against is drawn too: TF (2-4-4) kept in reserve
    friction_a = (model.friction_torque_nm or 0.0) / model.torque_constant_nm_per_a if biased else 0.0
    top_rpm = min(max(CURRENT_SHARE * model.max_current_a - friction_a, 0.0) / per_a / RPM,
                  SPEED_SHARE * (model.max_speed_rpm or 60.0))
    if model.stiffness is not None and per_nm > 0.0:  # the gear stays on its first slope (K1, 1-9-2)
        top_rpm = min(top_rpm, GEAR_TORQUE_SHARE * model.stiffness.t1_nm / per_nm / RPM)
    if biased:  # a lightly damped loop swings far: a smaller amplitude keeps the bias within its share
        top_rpm = min(top_rpm, BIAS_SHARE * (model.max_speed_rpm or 60.0) / (BIAS_MARGIN * per_speed))
    amplitude = top_rpm if requested_rpm is None else float(requested_rpm)
    if not 0.0 < amplitude <= top_rpm * (1 + 1e-9):
        raise ValueError(f"excitation amplitude {amplitude:g} r/min: allowed 0 ... {top_rpm:.3g} r/min "
                         f"for this axis (current within {CURRENT_SHARE:.0%} of {model.max_current_a:g} A, "
                         f"speed within {SPEED_SHARE:.0%} of the maximum"
                         + (f", the bias speed within {BIAS_SHARE:.0%} of it)" if biased else ")"))
    travel = math.degrees(amplitude * RPM * per_rad)
    period = excitation_period_periods(hold)
    settle = min(max(_settle_s(h, rate), 0.1), HORIZON_S)
    speed_bound_rpm = amplitude * per_speed
    # the JOG's speed step: rounded up to it
    steps = math.ceil(BIAS_MARGIN * speed_bound_rpm / SPEED_STEP_RPM - 1e-9) if biased else 0
    bias_rpm = round(steps * SPEED_STEP_RPM, 6)
    return ExcitationPlan(
        amplitude_rpm=amplitude, hold_periods=hold, period_samples=period, records=RECORDS,
        travel_bound_deg=travel, travel_limit_deg=TRAVEL_MARGIN * travel + 0.01,
        peak_current_a=amplitude * RPM * per_a + friction_a, f_max_hz=0.4 * rate / hold, settle_s=settle,
        duration_s=RECORDS * (settle + period * dt), bias_rpm=bias_rpm, speed_bound_rpm=speed_bound_rpm,
        bias_sign=sign or 1,
    )
