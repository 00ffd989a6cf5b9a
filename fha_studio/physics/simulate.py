"""`simulate()`: a whole recorded command through the closed-loop axis, and the monitors' imperfections.

Used by the model check to re-simulate a recording and by tests/the sim to produce recordings
with known hidden effects.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fha_studio.physics import _kernel
from fha_studio.physics.model import AxisModel
from fha_studio.physics.servo import ServoSettings, kernel_params

# Keys of simulate()'s result and their units (SI, output side, physical frame: + = CW).
SIMULATION_UNITS: dict[str, str] = {
    "t": "s",
    "cmd_pos": "rad",  # the command as the servo saw it
    "pos": "rad",  # motor-side angle at the output (what the motor encoder reports)
    "load_pos": "rad",  # output flange / load angle (an external encoder would see this)
    "vel": "rad/s",  # motor-side speed at the output
    "current": "A",  # motor current; torque = Kt x current
    "torque": "N m",  # Kt x current
    "speed_cmd": "rad/s",  # speed-loop reference (command frame)
    # what a torque sensor on the output flange reads: the torque the flange exerts on the load,
    # + = driving it CW (a recording's ``torque`` column); ServoAxis.flange_torque_nm says how
    "flange_torque": "N m",
}


# Servo periods simulated per chunk: the per-period records are kept for one chunk only.
SIMULATION_CHUNK = 50_000


@dataclass(frozen=True)
class MonitorOptions:
    """What a real drive's monitors do to the signals (applied to simulate()'s output).

    quantise_position: pos to the encoder's output pulses (model.output_resolution_ppr).
    load_encoder_ppr: pulses per turn of an external load encoder (None = not quantised).
    current_resolution_a: step of the current monitor (0 = none); current_noise_a: its noise (std, A).
    speed_noise_rad_s: noise (std) on vel. seed: of the noise generator.
    flange_torque_noise_nm: noise (std, N m) of the output torque sensor on flange_torque.
    """

    quantise_position: bool = True
    load_encoder_ppr: int | None = None
    current_resolution_a: float = 0.0
    current_noise_a: float = 0.0
    speed_noise_rad_s: float = 0.0
    seed: int | None = 0
    flange_torque_noise_nm: float = 0.0

    @classmethod
    def typical(cls, model: AxisModel, seed: int | None = 0) -> MonitorOptions:
        """An assumption of a real drive's monitors: 10-bit current monitor over +-Imax with one
        step of noise, position in encoder pulses, load encoder at the same resolution."""
        step = 2.0 * model.max_current_a / 1024.0 if math.isfinite(model.max_current_a) else 0.0
        return cls(True, model.output_resolution_ppr, step, step, 0.0, seed)


def apply_monitor(result: dict[str, np.ndarray], model: AxisModel,
                  monitor: MonitorOptions) -> dict[str, np.ndarray]:
    """A copy of a simulate() result as the monitors would report it (quantised, noisy)."""
    out = dict(result)
    rng = np.random.default_rng(monitor.seed)
    if monitor.quantise_position:
        q = model.output_pulse_rad
        out["pos"] = np.floor(result["pos"] / q + 0.5) * q
    if monitor.load_encoder_ppr:
        q = 2.0 * math.pi / monitor.load_encoder_ppr
        out["load_pos"] = np.floor(result["load_pos"] / q + 0.5) * q
    cur = result["current"]
    if monitor.current_noise_a > 0:
        cur = cur + rng.normal(0.0, monitor.current_noise_a, cur.shape)
    if monitor.current_resolution_a > 0:
        cur = np.floor(cur / monitor.current_resolution_a + 0.5) * monitor.current_resolution_a
    out["current"] = cur
    out["torque"] = cur * model.torque_constant_nm_per_a
    if monitor.speed_noise_rad_s > 0:
        out["vel"] = result["vel"] + rng.normal(0.0, monitor.speed_noise_rad_s, result["vel"].shape)
    if monitor.flange_torque_noise_nm > 0 and "flange_torque" in result:  # drawn last: the others stay
        flange = result["flange_torque"]
        out["flange_torque"] = flange + rng.normal(0.0, monitor.flange_torque_noise_nm, flange.shape)
    return out


def simulate(model: AxisModel, servo: ServoSettings | None, t_s: np.ndarray, command_pos_rad: np.ndarray, *,
             monitor: MonitorOptions | None = None, start_at_rest: bool = True,
             current_average: bool = False) -> dict[str, np.ndarray]:
    """Run the closed loop through a recorded command and sample it at the recording's times.

    t_s: increasing sample times (s); command_pos_rad: the position command at those times (rad,
    output side, physical frame). The servo (servo=None: ServoSettings.tuned_for(model)) runs at
    its rate on the command linearly interpolated between samples. The axis starts at the first
    command, at rest, holding its static load (gravity, offset) as a servo that has been on.
    Returns {key: array} with the keys and units of SIMULATION_UNITS, sampled at t_s (the servo
    period ending at or just after each sample time, interpolated). monitor: quantisation/noise.
    current_average: current, torque and flange_torque as their mean over each sample interval
    (t[k-1], t[k]] (a sampled monitor or sensor with an anti-alias filter) instead of the
    instantaneous value; the first sample stays instantaneous.
    """
    t = np.asarray(t_s, dtype=float)
    cmd = np.asarray(command_pos_rad, dtype=float)
    if t.ndim != 1 or cmd.shape != t.shape:
        raise ValueError(f"simulate: t_s and command_pos_rad must be 1-D and equally long, got {t.shape} and "
                         f"{cmd.shape}")
    if t.size < 2:
        raise ValueError("simulate: need at least two samples")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(cmd))):
        bad = int(np.flatnonzero(~(np.isfinite(t) & np.isfinite(cmd)))[0])
        raise ValueError(f"simulate: non-finite time or command at sample {bad}")
    if np.any(np.diff(t) <= 0):
        bad = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
        raise ValueError(f"simulate: time must increase, it does not at sample {bad}")
    settings = servo if servo is not None else ServoSettings.tuned_for(model)
    p = kernel_params(model, settings)
    dt = p.dt
    n = math.ceil((t[-1] - t[0]) / dt - 1e-9) + 1
    d = p.direction

    state = _kernel.KernelState(step_index=0)
    _initialise_at_rest(state, p, float(cmd[0]), start_at_rest)
    keys = ("cmd_pos", "pos", "load_pos", "vel", "current", "speed_cmd", "flange_torque")
    out: dict[str, np.ndarray] = {"t": t.copy()}
    for key in keys:
        out[key] = np.empty(len(t))
    # integrals over time of the current and the flange torque at each sample (current_average)
    charge_at = np.empty(len(t))
    impulse_at = np.empty(len(t))
    # the servo periods run in chunks: memory stays bounded by the chunk, whatever the duration
    last_t = 0.0
    last = [d * state.cprev, state.xm, state.xl, state.vm, state.current, state.vref, state.flange_torque]
    last_charge = last_impulse = 0.0
    done = 0  # samples filled
    for k0 in range(0, n, SIMULATION_CHUNK):
        m = min(SIMULATION_CHUNK, n - k0)
        t_servo = dt * np.arange(k0 + 1, k0 + m + 1)  # relative to t[0]
        cmd_servo = (d * np.interp(t[0] + t_servo, t, cmd)).tolist()
        ts = np.concatenate(([last_t], t_servo))
        stop = int(np.searchsorted(t, t[0] + ts[-1], side="right")) if k0 + m < n else len(t)
        rel = t[done:stop] - t[0]
        if current_average:  # the charge needs every period's current
            keep, record_at = np.arange(m + 1), None
        else:
            # np.interp reads only the two periods a sample falls between, and only the one it
            # falls on exactly (as a sample at whole milliseconds does, the servo at 5 kHz): record
            # those (and the chunk's last, where the next chunk starts); the samples come out bit
            # for bit the same, at half the periods recorded on such a grid
            j = np.clip(np.searchsorted(ts, rel, side="right") - 1, 0, m)
            after = np.clip(j + 1, 0, m)
            # the periods to keep, in order and once each (a mask: np.unique would sort them again)
            marked = np.zeros(m + 1, dtype=bool)
            marked[[0, m]] = True
            marked[j] = True
            marked[after[ts[j] != rel]] = True
            keep = np.flatnonzero(marked)
            record_at = (keep[1:] - 1).tolist()
        rec: tuple[list, ...] = ([], [], [], [], [], [], [], [])
        _kernel.run(p, state, cmd_servo, m, True, rec, 1, record_at=record_at, accounting=False)
        ts = ts[keep]
        # the lists to arrays through fromiter with their dtype and length stated: numpy then skips
        # its type discovery per item (a quarter less than np.array(list, dtype=float))
        recorded = [np.fromiter(r, dtype=float, count=len(r)) for r in rec[1:]]
        for j_key, key in enumerate(keys):
            out[key][done:stop] = np.interp(rel, ts, np.concatenate(([last[j_key]], recorded[j_key])))
        if current_average:
            charge = last_charge + np.concatenate(([0.0], np.cumsum(recorded[4]) * dt))
            charge_at[done:stop] = np.interp(rel, ts, charge)
            last_charge = float(charge[-1])
            impulse = last_impulse + np.concatenate(([0.0], np.cumsum(recorded[6]) * dt))
            impulse_at[done:stop] = np.interp(rel, ts, impulse)
            last_impulse = float(impulse[-1])
        done = stop
        last_t = float(ts[-1])
        last = [float(rec[j_key + 1][-1]) for j_key in range(len(keys))]
    if current_average:
        # the current recorded at the end of a servo period was applied during all of it
        out["current"][1:] = np.diff(charge_at) / np.diff(t)
        out["flange_torque"][1:] = np.diff(impulse_at) / np.diff(t)
    out["torque"] = out["current"] * model.torque_constant_nm_per_a
    if monitor is not None:
        out = apply_monitor(out, model, monitor)
    return out


def _static_load_nm(p: _kernel.KernelParams, x: float) -> float:
    return p.offset + (p.grav_a * math.sin(x + p.grav_phase) if p.grav_a else 0.0)


def _hold_current(p: _kernel.KernelParams, x: float) -> float:
    return max(-p.ilim, min(p.ilim, _static_load_nm(p, x) / p.kt))


def _rest_load(p: _kernel.KernelParams, xm: float) -> float:
    ke = p.ke_a * math.sin(p.ke_w * xm + p.ke_phase) if p.ke_a else 0.0
    return xm + ke


def _initialise_at_rest(s: _kernel.KernelState, p: _kernel.KernelParams, x0: float, hold_load: bool) -> None:
    """Axis at rest at x0 (physical), servo on, integrator and gear wind-up holding the static load."""
    s.xm = x0
    s.cprev = p.direction * x0
    s.xl = _rest_load(p, x0)
    if not hold_load:
        # no current and no wind-up: a compliant flange passes nothing yet; a rigid axis starts to
        # fall under its load, the sensed load's share of that acceleration taken off its torque
        s.flange_torque = 0.0 if p.compliant else _static_load_nm(p, x0) * (1.0 - p.j_sensed / p.j_total)
        return
    s.flange_torque = _static_load_nm(p, x0)  # the flange holds the static load
    i_hold = _hold_current(p, x0)
    s.current = i_hold
    # integ holds the current in the command frame: ic = kv * integ at zero error
    s.integ = p.direction * i_hold / p.kv if p.kv else 0.0
    if p.compliant:
        torque = _static_load_nm(p, x0)
        # the gear carries the static load: twist from the (odd) wind-up curve, plus the dead band
        a = abs(torque)
        if a <= p.t1:
            tw = a / p.k1
        elif a <= p.t2:
            tw = p.th1 + (a - p.t1) / p.k2
        else:
            tw = p.th2 + (a - p.t2) / p.k3
        if a > 0:
            tw += p.lm_half
        s.xl -= math.copysign(tw, torque)
