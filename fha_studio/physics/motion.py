"""Command position generators: jog (ramp to a speed and hold it) and move-by-angle (trapezoid).

A profile is a list of constant-acceleration segments on the generator's own clock (s); the
servo samples it at its rate. Angles in rad, speeds in rad/s, accelerations in rad/s^2, in the
frame of the command (positive = forward).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Segment:
    """Constant acceleration from t0_s for duration_s (inf = open-ended)."""

    t0_s: float
    duration_s: float
    pos0_rad: float
    speed0_rad_s: float
    accel_rad_s2: float

    def end_state(self) -> tuple[float, float]:
        """(position, speed) at the end of a finite segment."""
        t = self.duration_s
        return (self.pos0_rad + self.speed0_rad_s * t + 0.5 * self.accel_rad_s2 * t * t,
                self.speed0_rad_s + self.accel_rad_s2 * t)


def _check_positive(name: str, value: float) -> float:
    if not (isinstance(value, int | float) and value > 0 and not math.isnan(value)):
        raise ValueError(f"motion: {name} must be positive, got {value!r}")
    return float(value)


class MotionGenerator:
    """Piecewise constant-acceleration command profile (jog, stop, trapezoidal move, hold)."""

    def __init__(self, pos_rad: float = 0.0) -> None:
        self._segments: list[Segment] = []
        self.hold(0.0, pos_rad)

    # ----- planning ---------------------------------------------------------------------------
    def hold(self, t_s: float, pos_rad: float) -> None:
        """Stand still at pos_rad from t_s on (e.g. follow the feedback while the servo is off)."""
        self._segments = [Segment(t_s, math.inf, float(pos_rad), 0.0, 0.0)]
        self._target_rad = float(pos_rad)

    def jog(self, t_s: float, speed_rad_s: float, accel_rad_s2: float) -> None:
        """From the state at t_s, ramp at accel_rad_s2 (inf = at once) to speed_rad_s and keep it."""
        accel = _check_positive("accel_rad_s2", accel_rad_s2)
        p, v = self.state_at(t_s)
        dv = float(speed_rad_s) - v
        segs = []
        t = t_s
        if dv != 0.0 and math.isfinite(accel):
            dur = abs(dv) / accel
            seg = Segment(t, dur, p, v, math.copysign(accel, dv))
            segs.append(seg)
            p, _ = seg.end_state()
            t += dur
        segs.append(Segment(t, math.inf, p, float(speed_rad_s), 0.0))
        self._segments = segs
        self._target_rad = math.nan if speed_rad_s != 0.0 else p

    def stop(self, t_s: float, decel_rad_s2: float) -> None:
        """Ramp down to standstill at decel_rad_s2 from the state at t_s, then hold."""
        self.jog(t_s, 0.0, decel_rad_s2)
        last = self._segments[-1]
        self._target_rad = last.pos0_rad

    def move_by(self, t_s: float, angle_rad: float, speed_rad_s: float, accel_rad_s2: float) -> None:
        """Trapezoidal (or triangular) move by angle_rad from standstill at t_s, then hold.

        Raises ValueError when the command is still moving (stop first).
        """
        speed = _check_positive("speed_rad_s", speed_rad_s)
        accel = _check_positive("accel_rad_s2", accel_rad_s2)
        p, v = self.state_at(t_s)
        if v != 0.0:
            raise ValueError("motion: a move needs the command at standstill; stop the jog first")
        d = abs(float(angle_rad))
        sign = 1.0 if angle_rad >= 0 else -1.0
        segs: list[Segment] = []
        t = t_s
        if d > 0:
            if math.isinf(accel):
                t_acc, v_peak = 0.0, speed
            elif d < speed * speed / accel:  # never reaches speed: triangle
                v_peak = math.sqrt(d * accel)
                t_acc = v_peak / accel
            else:
                v_peak, t_acc = speed, speed / accel
            d_acc = 0.5 * v_peak * t_acc
            t_cruise = (d - 2.0 * d_acc) / v_peak
            a = sign * accel if t_acc > 0 else 0.0
            for dur, acc, v0 in ((t_acc, a, 0.0), (t_cruise, 0.0, sign * v_peak), (t_acc, -a, sign * v_peak)):
                if dur > 0:
                    seg = Segment(t, dur, p, v0, acc)
                    segs.append(seg)
                    p, _ = seg.end_state()
                    t += dur
        target = float(self.state_at(t_s)[0] + angle_rad)
        segs.append(Segment(t, math.inf, target, 0.0, 0.0))
        self._segments = segs
        self._target_rad = target

    def shift(self, delta_rad: float) -> None:
        """Move the whole profile by delta_rad (a pulse-train step input)."""
        self._segments = [
            Segment(s.t0_s, s.duration_s, s.pos0_rad + delta_rad, s.speed0_rad_s, s.accel_rad_s2)
            for s in self._segments
        ]
        if not math.isnan(self._target_rad):
            self._target_rad += delta_rad

    # ----- sampling ---------------------------------------------------------------------------
    @property
    def target_rad(self) -> float:
        """Where the profile comes to rest (nan while jogging)."""
        return self._target_rad

    def end_time_s(self) -> float:
        """When the profile reaches its final constant state (start of the open-ended segment)."""
        return self._segments[-1].t0_s

    def _segment_at(self, t_s: float) -> Segment:
        seg = self._segments[0]
        for s in self._segments:
            if s.t0_s <= t_s:
                seg = s
            else:
                break
        return seg

    def state_at(self, t_s: float) -> tuple[float, float]:
        """(position rad, speed rad/s) of the command at t_s."""
        s = self._segment_at(t_s)
        tau = max(0.0, min(t_s - s.t0_s, s.duration_s))
        return (s.pos0_rad + s.speed0_rad_s * tau + 0.5 * s.accel_rad_s2 * tau * tau,
                s.speed0_rad_s + s.accel_rad_s2 * tau)

    def positions(self, t_s: np.ndarray) -> np.ndarray:
        """Command positions (rad) at the times t_s (vectorised)."""
        t = np.asarray(t_s, dtype=float)
        starts = np.array([s.t0_s for s in self._segments])
        idx = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(starts) - 1)
        p0 = np.array([s.pos0_rad for s in self._segments])[idx]
        v0 = np.array([s.speed0_rad_s for s in self._segments])[idx]
        a = np.array([s.accel_rad_s2 for s in self._segments])[idx]
        dur = np.array([s.duration_s for s in self._segments])[idx]
        tau = np.clip(t - starts[idx], 0.0, dur)
        return p0 + v0 * tau + 0.5 * a * tau * tau
