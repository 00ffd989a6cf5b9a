"""A move's overshoot and settling, measured through the drive-side trace (the verification of a
tuning: "settle a 90 deg move no slower than before, overshoot at most 10 %").

The trace records the feedback and command positions (monitor 100, 101) while the drive moves by
the angle (MOV at the SPD speed). Settling: from when the command reaches its target until the
position stays within the in-position range (tune item, pulses); overshoot: the furthest the
position goes past the target, in % of the move.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from fha_studio.hardware.parameters import MonitorItem
from fha_studio.hardware.protocol import TRACE_MAX_SAMPLES, IoBit, TraceState

#: the trace covers the move and this long after it
AFTER_MOVE_S = 0.8
POLL_S = 0.05
STILL_WAIT_S = 10.0


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


def measure_move(client: Any, angle_deg: float, speed_rpm: float, servo_rate_hz: float,
                 output_ppr: int, in_position_pulses: int, wait: Callable[[float], None]) -> MoveFigures:
    """Move by ``angle_deg`` at ``speed_rpm`` with the trace running; the figures of the move."""
    move_s = abs(angle_deg) / (6.0 * speed_rpm) + AFTER_MOVE_S + 0.3
    divider = max(1, math.ceil(move_s * servo_rate_hz / TRACE_MAX_SAMPLES))
    count = min(TRACE_MAX_SAMPLES, math.ceil(move_s * servo_rate_hz / divider))
    channels = client.configure_trace((MonitorItem.FEEDBACK_POSITION, MonitorItem.COMMAND_POSITION),
                                      divider=divider)
    waited = 0.0
    while client.io_state().bit(IoBit.MOVING):  # the last motion is still coming to rest
        if waited > STILL_WAIT_S:
            raise TimeoutError(f"the axis did not come to rest within {STILL_WAIT_S:g} s")
        wait(POLL_S)
        waited += POLL_S
    alarm = client.alarm()
    if alarm:
        raise MoveAlarm(alarm)
    client.set_move_speed(speed_rpm)
    client.arm_trace(count)
    client.move_by(angle_deg)
    waited = 0.0
    while client.trace_status().state is not TraceState.DONE:
        wait(POLL_S)
        waited += POLL_S
        if waited > 10 * move_s:
            raise TimeoutError(f"the move's trace did not finish within {10 * move_s:.1f} s")
    capture = client.read_trace()
    alarm = client.alarm()
    if alarm:  # e.g. 60, the position error overflowed: the loop could not follow
        raise MoveAlarm(alarm)
    pos = np.asarray(capture.column(channels[0]), float)
    cmd = np.asarray(capture.column(channels[1]), float)
    target = float(cmd[-1])  # where the command ends (the move's pulses, rounded by the drive)
    t = np.arange(len(pos)) * divider / servo_rate_hz
    return move_figures(t, cmd, pos, target, float(in_position_pulses))
