"""A move's overshoot and settling, measured through the drive-side trace (the verification of a
tuning: "settle a 90 deg move no slower than before, overshoot at most 10 %"), and the move itself.

The verification move (``verification_move``) is one profile, the same for the prediction of a
proposal and for the measurement: 90 deg at half the maximum speed, at an acceleration the axis
can follow, and no more than the drive's JOG acceleration, which the drive uses for MOV (a faster
profile than the motor's torque makes every tuning overshoot, which is the profile, not the loop):

- at most half the torque-limited TM / (J_A + J_L) of FHA-C manual 2-4-4 (the rigid axis);
- at most ``SWING_TORQUE_SHARE`` x TM / (J_motor + 3 J_load) for the gear's spring: where the
  profile's acceleration steps, the load swings on the spring beyond its share J_load x a, and
  where a triangular profile's acceleration reverses (+a to -a) the spring's torque reaches
  3 J_load x a, which the motor must hold with its own J_motor x a.

The trace records the feedback and command positions (monitor 100, 101) while the drive moves by
the angle (MOV at the SPD speed) and ``AFTER_MOVE_S`` after the command has arrived. Settling: from
when the command reaches its target until the position stays within the in-position range (tune
item 4, pulses); overshoot: the furthest the position goes past the target, in % of the move.

Waiting is on what the drive reports, never on the computer's clock: its trace's state and sample
count (``TST``) measure the drive's own time, and ``pace(seconds)`` is called between two looks
(a stepped simulated drive's ``advance``; nothing on a drive that runs by itself, whose link
paces the looks).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from fha_studio.hardware.parameters import MonitorItem
from fha_studio.hardware.protocol import TRACE_MAX_SAMPLES, IoBit, TraceState
from fha_studio.physics import AxisModel
from fha_studio.physics.motion import MotionGenerator

RPM = 2.0 * math.pi / 60.0
#: the verification move of a tuning
VERIFY_MOVE_DEG = 90.0
#: the verification move's acceleration: this share of the torque-limited one (rigid axis) ...
RIGID_TORQUE_SHARE = 0.5
#: ... and this share of the maximum torque where the load swings on the gear's spring
SWING_TORQUE_SHARE = 0.8
#: the trace covers the move and this long after the command has arrived
AFTER_MOVE_S = 0.8
#: between two looks at the drive
POLL_S = 0.01
#: the longest the axis may take to come to rest before the move (drive time)
STILL_WAIT_S = 10.0
#: a look at the drive that goes on this long (computer time) without the drive's trace
#: finishing means the drive's time stands still: it is never a measure of the move
STALLED_S = 120.0


class MoveAlarm(Exception):
    """The drive raised an alarm around the move (the loop could not follow it)."""

    def __init__(self, code: int) -> None:
        super().__init__(f"alarm {code} during the verification move")
        self.code = code


@dataclass(frozen=True)
class MoveFigures:
    overshoot_pct: float
    settling_ms: float | None  # None: not settled within the trace

    def to_dict(self) -> dict[str, float | None]:
        return {"overshoot_pct": round(self.overshoot_pct, 3),
                "settling_ms": None if self.settling_ms is None else round(self.settling_ms, 1)}


@dataclass(frozen=True)
class MoveProfile:
    """A move as the drive makes it: by ``angle_deg`` (output) at ``speed_rpm``, accelerating and
    decelerating at ``accel_rpm_s`` (the JOG acceleration item, r/min/s), trapezoidal."""

    angle_deg: float
    speed_rpm: float
    accel_rpm_s: float

    def _generator(self) -> MotionGenerator:
        g = MotionGenerator(0.0)
        g.move_by(0.0, math.radians(self.angle_deg), self.speed_rpm * RPM, self.accel_rpm_s * RPM)
        return g

    def duration_s(self) -> float:
        """From the start until the command arrives."""
        return self._generator().end_time_s()

    def command_rad(self, servo_rate_hz: float, after_s: float = AFTER_MOVE_S) -> np.ndarray:
        """The command (rad, from 0) at each servo period, until ``after_s`` after it arrived."""
        g = self._generator()
        t = np.arange(0.0, g.end_time_s() + after_s, 1.0 / servo_rate_hz)
        return g.positions(t)


def verification_move(model: AxisModel, jog_acceleration_rpm_s: float, minimum_rpm_s: float = 1.0,
                      angle_deg: float = VERIFY_MOVE_DEG) -> MoveProfile:
    """The move a tuning is verified with (see the module docstring): ``jog_acceleration_rpm_s``
    is the drive's JOG acceleration item, lowered for the move when the axis could not follow it
    (``minimum_rpm_s``: the item's smallest value)."""
    speed = 0.5 * (model.max_speed_rpm or 10.0)
    accel = RIGID_TORQUE_SHARE * model.max_acceleration_rad_s2()
    if model.stiffness is not None:
        torque = model.max_acceleration_rad_s2() * model.total_inertia_kgm2  # TM (2-4-4)
        swing = model.motor_side_inertia_kgm2 + 3.0 * model.load_side_inertia_kgm2
        accel = min(accel, SWING_TORQUE_SHARE * torque / swing)
    followable = max(minimum_rpm_s, math.floor(accel / RPM))
    return MoveProfile(angle_deg, speed, float(min(jog_acceleration_rpm_s, followable)))


def move_figures(t_s: np.ndarray, command: np.ndarray, position: np.ndarray, target: float,
                 window: float) -> MoveFigures:
    """Overshoot (% of the move) and settling (ms after the command's arrival) from samples."""
    start = float(position[0])
    span = target - start
    sign = 1.0 if span >= 0 else -1.0
    over = max(0.0, float(np.max(sign * (position - target))))
    arrived = np.nonzero(np.abs(command - target) <= 0.5)[0]
    if not len(arrived):
        return MoveFigures(100.0 * over / abs(span) if span else 0.0, None)
    k0 = int(arrived[0])
    outside = np.nonzero(np.abs(position[k0:] - target) > window)[0]
    if len(outside) and outside[-1] == len(position) - k0 - 1:
        settling = None
    else:
        k = k0 + (int(outside[-1]) + 1 if len(outside) else 0)
        settling = float(t_s[k] - t_s[k0]) * 1000.0
    return MoveFigures(100.0 * over / abs(span) if span else 0.0, settling)


def until_trace_done(client: Any, pace: Callable[[float], None], look: Callable[[], None] = lambda: None,
               now: Callable[[], float] | None = None) -> None:
    """Look at the drive (``look``, then its trace's state) until its capture is done; ``pace``
    between looks. ``now`` (the computer's clock) only notices a drive whose time stands still."""
    clock = now or time.monotonic
    started = clock()
    while True:
        look()
        if client.trace_status().state is TraceState.DONE:
            return
        if clock() - started > STALLED_S:
            raise TimeoutError(f"the drive's trace did not advance in {STALLED_S:g} s: is its time "
                               "standing still (a stepped simulated drive nobody advances)?")
        pace(POLL_S)


def wait_drive_time(client: Any, seconds: float, servo_rate_hz: float, pace: Callable[[float], None],
                    look: Callable[[], None] = lambda: None) -> None:
    """Let ``seconds`` of the drive's own time pass: a capture of that length (the trace's first
    channel as configured, at a divider that fits it) measures it. Reconfigure the trace after."""
    divider = max(1, math.ceil(seconds * servo_rate_hz / TRACE_MAX_SAMPLES))
    count = max(1, min(TRACE_MAX_SAMPLES, math.ceil(seconds * servo_rate_hz / divider)))
    client.configure_trace((MonitorItem.FEEDBACK_POSITION,), divider=divider)
    client.arm_trace(count)
    until_trace_done(client, pace, look)


def _wait_for_rest(client: Any, servo_rate_hz: float, pace: Callable[[float], None]) -> None:
    """Until the drive says the axis is not moving, at most ``STILL_WAIT_S`` of its time."""
    if not client.io_state().bit(IoBit.MOVING):
        return
    divider = max(1, math.ceil(STILL_WAIT_S * servo_rate_hz / TRACE_MAX_SAMPLES))
    client.configure_trace((MonitorItem.FEEDBACK_POSITION,), divider=divider)
    client.arm_trace(min(TRACE_MAX_SAMPLES, math.ceil(STILL_WAIT_S * servo_rate_hz / divider)))
    while client.io_state().bit(IoBit.MOVING):
        if client.trace_status().state is TraceState.DONE:
            raise TimeoutError(f"the axis did not come to rest within {STILL_WAIT_S:g} s")
        pace(POLL_S)


def measure_move(client: Any, profile: MoveProfile, servo_rate_hz: float, output_ppr: int,
                 in_position_pulses: int, pace: Callable[[float], None]) -> MoveFigures:
    """Move by ``profile`` (the drive's JOG acceleration must be ``profile.accel_rpm_s``) with the
    trace running; the figures of the move."""
    move_s = profile.duration_s() + AFTER_MOVE_S
    divider = max(1, math.ceil(move_s * servo_rate_hz / TRACE_MAX_SAMPLES))
    count = min(TRACE_MAX_SAMPLES, math.ceil(move_s * servo_rate_hz / divider))
    _wait_for_rest(client, servo_rate_hz, pace)  # the last motion is still coming to rest
    alarm = client.alarm()
    if alarm:
        raise MoveAlarm(alarm)
    channels = client.configure_trace((MonitorItem.FEEDBACK_POSITION, MonitorItem.COMMAND_POSITION),
                                      divider=divider)
    client.set_move_speed(profile.speed_rpm)
    client.arm_trace(count)
    client.move_by(profile.angle_deg)
    until_trace_done(client, pace)
    capture = client.read_trace()
    alarm = client.alarm()
    if alarm:  # e.g. 60, the position error overflowed: the loop could not follow
        raise MoveAlarm(alarm)
    pos = np.asarray(capture.column(channels[0]), float)
    cmd = np.asarray(capture.column(channels[1]), float)
    target = float(cmd[-1])  # where the command ends (the move's pulses, rounded by the drive)
    t = np.arange(len(pos)) * divider / servo_rate_hz
    return move_figures(t, cmd, pos, target, float(in_position_pulses))
