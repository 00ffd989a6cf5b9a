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

Viscous friction (the model's effect, on the motor side as the kernel puts it) is part of the
plant: it is linear. Coulomb friction, quantisation and the current limit are not in the linear
model: the excitation rides on a bias speed so the Coulomb friction is a constant torque
(``excitation``), it stays well inside the current limit, and quantisation is noise.
The trace records the speed at the end of each period, so the measured closed loop and plant
carry one period's advance (``z``) against the loop's own signals: ``speed_closed_loop`` and
``plant`` include it.

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
from scipy import signal

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
                      [0, -(c + p.visc) / jm, -k / jm, c / jm],
                      [0, 1, 0, -1],
                      [0, c / jl, k / jl, -c / jl]], float)
        b = np.array([[0], [p.kt / jm], [0], [0]], float)
    else:
        a = np.array([[0, 1], [0, -p.visc / p.j_total]], float)
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

    def polynomials(self) -> LoopPolynomials:
        """The same loops built with numpy alone (see ``LoopPolynomials``)."""
        p = kernel_params(self.model, self.settings)
        nums, den = _plant_polynomials(self.model, self.settings.servo_rate_hz)
        plant = _discrete_plant(self.model, self.settings.servo_rate_hz)
        ad, bd, cp, dp = (np.asarray(m, float) for m in (plant.A, plant.B, plant.C, plant.D))
        ki = p.dt * p.tv_inv
        g_e, g_s = p.kv * (1.0 + ki), p.kv * ki  # i = g_e e + g_s (the integral before this period)
        nc, dc = np.array([g_e, -p.kv]), np.array([1.0, -1.0])
        quantised = p.pulse_rad > 0.0
        alpha = p.speed_filter_alpha if quantised else 1.0
        if quantised:  # the pulse difference per period (the mean speed), low-passed
            nf, df, fb = np.array([alpha]), np.array([1.0, -(1.0 - alpha)]), nums[1]
        else:
            nf, df, fb = np.array([1.0]), np.array([1.0]), nums[0]
        open_num = np.polymul(np.polymul(nf, fb), nc)
        open_den = np.polymul(np.polymul(df, den), dc)
        char = np.polyadd(open_den, open_num)
        # the closed position loop in state space: [plant states, integral, (filtered speed), position]
        n_p = ad.shape[0]
        n = n_p + 1 + (1 if quantised else 0) + 1
        i_s, i_f, i_x = n_p, n_p + 1, n - 1
        feedback = np.zeros(n)  # the speed the loop sees
        if quantised:
            feedback[i_f] = 1.0
        else:
            feedback[:n_p] = cp[0]
        error = -feedback
        error[i_x] -= p.kp  # e = input - Kp x - feedback
        current = g_e * error
        current[i_s] += g_s  # i = row . state + g_e input
        a = np.zeros((n, n))
        b = np.zeros((n, 1))
        a[:n_p, :] = bd @ current[None, :]
        a[:n_p, :n_p] += ad
        b[:n_p, 0] = bd[:, 0] * g_e
        a[i_s, :] = error
        a[i_s, i_s] += 1.0
        b[i_s, 0] = 1.0
        mean = np.zeros(n)  # the mean speed over the period
        mean[:n_p] = cp[1]
        mean += dp[1, 0] * current
        if quantised:
            a[i_f, :] = alpha * mean
            a[i_f, i_f] += 1.0 - alpha
            b[i_f, 0] = alpha * dp[1, 0] * g_e
        a[i_x, :] = p.dt * mean
        a[i_x, i_x] += 1.0
        b[i_x, 0] = p.dt * dp[1, 0] * g_e
        c = np.zeros((3, n))
        c[0, i_x] = 1.0
        c[1, :] = current
        c[2, :n_p] = cp[4]
        d = np.array([[0.0], [g_e], [0.0]])
        return LoopPolynomials(
            dt=p.dt, kp=p.kp, ff=p.ff, speed_num=open_num, speed_den=open_den, speed_char=char,
            position_num=p.dt * np.polymul(np.polymul(nums[1], nc), df),
            position_den=np.polymul([1.0, -1.0], char), a=a, b=b, c=c, d=d,
        )

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


@functools.lru_cache(maxsize=64)
def _plant_polynomials(model: AxisModel, servo_rate_hz: float) -> tuple[tuple[np.ndarray, ...], np.ndarray]:
    """``_discrete_plant``'s outputs as polynomials in z over one common denominator
    (scipy.signal.ss2tf): the numerators of [speed at the start, mean speed, speed at the end,
    current, gear torque] per ampere, and the denominator (for frequency responses)."""
    plant = _discrete_plant(model, servo_rate_hz)
    a, b, c, d = (np.asarray(m, float) for m in (plant.A, plant.B, plant.C, plant.D))
    nums, den = signal.ss2tf(a, b, c, d)
    return tuple(np.trim_zeros(np.asarray(row, float), "f") if np.any(row) else np.zeros(1)
                 for row in nums), np.asarray(den, float)


@dataclass(frozen=True)
class LoopPolynomials:
    """The loops of a ``LoopModel`` built with numpy alone, for a search over many gains (a
    candidate's margins, stability and the response to a move in about a millisecond; python-
    control's interconnections take tens): the open loops as polynomials in z (their frequency
    responses), and the closed position loop as one state-space model (its poles, and a move
    simulated block by block). The same composition as the state-space loops of ``LoopModel``,
    period for period; ``LoopModel.polynomials()`` builds it."""

    dt: float
    kp: float
    ff: float
    speed_num: np.ndarray  # the speed loop's open loop, broken at the current command
    speed_den: np.ndarray
    speed_char: np.ndarray  # the closed speed loop's characteristic polynomial
    position_num: np.ndarray  # speed command -> position at the start of the period (closed speed loop)
    position_den: np.ndarray
    # the closed position loop, input: the speed command before the position error,
    # (Kp + FF/dt) c[k] - (FF/dt) c[k-1], or a speed added to it; outputs: the position (rad),
    # the current (A), the gear's torque at K1 (N m)
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray

    @staticmethod
    def _at(num: np.ndarray, den: np.ndarray, freq_hz: np.ndarray, dt: float) -> np.ndarray:
        z = np.exp(1j * TWO_PI * np.asarray(freq_hz, float) * dt)
        return np.asarray(np.polyval(num, z) / np.polyval(den, z))

    def speed_open_loop_at(self, freq_hz: np.ndarray) -> np.ndarray:
        return self._at(self.speed_num, self.speed_den, freq_hz, self.dt)

    def position_open_loop_at(self, freq_hz: np.ndarray) -> np.ndarray:
        """Kp x (speed command -> position): the position loop broken at the position error."""
        return self.kp * self._at(self.position_num, self.position_den, freq_hz, self.dt)

    def speed_stable(self) -> bool:
        """True when the closed speed loop alone is stable."""
        return bool(np.all(np.abs(np.roots(self.speed_char)) < 1.0 - 1e-9))

    def stable(self) -> bool:
        """True when the closed speed and position loops are stable (the closed position loop's
        poles from its state-space model)."""
        return self.speed_stable() and bool(np.all(np.abs(np.linalg.eigvals(self.a)) < 1.0 - 1e-9))

    def impulse(self, samples: int) -> np.ndarray:
        """Position, current and gear torque (samples x 3) after a speed of 1 rad/s added to the
        speed command for one period (an excitation's building block)."""
        u = np.zeros(samples)
        u[0] = 1.0
        return simulate_blocks(self.a, self.b, self.c, self.d, u)

    def unit_move(self, command_rad: np.ndarray) -> np.ndarray:
        """Position, current and gear torque (samples x 3) for the speed command c - Kp x (no Kp before c):
        ``move`` weighs it for any Kp and feed-forward of the same loop."""
        c = np.asarray(command_rad, float) - float(command_rad[0])
        return simulate_blocks(self.a, self.b, self.c, self.d, c)

    def move(self, command_rad: np.ndarray, unit: np.ndarray | None = None,
             ff: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Position (rad, at the start of each period) and current (A) for a position command
        sampled at the servo rate, from rest at its first value (``unit``: ``unit_move``'s result
        for the same command; ``ff``: another feed-forward gain than the loop's, 0 ... 1).
        The speed command is (Kp + FF/dt) c[k] - (FF/dt) c[k-1] - Kp x: linear in the command, so
        the response is Kp u + (FF/dt) (u - u delayed one period) of the response u to c."""
        y = self.unit_move(command_rad) if unit is None else unit
        gain = self.ff if ff is None else ff
        delayed = np.vstack([np.zeros((1, y.shape[1])), y[:-1]])
        out = self.kp * y + (gain / self.dt) * (y - delayed)
        return out[:, 0] + float(command_rad[0]), out[:, 1]


def simulate_blocks(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray, u: np.ndarray,
                    block: int = 16) -> np.ndarray:
    """Outputs (samples x outputs) of x[k+1] = a x[k] + b u[k], y[k] = c x[k] + d u[k] from
    x[0] = 0 (one input): the state is carried from block to block (a^L), the outputs inside a
    block come from the block's first state and the impulse response (a Toeplitz matrix), so
    that numpy does the work and the state-space form keeps its accuracy (a transfer function's
    coefficients lose it with poles close to 1)."""
    n, q, steps = a.shape[0], c.shape[0], len(u)
    blocks = -(-steps // block)
    padded = np.zeros(blocks * block)
    padded[:steps] = u
    ub = padded.reshape(blocks, block)
    observe = np.empty((block, q, n))  # c a^i
    reach = np.empty((n, block))  # a^(L-1-j) b
    m = c.copy()
    for i in range(block):
        observe[i] = m
        m = m @ a
    power = np.eye(n)
    for j in range(block - 1, -1, -1):
        reach[:, j] = (power @ b).ravel()
        power = power @ a
    markov = np.empty((block, q))  # y's response at lag i to u at lag 0
    markov[0] = d.ravel()
    for i in range(1, block):
        markov[i] = (observe[i - 1] @ b).ravel()
    lags = np.subtract.outer(np.arange(block), np.arange(block))
    toeplitz = np.where((lags >= 0)[..., None], markov[np.clip(lags, 0, None)], 0.0)  # (L, L, q)
    # einsum rather than matmul: these products are small, and a multi-threaded BLAS on a busy
    # machine makes them ten times slower
    pushed = np.einsum("nj,kj->kn", reach, ub)  # what each block's inputs add to its end state
    # the state at each block's start, x[k] = sum over j < k of power^(k-1-j) pushed[j], by a scan
    # that doubles its reach at each step (log2(blocks) steps instead of a loop over the blocks)
    states = np.zeros((blocks, n))
    states[1:] = pushed[:-1]
    reach_power, shift = power, 1
    while shift < blocks:
        states[shift:] = states[shift:] + np.einsum("mn,kn->km", reach_power, states[:-shift])
        reach_power = reach_power @ reach_power
        shift *= 2
    y = np.einsum("kn,iqn->kiq", states, observe) + np.einsum("kj,ijq->kiq", ub, toeplitz)
    return np.asarray(y.reshape(blocks * block, q)[:steps])


def kernel_gains(model: AxisModel, settings: ServoSettings) -> dict[str, float]:
    """Kv (A s/rad), Tv (s), Kp (1/s) and FF as the loop uses them (from the physics)."""
    p = kernel_params(model, settings)
    return {"kv": p.kv, "tv_s": (1.0 / p.tv_inv) if p.tv_inv else math.inf, "kp": p.kp, "ff": p.ff}
