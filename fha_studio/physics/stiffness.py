"""The gear's torsional stiffness: the three-region wind-up curve of FHA-C manual section 1-9-2.

Output-referred: twist in rad between the motor side (motor angle / ratio) and the output
flange, torque in N m carried by the gear. The curve is symmetric (odd) in twist.

The manual gives the wind-up for a torque T as
    phi = T / K1                      for 0 <= T <= T1
    phi = theta1 + (T - T1) / K2      for T1 < T <= T2
    phi = theta2 + (T - T2) / K3      for T > T2
with theta1, theta2 rounded in the table. A spring in an integrator must be continuous, so the
twist breakpoints used here are derived, theta1 = T1/K1 and theta2 = theta1 + (T2 - T1)/K2;
they agree with the table's rounded theta1/theta2 to a few micro-radians (well under 1 arc-sec).
The hysteresis loop of the figure (0-A-B-A'-B') is not modelled; `lost_motion` is the separate
dead-band effect.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

ARCSEC_PER_RAD = 180.0 / math.pi * 3600.0
ARCMIN_PER_RAD = 180.0 / math.pi * 60.0


@dataclass(frozen=True)
class GearStiffness:
    """Piecewise-linear torque/twist curve of the gear (manual 1-9-2), output-referred, SI.

    t1_nm, t2_nm: torque breakpoints; k1/k2/k3_nm_per_rad: spring rates of the three regions.
    """

    t1_nm: float
    t2_nm: float
    k1_nm_per_rad: float
    k2_nm_per_rad: float
    k3_nm_per_rad: float

    def __post_init__(self) -> None:
        for name in ("t1_nm", "t2_nm", "k1_nm_per_rad", "k2_nm_per_rad", "k3_nm_per_rad"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise ValueError(f"gear stiffness: {name} must be a positive number, got {value!r}")
        if self.t2_nm < self.t1_nm:
            raise ValueError(f"gear stiffness: t2_nm ({self.t2_nm}) must not be below t1_nm ({self.t1_nm})")

    @classmethod
    def linear(cls, stiffness_nm_per_rad: float) -> GearStiffness:
        """A linear spring (one region), e.g. for a custom axis with only K1 known."""
        k = float(stiffness_nm_per_rad)
        return cls(t1_nm=1.0, t2_nm=1.0, k1_nm_per_rad=k, k2_nm_per_rad=k, k3_nm_per_rad=k)

    @classmethod
    def from_catalogue(cls, stiffness: object) -> GearStiffness:
        """From the catalogue's `stiffness` record (t1_nm, t2_nm, k1..k3_nm_per_rad)."""
        return cls(
            t1_nm=float(stiffness.t1_nm),  # type: ignore[attr-defined]
            t2_nm=float(stiffness.t2_nm),  # type: ignore[attr-defined]
            k1_nm_per_rad=float(stiffness.k1_nm_per_rad),  # type: ignore[attr-defined]
            k2_nm_per_rad=float(stiffness.k2_nm_per_rad),  # type: ignore[attr-defined]
            k3_nm_per_rad=float(stiffness.k3_nm_per_rad),  # type: ignore[attr-defined]
        )

    @property
    def theta1_rad(self) -> float:
        """Twist at T1 (derived, = T1/K1)."""
        return self.t1_nm / self.k1_nm_per_rad

    @property
    def theta2_rad(self) -> float:
        """Twist at T2 (derived, = theta1 + (T2 - T1)/K2)."""
        return self.theta1_rad + (self.t2_nm - self.t1_nm) / self.k2_nm_per_rad

    @property
    def max_stiffness_nm_per_rad(self) -> float:
        """The largest spring rate of the curve (sets the integrator's step)."""
        return max(self.k1_nm_per_rad, self.k2_nm_per_rad, self.k3_nm_per_rad)

    def scaled(self, factor: float) -> GearStiffness:
        """The same curve shape with every spring rate multiplied by factor (breakpoints in torque kept)."""
        return GearStiffness(
            self.t1_nm, self.t2_nm, self.k1_nm_per_rad * factor, self.k2_nm_per_rad * factor,
            self.k3_nm_per_rad * factor,
        )

    def wind_up_rad(self, torque_nm: float | np.ndarray) -> float | np.ndarray:
        """Twist in rad for a torque in N m (the manual's formulas; odd in torque)."""
        t = np.abs(np.asarray(torque_nm, dtype=float))
        phi = np.where(
            t <= self.t1_nm,
            t / self.k1_nm_per_rad,
            np.where(
                t <= self.t2_nm,
                self.theta1_rad + (t - self.t1_nm) / self.k2_nm_per_rad,
                self.theta2_rad + (t - self.t2_nm) / self.k3_nm_per_rad,
            ),
        )
        out = np.copysign(phi, torque_nm)
        return float(out) if out.ndim == 0 else out

    def torque_nm(self, twist_rad: float | np.ndarray) -> float | np.ndarray:
        """Torque in N m carried by the gear at a twist in rad (inverse of wind_up_rad)."""
        a = np.abs(np.asarray(twist_rad, dtype=float))
        th1, th2 = self.theta1_rad, self.theta2_rad
        t = np.where(
            a <= th1,
            self.k1_nm_per_rad * a,
            np.where(
                a <= th2,
                self.t1_nm + self.k2_nm_per_rad * (a - th1),
                self.t2_nm + self.k3_nm_per_rad * (a - th2),
            ),
        )
        out = np.copysign(t, twist_rad)
        return float(out) if out.ndim == 0 else out
