"""The simulated drive's commanded motion: a jog under the 100 ms communication watchdog, a move
at the SPD speed, a stop ramp, or none; and when a motion has ended (the output at rest, not only
the command). :class:`~fha_studio.hardware.sim.drive.SimDrive` checks the servo, the alarms and
the speed limit before it asks; speeds and angles here are rad/s and rad in the command sense."""

from __future__ import annotations

import math
from enum import StrEnum

from fha_studio.hardware.sim.constants import SimConstants
from fha_studio.hardware.sim.reply import rejected
from fha_studio.physics import AxisModel, ServoAxis

RPM = 2.0 * math.pi / 60.0  # rad/s per r/min


class MotionKind(StrEnum):
    IDLE = "idle"
    JOG = "jog"
    MOVE = "move"
    STOP = "stop"


class SimMotion:
    """What the axis is commanded to do (made anew at every power-on)."""

    def __init__(self, axis: ServoAxis, model: AxisModel, constants: SimConstants, move_speed_rad_s: float):
        self.axis = axis
        self.model = model
        self.constants = constants
        self.kind = MotionKind.IDLE
        self.still_since_s = 0.0  # since when the output turns slower than standstill_speed_rpm
        self.sign = 0.0  # direction of the commanded motion, command frame
        self.jog_speed_rad_s = 0.0
        self.jog_deadline_s = 0.0
        self.move_speed_rad_s = move_speed_rad_s

    @property
    def moving(self) -> bool:
        """A jog, a move or a stop ramp is in progress, or the command has arrived but the output
        still turns faster than ``standstill_speed_rpm`` (the servo lags the command; the bit
        clears when the output stands still, not when the command does)."""
        return self.kind is not MotionKind.IDLE

    def idle(self) -> None:
        self.kind = MotionKind.IDLE

    def jog(self, speed_rad_s: float, accel_rad_s2: float, now_s: float) -> None:
        """Jog at ``speed_rad_s`` until the watchdog's deadline; a repeat moves the deadline on."""
        if self.kind is MotionKind.MOVE:
            raise rejected("JOG: a move is running (STP first)")
        if self.kind is not MotionKind.JOG or speed_rad_s != self.jog_speed_rad_s:
            self.axis.jog(speed_rad_s, accel_rad_s2)
        self.jog_speed_rad_s = speed_rad_s
        self.kind = MotionKind.JOG
        if speed_rad_s:
            self.sign = 1.0 if speed_rad_s > 0 else -1.0
        self.jog_deadline_s = now_s + self.constants.jog_watchdog_s

    def move_by(self, angle_rad: float, accel_rad_s2: float, now_s: float) -> None:
        """Move by ``angle_rad`` at the SPD speed; refused (``x``) while the axis moves."""
        if self.moving:
            raise rejected("MOV: the axis is moving")
        if angle_rad == 0:
            return
        self.axis.move_by(angle_rad, self.move_speed_rad_s, accel_rad_s2)
        self.kind = MotionKind.MOVE
        self.still_since_s = now_s
        self.sign = 1.0 if angle_rad > 0 else -1.0

    def stop(self, accel_rad_s2: float, now_s: float) -> None:
        """Decelerate to standstill and hold."""
        self.axis.stop(accel_rad_s2)
        self.kind = MotionKind.STOP
        self.still_since_s = now_s

    def halt(self, now_s: float) -> None:
        """Stop the command at once (an inhibit input or a limit switch); "moving" until the
        output stands still."""
        if self.kind is MotionKind.STOP and self.axis.motion_done:
            return  # halted already: the output is coming to rest (checked every 1 ms)
        self.stop(math.inf, now_s)

    def watchdog_decel_rad_s2(self, speed_rad_s: float) -> float:
        """The deceleration the JOG watchdog stops the command with [rad/s^2]: the command
        reaches standstill within ``jog_watchdog_stop_s``, unless that asks for more than
        ``jog_watchdog_torque_share`` of the axis's torque-limited acceleration (TM / (JA + JL),
        manual 2-4-4): a heavy load is then braked at that share, slower but without the current
        limit making the axis overshoot (docs/sim.md states the resulting standstill time)."""
        c = self.constants
        wanted = abs(speed_rad_s) / c.jog_watchdog_stop_s
        followable = c.jog_watchdog_torque_share * self.model.max_acceleration_rad_s2()
        return max(min(wanted, followable), 1e-6)

    def supervise(self, now_s: float) -> None:
        """Every 1 ms: the watchdog (no JOG for 100 ms: the command ramps to standstill,
        docs/sim.md), and a move or stop ends when the output stands still, not only the command:
        below standstill_speed_rpm for standstill_s (a swing through zero speed is not standstill)."""
        if self.kind is MotionKind.JOG and now_s >= self.jog_deadline_s:
            self.stop(self.watchdog_decel_rad_s2(self.jog_speed_rad_s), now_s)
        elif self.kind in (MotionKind.MOVE, MotionKind.STOP) and self.axis.motion_done:
            if abs(self.axis.output_speed_rad_s) >= self.constants.standstill_speed_rpm * RPM:
                self.still_since_s = now_s
            elif now_s - self.still_since_s >= self.constants.standstill_s:
                self.kind = MotionKind.IDLE
