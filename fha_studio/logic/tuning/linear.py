"""The speed and position loops of the physics model, linearised (python-control, discrete time).

The numbers come from the one physics model: ``physics.servo.kernel_params(model, settings)``
flattens an ``AxisModel`` and ``ServoSettings`` for the simulated loop, and the same numbers build
the linear model here, period for period as ``physics._kernel.run`` computes:

- plant: the two-mass system of docs/physics.md (motor side J_A - J_flange, load side
  J_flange + J_L, the gear's spring at K1 with its structural damping), or one rigid mass without
  torsional compliance, driven by the current held over each servo period (zero-order hold);
- speed feedback: the motor-side speed at the start of the period, or with quantised feedback the
  position difference per period low-passed (``speed_filter_alpha``);
- PI speed controller: i = Kv x (e + integral), the integral summed per period (backward Euler);
- position loop: speed command = Kp x (command - position) + FF x command speed.

Friction, quantisation and the current limit are not in the linear model (the excitation stays
well inside the current limit; quantisation is noise). The trace records the speed at the end of
each period, so the measured closed loop and plant carry one period's advance (``z``) against the
loop's own signals: ``speed_closed_loop`` and ``plant`` include it.

Two-mass prediction (the catalogue's K1 and the declared load): anti-resonance
sqrt(K1 / J_load) and resonance sqrt(K1 x (1/J_motor + 1/J_load)), in Hz.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import control
import numpy as np

from fha_studio.physics import AxisModel, ServoSettings
from fha_studio.physics.servo import kernel_params

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class TwoMassPrediction:
    """What the catalogue's stiffness and the declared load inertia predict (Hz); None when the
    model has no torsional compliance (one rigid mass)."""

    resonance_hz: float | None
    antiresonance_hz: float | None


def two_mass_prediction(model: AxisModel) -> TwoMassPrediction:
    """Resonance and anti-resonance of the gear's spring (K1, 1-9-2) between the motor side and
    the load side of ``model`` (whether or not its torsional compliance is switched on)."""
    stiffness = model.stiffness
    if stiffness is None:
        return TwoMassPrediction(None, None)
    k = stiffness.k1_nm_per_rad
    jm, jl = model.motor_side_inertia_kgm2, model.load_side_inertia_kgm2
    return TwoMassPrediction(
        resonance_hz=math.sqrt(k * (1.0 / jm + 1.0 / jl)) / TWO_PI,
        antiresonance_hz=math.sqrt(k / jl) / TWO_PI,
    )


def _ss(a: Any, b: Any, c: Any, d: Any, dt: float) -> Any:
    return control.ss(np.atleast_2d(a), np.atleast_2d(b), np.atleast_2d(c), np.atleast_2d(d), dt)


@functools.lru_cache(maxsize=64)
def _discrete_plant(model: AxisModel, servo_rate_hz: float) -> Any:
    """Current (A) held over a period -> [motor-side speed at the start of the period, mean
    motor-side speed over the period (position change / dt), speed at its end, the current
    itself, the gear's torque at K1]. States: the
    speeds and the twist (positions do not act on the dynamics, so no integrator is hidden)."""
    # the plant does not depend on the gains: ServoSettings' defaults at this rate
    p = kernel_params(model, ServoSettings(servo_rate_hz=servo_rate_hz))
    if p.compliant:
        jm, jl, k, c = p.jm, p.jl, p.k1, p.damping
        # states [xm, vm, twist, vl]; xm only to read its change over the period
        a = np.array([[0, 1, 0, 0],
                      [0, -c / jm, -k / jm, c / jm],
                      [0, 1, 0, -1],
                      [0, c / jl, k / jl, -c / jl]], float)
        b = np.array([[0], [p.kt / jm], [0], [0]], float)
    else:
        a = np.array([[0, 1], [0, 0]], float)
        b = np.array([[0], [p.kt / p.j_total]], float)
    n = a.shape[0]
    disc = control.c2d(control.ss(a, b, np.eye(n), np.zeros((n, 1))), p.dt, method="zoh")
    phi, gamma = np.asarray(disc.A), np.asarray(disc.B)
    keep = list(range(1, n))  # the speed states (and twist)
    ad, bd = phi[np.ix_(keep, keep)], gamma[keep, :]
    start = np.zeros((1, n - 1))
    start[0, 0] = 1.0
    mean = phi[[0], :][:, keep] / p.dt
    spring = np.zeros((1, n - 1))
    if p.compliant:
        spring[0, 1] = p.k1  # the gear's torque at K1 (for the excitation's bound)
    c_out = np.vstack([start, mean, ad[[0], :], np.zeros((1, n - 1)), spring])
    d_out = np.vstack([[[0.0]], gamma[[0], :] / p.dt, bd[[0], :], [[1.0]], [[0.0]]])
    return control.ss(ad, bd, c_out, d_out, p.dt)


@dataclass(frozen=True)
class LoopModel:
    """The linearised loops of one axis at one set of servo settings (discrete, servo period)."""

    model: AxisModel
    settings: ServoSettings

    @property
    def servo_period_s(self) -> float:
        return 1.0 / self.settings.servo_rate_hz

    # ----- building blocks ----------------------------------------------------------------------
    def _plant(self) -> Any:
        return _discrete_plant(self.model, self.settings.servo_rate_hz)



    def _feedback_selector(self) -> Any:
        """Plant outputs -> the speed the loop sees: the speed at the start of the period, or with
        quantised feedback the last period's position difference / dt, low-passed."""
        p = kernel_params(self.model, self.settings)
        if p.pulse_rad > 0.0:
            alpha = p.speed_filter_alpha
            # v_f[k] = v_f[k-1] + alpha (dx[k-1]/dt - v_f[k-1])
            filt = control.ss(control.tf([alpha], [1.0, -(1.0 - alpha)], p.dt))
            return filt * control.ss([], [], [], [[0.0, 1.0, 0.0, 0.0, 0.0]], p.dt)
        return control.ss([], [], [], [[1.0, 0.0, 0.0, 0.0, 0.0]], p.dt)

    def speed_controller(self) -> Any:
        """PI: Kv x (1 + (dt/Tv) z/(z - 1)), speed error (rad/s) -> current (A)."""
        p = kernel_params(self.model, self.settings)
        ki = p.dt * p.tv_inv
        return control.tf([p.kv * (1.0 + ki), -p.kv], [1.0, -1.0], p.dt)

    # ----- the loops -------------------------------------------------------------------------
    def speed_open_loop(self) -> Any:
        """Loop gain of the speed loop, broken at the current command (for the margins)."""
        return self._feedback_selector() * self._plant() * control.ss(self.speed_controller())

    def speed_loop(self) -> Any:
        """Speed command (rad/s) -> the plant's outputs with the speed loop closed."""
        forward = self._plant() * control.ss(self.speed_controller())
        return control.feedback(forward, self._feedback_selector())

    def plant(self) -> Any:
        """Torque (N m, Kt x the commanded current, as monitor 108 reports it) -> output speed
        (rad/s) as the trace records it (end of the period)."""
        return self._plant()[2, 0] * (1.0 / self.model.torque_constant_nm_per_a)

    def speed_closed_loop(self) -> Any:
        """Speed command (rad/s) -> output speed (rad/s) as the trace records both."""
        return self.speed_loop()[2, 0]

    def _position_per_speed_command(self) -> Any:
        """Speed command -> motor-side position at the start of the period (rad)."""
        dt = self.servo_period_s
        integrate = control.ss(control.tf([dt], [1.0, -1.0], dt))
        return integrate * self.speed_loop()[1, 0]

    def injection_to_position(self) -> Any:
        """An added speed command (rad/s) -> motor-side position (rad), with the position loop
        closed: bounds the angle an excitation travels."""
        p = kernel_params(self.model, self.settings)
        return control.feedback(self._position_per_speed_command(), control.ss([], [], [], [[p.kp]], p.dt))

    def position_closed_loop(self) -> Any:
        """Position command (rad) -> motor-side position (rad), Kp and feed-forward as set."""
        p = kernel_params(self.model, self.settings)
        dt = p.dt
        pos = self._position_per_speed_command()
        # speed command = Kp (c - x) + FF (c - c_prev)/dt
        pre = control.ss(control.tf([p.kp + p.ff / dt, -p.ff / dt], [1.0, 0.0], dt))
        loop = control.feedback(pos, control.ss([], [], [], [[p.kp]], dt))
        # (Kp + FF d/dt) c - Kp x  ==  pre(c) - Kp x
        return loop * pre

    # ----- figures ---------------------------------------------------------------------------
    def response(self, which: str, freq_hz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Magnitude (dB) and phase (deg, unwrapped) of ``plant`` or ``speed_closed_loop``."""
        sys = self.plant() if which == "plant" else self.speed_closed_loop()
        resp = control.frequency_response(sys, TWO_PI * np.asarray(freq_hz, float))
        h = np.asarray(resp.complex).reshape(-1)
        return 20.0 * np.log10(np.abs(h)), np.degrees(np.unwrap(np.angle(h)))

    def quantisation_current_noise_a(self) -> float:
        """Standard deviation of the current that the encoder's quantisation makes through the
        speed loop (A): the pulse difference per period has the variance q^2/6 of two uniform
        rounding errors, the speed filter passes alpha/(2 - alpha) of it, Kv amplifies it. 0 with
        ideal feedback."""
        p = kernel_params(self.model, self.settings)
        if p.pulse_rad <= 0.0:
            return 0.0
        alpha = p.speed_filter_alpha
        return p.kv * p.pulse_rad / p.dt * math.sqrt(alpha / (2.0 - alpha) / 6.0)

    def current_per_position_pulse_a(self) -> float:
        """Current (A) one encoder pulse of position error asks for (Kv x Kp x pulse)."""
        p = kernel_params(self.model, self.settings)
        return p.kv * p.kp * self.model.output_pulse_rad

    def stable(self) -> bool:
        """True when the closed speed and position loops are stable."""
        poles = np.concatenate([control.poles(self.speed_loop()), control.poles(self.position_closed_loop())])
        return bool(np.all(np.abs(poles) < 1.0 - 1e-9))


def kernel_gains(model: AxisModel, settings: ServoSettings) -> dict[str, float]:
    """Kv (A s/rad), Tv (s), Kp (1/s) and FF as the loop uses them (from the physics)."""
    p = kernel_params(model, settings)
    return {"kv": p.kv, "tv_s": (1.0 / p.tv_inv) if p.tv_inv else math.inf, "kp": p.kp, "ff": p.ff}
