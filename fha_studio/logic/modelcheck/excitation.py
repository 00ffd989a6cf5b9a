"""What a recording's motion can show, and what it cannot for lack of excitation.

An effect can only be told from its look-alikes where the motion makes them differ: friction by
direction needs both directions, breakaway needs starts from rest, Coulomb against viscous friction
needs more than one speed. Where the recording lacks that motion, the check says so, with the
recording that would show it, and does not try the candidates that would only fit noise or a
look-alike there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fha_studio.logic.modelcheck.signals import Signals

#: the axis slid one way only when the other direction holds less than this share of the travel
ONE_WAY_TRAVEL_SHARE = 0.02
#: a standstill long enough to start from rest (the servo's integrator settles, friction sticks)
STANDSTILL_MIN_S = 0.2
#: the axis moved at one speed only when its typical moving speeds span less than this factor
SPEED_RANGE_MIN_FACTOR = 1.5
#: candidates that need both directions of motion to be seen at all
NEEDS_BOTH_DIRECTIONS = ("asymmetric_friction",)


@dataclass(frozen=True)
class Excitation:
    """The motion of a recording, as far as it decides what can be seen."""

    travel_cw_rad: float
    travel_ccw_rad: float
    longest_standstill_s: float
    speed_low_rad_s: float  # 25th percentile of |speed| while moving
    speed_high_rad_s: float  # 95th percentile of |speed| while moving

    @property
    def one_way(self) -> str:
        """"CW" or "CCW" when the axis slid that way only, else ""."""
        total = self.travel_cw_rad + self.travel_ccw_rad
        if total <= 0:
            return ""
        if self.travel_ccw_rad < ONE_WAY_TRAVEL_SHARE * total:
            return "CW"
        if self.travel_cw_rad < ONE_WAY_TRAVEL_SHARE * total:
            return "CCW"
        return ""

    @property
    def no_standstill(self) -> bool:
        return self.longest_standstill_s < STANDSTILL_MIN_S

    @property
    def one_speed(self) -> bool:
        return self.speed_high_rad_s < SPEED_RANGE_MIN_FACTOR * max(self.speed_low_rad_s, 1e-12)

    def excluded(self) -> frozenset[str]:
        """Candidates this motion cannot show (not tried)."""
        return frozenset(NEEDS_BOTH_DIRECTIONS) if self.one_way else frozenset()

    def lines(self, coast: bool = False) -> list[str]:
        """What cannot be seen for lack of excitation, each with the recording that would show it;
        ``coast``: a coast after an alarm slowed through the speeds and told the frictions apart."""
        out = []
        if self.one_way:
            out.append(
                f"Friction by direction cannot be seen: the axis slid one way only ({self.one_way}); "
                "friction and a constant load torque look the same then. Record moves in both "
                "directions: friction changes sign with the direction, a load torque does not."
            )
        if self.no_standstill:
            out.append(
                "Breakaway from rest cannot be seen: the axis never stood still for "
                f"{STANDSTILL_MIN_S:g} s. Record moves that start from a standstill with the servo on."
            )
        if self.one_speed and not coast:
            rpm = 0.5 * (self.speed_low_rad_s + self.speed_high_rad_s) * 30.0 / math.pi
            out.append(
                "Coulomb and viscous friction cannot be told apart: the axis moved at about one speed "
                f"({rpm:.3g} r/min). Record constant-speed runs at several speeds."
            )
        return out


def excitation_of(sig: Signals) -> Excitation:
    """The excitation of the analysis signals (speed from the analysis filter)."""
    v = sig.speed_rad_s
    dt = sig.filt.dt_s
    threshold = 3.0 * max(sig.pos_noise_rad, 1e-9) / (sig.filt.window * dt)
    cw = v > threshold
    ccw = v < -threshold
    still = ~(cw | ccw)
    moving = np.abs(v[~still])
    low, high = (np.percentile(moving, [25, 95]) if moving.size else (0.0, 0.0))
    return Excitation(
        travel_cw_rad=float(np.sum(v[cw]) * dt),
        travel_ccw_rad=float(-np.sum(v[ccw]) * dt),
        longest_standstill_s=_longest_run(still) * dt,
        speed_low_rad_s=float(low),
        speed_high_rad_s=float(high),
    )


def _longest_run(mask: np.ndarray) -> int:
    if not mask.any():
        return 0
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(np.int8), [0]])))
    return int(np.max(edges[1::2] - edges[::2]))
