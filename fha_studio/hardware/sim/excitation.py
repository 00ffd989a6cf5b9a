"""The simulated drive's excitation for a frequency response (EXA / EXL / EXG, docs/protocol.md).

A pseudo-random binary sequence (PRBS: a maximum-length shift register, period 2^bits - 1 bits,
the register as long as one period still fits a trace: ``protocol.excitation_register_bits``) of
+/- the amplitude, each bit held ``hold`` servo periods, is added to the
speed command at the speed loop's summing point while the position loop holds the axis, or on
top of a JOG (a bias speed: the axis then turns one way throughout, never sticking on its
friction at a reversal). It runs only while renewed: without an ``EXG`` for ``watchdog_s`` (the
jog watchdog's 100 ms) it stops, and it stops when the output has travelled more than the limit
from where it started; on a jog, from where the jog's command takes it (the output's distance to
the position command, against that distance when the excitation started).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from fha_studio.hardware.protocol import EXCITATION_STEP_RPM, excitation_register_bits
from fha_studio.hardware.sim.motion import MotionKind
from fha_studio.hardware.sim.reply import rejected

RPM = 2.0 * math.pi / 60.0
#: EXA: the amplitude may be at most this share of the maximum speed
MAX_AMPLITUDE_SHARE = 0.1
#: EXG: longest bit, in servo periods
MAX_HOLD_PERIODS = 64

#: taps of maximum-length shift registers (Fibonacci, XOR of the tapped bits), by length
PRBS_TAPS = {4: (4, 3), 5: (5, 3), 6: (6, 5), 7: (7, 6), 8: (8, 6, 5, 4), 9: (9, 5), 10: (10, 7),
             11: (11, 9), 12: (12, 11, 10, 4)}


def prbs_bits(count: int, bits: int, state: int = 1) -> tuple[list[int], int]:
    """``count`` bits (0/1) of the maximum-length sequence of a ``bits``-bit register and the
    register's next state (period 2^bits - 1)."""
    out = []
    mask = (1 << bits) - 1
    taps = PRBS_TAPS[bits]
    for _ in range(count):
        bit = 0
        for tap in taps:
            bit ^= state >> (tap - 1)
        bit &= 1
        state = ((state << 1) | bit) & mask
        out.append(bit)
    return out, state


@dataclass
class SimExcitation:
    """State of the drive's excitation generator (speeds in rad/s, command frame)."""

    amplitude_rad_s: float = 0.0
    travel_limit_rad: float = 0.0
    hold_periods: int = 0  # 0: not running
    deadline_s: float = 0.0
    start_rad: float = 0.0  # the output's distance to the position command when it started
    _state: int = 1
    _phase: int = 0
    _bit: int = 0

    @property
    def active(self) -> bool:
        return self.hold_periods > 0

    def start(self, hold_periods: int, now_s: float, deadline_s: float, position_rad: float) -> None:
        """Start (or renew: the sequence goes on) with each bit held ``hold_periods`` periods;
        ``position_rad``: the output's distance to the position command (physical frame)."""
        if not self.active or hold_periods != self.hold_periods:
            self._state, self._phase = 1, 0
            self._bit = 0
            self.start_rad = position_rad
        self.hold_periods = hold_periods
        self.deadline_s = deadline_s

    def stop(self) -> None:
        self.hold_periods = 0

    def supervise(self, now_s: float, may_run: bool, position_rad: float) -> None:
        """Every 1 ms: stop without a renewal (watchdog), with the servo off or an alarm, or past
        the travel limit from where it started (``position_rad``: the output's distance to the
        position command, as for ``start``)."""
        if self.active and (now_s >= self.deadline_s or not may_run
                            or abs(position_rad - self.start_rad) > self.travel_limit_rad):
            self.stop()

    def values(self, n: int) -> list[float]:
        """The next ``n`` periods' added speed command."""
        out = []
        hold, amp = self.hold_periods, self.amplitude_rad_s
        length = excitation_register_bits(hold)
        for _ in range(n):
            if self._phase == 0:
                bits, self._state = prbs_bits(1, length, self._state)
                self._bit = bits[0]
            self._phase = (self._phase + 1) % hold
            out.append(amp if self._bit else -amp)
        return out


# --- the CN3 commands (the drive's lock is held by the responder) ---------------------------------


def set_amplitude(drive: Any, value: int) -> None:
    """EXA: the amplitude in 0.0001 r/min (output), up to MAX_AMPLITUDE_SHARE of the maximum speed."""
    top = MAX_AMPLITUDE_SHARE * (drive.model.max_speed_rpm or 0.0)
    if not 0 < value * EXCITATION_STEP_RPM <= top + 1e-9:
        raise rejected(f"EXA {value * EXCITATION_STEP_RPM:g} r/min outside 0 ... {top:g} r/min")
    drive.excitation.amplitude_rad_s = value * EXCITATION_STEP_RPM * RPM


def set_travel_limit(drive: Any, value: int) -> None:
    """EXL: the angle (0.01 deg, output) the excitation may travel from where it started."""
    if value <= 0:
        raise rejected(f"EXL {value * 0.01:g} deg: the travel limit must be positive")
    drive.excitation.travel_limit_rad = math.radians(value * 0.01)


def run(drive: Any, value: int) -> None:
    """EXG: run (or keep running: like JOG, for the jog watchdog's time) the excitation with bits of ``value``
    servo periods; 0 stops it. Refused with the servo off, an alarm, a motion other than a JOG
    (on a jog it adds to the jog's speed command), or without an amplitude and a travel limit."""
    exc: SimExcitation = drive.excitation
    if value == 0:
        exc.stop()
        return
    if drive.alarm:
        raise rejected(f"EXG: alarm {drive.supervisor.describe()} is active")
    if not drive.servo_on:
        raise rejected("EXG: the servo is off")
    if drive.moving and drive.motion.kind is not MotionKind.JOG:
        raise rejected("EXG: the axis is moving (STP first; on a JOG it may run)")
    if not 1 <= value <= MAX_HOLD_PERIODS:
        raise rejected(f"EXG {value}: bits of 1 ... {MAX_HOLD_PERIODS} servo periods")
    if exc.amplitude_rad_s <= 0 or exc.travel_limit_rad <= 0:
        raise rejected("EXG: set the amplitude (EXA) and the travel limit (EXL) first")
    deadline_s = drive.time_s + drive.constants.jog_watchdog_s
    exc.start(value, drive.time_s, deadline_s, excitation_offset_rad(drive))


def excitation_offset_rad(drive: Any) -> float:
    """The output's distance to the position command (physical frame, rad): what the excitation's
    travel limit is measured on (standing still, the command stands still too)."""
    return float(drive.axis.output_pos_rad - drive.axis.command_pos_rad)
