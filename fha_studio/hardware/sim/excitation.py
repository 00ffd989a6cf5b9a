"""The simulated drive's excitation for a frequency response (EXA / EXL / EXG, docs/protocol.md).

A pseudo-random binary sequence (PRBS: a maximum-length shift register, period 2^bits - 1 bits,
the register as long as one period still fits a trace: ``protocol.excitation_register_bits``) of
+/- the amplitude, each bit held ``hold`` servo periods, is added to the
speed command at the speed loop's summing point while the position loop holds the axis. It runs
only while renewed: without an ``EXG`` for ``watchdog_s`` (the jog watchdog's 100 ms) it stops,
and it stops when the output has travelled more than the limit from where it started.
"""

from __future__ import annotations

from dataclasses import dataclass

from fha_studio.hardware.protocol import excitation_register_bits

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
    start_rad: float = 0.0
    _state: int = 1
    _phase: int = 0
    _bit: int = 0

    @property
    def active(self) -> bool:
        return self.hold_periods > 0

    def start(self, hold_periods: int, now_s: float, deadline_s: float, position_rad: float) -> None:
        """Start (or renew: the sequence goes on) with each bit held ``hold_periods`` periods."""
        if not self.active or hold_periods != self.hold_periods:
            self._state, self._phase = 1, 0
            self._bit = 0
            self.start_rad = position_rad
        self.hold_periods = hold_periods
        self.deadline_s = deadline_s

    def stop(self) -> None:
        self.hold_periods = 0

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
