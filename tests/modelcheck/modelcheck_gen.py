"""Recordings with hidden effects, made with the shared physics (closed loop, monitors' quantisation/noise).

The test knows the truth (the effects it put in); the workflow sees only the recording.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fha_studio.physics import AxisModel, Effects, MonitorOptions, ServoSettings, apply_monitor, simulate
from fha_studio.recording import RecordingMetadata, make_recording

RPM = 2.0 * math.pi / 60.0


def trapezoid_moves(
    moves: list[tuple[float, float, float, float]], rate_hz: float, start_dwell_s: float = 0.2
):
    """Command (rad) of moves [(angle_deg, speed_rpm, accel_rad_s2, dwell_s)] sampled at rate_hz."""
    dt = 1.0 / rate_hz
    v_list = [np.zeros(int(start_dwell_s * rate_hz))]
    for angle_deg, speed_rpm, accel, dwell in moves:
        d = math.radians(abs(angle_deg))
        s = math.copysign(1.0, angle_deg)
        vmax = speed_rpm * RPM
        if d < vmax**2 / accel:
            vmax = math.sqrt(d * accel)
        t_acc = vmax / accel
        t_flat = d / vmax - t_acc
        t_total = 2 * t_acc + t_flat
        t = np.arange(0.0, t_total, dt)
        v = np.minimum.reduce([accel * t, np.full_like(t, vmax), accel * (t_total - t)])
        v = np.maximum(v, 0.0) * s
        # scale so the move covers exactly the angle at this sampling
        if np.sum(v) != 0:
            v *= s * d / (np.sum(v) * dt)
        v_list.append(v)
        v_list.append(np.zeros(int(dwell * rate_hz)))
    v = np.concatenate(v_list)
    pos = np.concatenate([[0.0], np.cumsum(v[:-1]) * dt])
    return np.arange(len(pos)) * dt, pos


def sine_sweep(duration_s: float, rate_hz: float, amplitude_deg: float, periods_s: tuple[float, ...]):
    """Sum of sinusoids (a rich excitation) starting at rest."""
    t = np.arange(0.0, duration_s, 1.0 / rate_hz)
    pos = np.zeros_like(t)
    for p in periods_s:
        pos += math.radians(amplitude_deg) * (1.0 - np.cos(2 * math.pi * t / p)) / len(periods_s)
    ramp = np.clip(t / 0.5, 0, 1)
    return t, pos * ramp


def standard_moves(scale: float = 1.0) -> list[tuple[float, float, float, float]]:
    """Back-and-forth moves at several speeds, accelerations and angles (both directions)."""
    return [
        (120 * scale, 30, 40, 0.25),
        (-60 * scale, 10, 20, 0.25),
        (200 * scale, 60, 60, 0.25),
        (-150 * scale, 45, 30, 0.25),
        (90 * scale, 20, 80, 0.25),
        (-200 * scale, 70, 50, 0.25),
        (60 * scale, 5, 15, 0.25),
        (-40 * scale, 15, 60, 0.3),
    ]


@dataclass
class Generated:
    recording: object
    truth: Effects
    model: AxisModel


def record(
    model: AxisModel,
    effects: Effects,
    t: np.ndarray,
    cmd: np.ndarray,
    *,
    actuator_code: str,
    noise_steps: float = 1.0,
    seed: int = 0,
    with_load_pos: bool = False,
    declared_load: float | None = None,
    servo: ServoSettings | None = None,
    metadata_overrides: dict | None = None,
    torque_sensor_noise_nm: float | None = None,
) -> Generated:
    """Simulate the closed loop with the hidden effects and write what a drive would record.

    torque_sensor_noise_nm: with a number, the recording has the ``torque`` column of a torque
    sensor on the output flange (the simulation's flange_torque, averaged over each interval as the
    current is, with this noise std in N m)."""
    truth_model = model.with_effects(effects)
    step = 2.0 * model.max_current_a / 1024.0
    monitor = MonitorOptions(
        True, model.output_resolution_ppr if with_load_pos else None, step, noise_steps * step, 0.0, seed,
        torque_sensor_noise_nm or 0.0,
    )
    # the loops see whole encoder pulses, so the current carries a real drive's quantisation noise
    settings = servo or ServoSettings.tuned_for(
        model, speed_bandwidth_hz=30.0, feed_forward_gain=0.8, quantised_feedback=True
    )
    # Simulate at the servo rate and let the current monitor average over each recording interval
    # (the anti-alias filter of a sampled monitor: an instantaneous sample of the servo's current,
    # which steps every servo period, would miss what the position integrates). Positions are
    # instantaneous encoder readings.
    sub = round(settings.servo_rate_hz * float(t[1] - t[0]))
    t_fine = t[0] + (t[1] - t[0]) / sub * np.arange((len(t) - 1) * sub + 1)
    fine = simulate(truth_model, settings, t_fine, np.interp(t_fine, t, cmd))
    out = {k: v[::sub] for k, v in fine.items()}
    cur = fine["current"]
    out["current"] = np.concatenate([[cur[0]], cur[1:].reshape(-1, sub).mean(axis=1)])
    flange = fine["flange_torque"]  # a strain-gauge amplifier's anti-alias filter, as the current's
    out["flange_torque"] = np.concatenate([[flange[0]], flange[1:].reshape(-1, sub).mean(axis=1)])
    out = apply_monitor(out, truth_model, monitor)
    meta = dict(
        actuator=actuator_code,
        load_inertia_kgm2=model.load_inertia_kgm2 if declared_load is None else declared_load,
        sample_rate_hz=1.0 / float(t[1] - t[0]),
    )
    if actuator_code == "custom":
        meta.update(
            torque_constant_nm_per_a=model.torque_constant_nm_per_a,
            actuator_inertia_kgm2=model.actuator_inertia_kgm2,
            motor_turns_per_output_rev=model.ratio,
        )
    meta.update(metadata_overrides or {})
    channels = dict(t=out["t"], pos=np.degrees(out["pos"]), current=out["current"], cmd_pos=np.degrees(cmd))
    if with_load_pos:
        channels["load_pos"] = np.degrees(out["load_pos"])
    if torque_sensor_noise_nm is not None:
        channels["torque"] = out["flange_torque"]
    rec = make_recording(RecordingMetadata(**meta), **channels)
    return Generated(rec, effects, truth_model)


def moves_for(
    model: AxisModel, scale_deg: float = 1.0, n_moves: int = 8
) -> list[tuple[float, float, float, float]]:
    """Back-and-forth moves within the axis's speed and torque: several speeds, accelerations, angles."""
    v_max = model.max_speed_rpm or 30.0
    a_max = 0.5 * (model.max_torque_nm or model.peak_torque_nm) / model.total_inertia_kgm2
    pattern = [
        (120, 0.35, 0.5),
        (-60, 0.15, 0.3),
        (200, 0.7, 0.8),
        (-150, 0.5, 0.4),
        (90, 0.25, 1.0),
        (-200, 0.8, 0.6),
        (60, 0.08, 0.2),
        (-40, 0.2, 0.9),
    ]
    return [(angle * scale_deg, f_v * v_max, f_a * a_max, 0.25) for angle, f_v, f_a in pattern[:n_moves]]
