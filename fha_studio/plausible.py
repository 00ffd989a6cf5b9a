"""Plausible ranges of the physical quantities a person or a file gives FHA Studio (any layer).

A value outside its range is refused with the range and the reason, instead of being computed
with: a load inertia of 1e30 kg m^2 or a friction of 1e308 N m is a typing or unit mistake, and
computing with it gives answers that look like results (or overflows in the physics).
The ranges are wide on purpose: they bound what an FHA-C axis can be, not what is usual.
The FHA-C figures quoted in the reasons are the catalogue's (resources/catalog, FHA-C manual 1-4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


class OutOfRange(ValueError):
    """A value outside its plausible range; ``str()`` names the quantity, the range and why."""


@dataclass(frozen=True)
class Range:
    """``minimum <= value <= maximum`` (or ``<`` where ``open_minimum``), in ``unit``, because ``reason``."""

    name: str
    minimum: float
    maximum: float
    unit: str
    reason: str
    open_minimum: bool = False

    def allowed(self) -> str:
        """The range in words, e.g. "0 ... 1500 kg m^2"."""
        low = f"more than {self.minimum:g}" if self.open_minimum else f"{self.minimum:g}"
        unit = f" {self.unit}" if self.unit else ""
        if self.open_minimum:
            return f"{low} and at most {self.maximum:g}{unit}"
        return f"{low} ... {self.maximum:g}{unit}"

    def contains(self, value: float) -> bool:
        if not math.isfinite(value):
            return False
        low_ok = value > self.minimum if self.open_minimum else value >= self.minimum
        return low_ok and value <= self.maximum

    def check(self, value: float, where: str = "") -> float:
        """``value`` as float, or :class:`OutOfRange` naming ``where`` (default: the quantity)."""
        number = float(value)
        if not self.contains(number):
            raise OutOfRange(
                f"{where or self.name} is {number:g}; allowed {self.allowed()} ({self.reason})"
            )
        return number


# The largest allowable load inertia in the FHA-C catalogue is 150 kg m^2 (FHA-40C-160); ten times
# that is past anything an FHA-C can move (sizing still shows by how much a load is too large).
LOAD_INERTIA_KGM2 = Range(
    "load inertia", 0.0, 1500.0, "kg m^2",
    "ten times the largest allowable inertia of the FHA-C catalogue, 150 kg m^2",
)
# The largest FHA-C actuator inertia is about 51 kg m^2 (output-referred, FHA-40C-160 with brake).
ACTUATOR_INERTIA_KGM2 = Range(
    "actuator inertia", 0.0, 500.0, "kg m^2",
    "ten times the largest FHA-C actuator inertia, about 51 kg m^2", open_minimum=True,
)
# Output-referred torque constants of the FHA-C range are 11 ... 102 N m/A.
TORQUE_CONSTANT_NM_PER_A = Range(
    "torque constant", 0.0, 1000.0, "N m/A",
    "ten times the largest FHA-C torque constant, 102 N m/A", open_minimum=True,
)
MOTOR_TURNS_PER_OUTPUT_REV = Range(
    "motor turns per output turn", 1.0, 10000.0, "",
    "a reduction ratio: 1 for a direct drive, FHA-C gears are 50 ... 160",
)
# The simulated drive's supervision runs at 1 kHz and its trace at the 5 kHz servo rate; a
# recording faster than 1 MHz is not from an HA-655 and not of an axis.
SAMPLE_RATE_HZ = Range(
    "sample rate", 0.0, 1.0e6, "Hz", "no HA-655 signal is sampled faster", open_minimum=True,
)
# The largest FHA-C maximum torque is 820 N m (FHA-40C-160): a hidden effect ten times that
# would tear the axis apart, and the physics' numbers stay far from overflow.
EFFECT_TORQUE_NM = Range(
    "effect torque", -8200.0, 8200.0, "N m", "ten times the largest FHA-C maximum torque, 820 N m",
)
# viscous friction reaching 8200 N m at 0.1 rad/s
EFFECT_VISCOUS_NM_S_PER_RAD = Range(
    "viscous friction coefficient", 0.0, 82000.0, "N m s/rad",
    "ten times the largest FHA-C maximum torque already at 1 r/min",
)
EFFECT_INERTIA_KGM2 = Range(
    "inertia error", -1500.0, 1500.0, "kg m^2", "the plausible load inertia, either sign",
)
EFFECT_ANGLE_ARCSEC = Range(
    "angle error", -36000.0, 36000.0, "arcsec",
    "10 degrees; FHA-C transmission errors and lost motion are a few arcminutes",
)
EFFECT_CYCLES_PER_MOTOR_REV = Range(
    "cycles per motor turn", 0.0, 1000.0, "1/rev",
    "ripple or error shapes up to 1000 per motor turn; the encoder resolves no finer",
    open_minimum=True,
)
EFFECT_PHASE_DEG = Range("phase", -360.0, 360.0, "deg", "one turn either way")
EFFECT_STIFFNESS_NM_PER_RAD = Range(
    "stiffness", 0.0, 1.0e9, "N m/rad",
    "the stiffest FHA-C gear is about 1e6 N m/rad (catalogue K3)", open_minimum=True,
)
# OWW (clear multi-turn data) takes about 5 s on a real driver; the simulated drive lets a test
# make it shorter or longer, but not longer than an hour.
OWW_CLEAR_S = Range("OWW clearing time", 0.0, 3600.0, "s", "an hour is longer than anyone waits")
# The sensor dogs sit somewhere on one output turn, given either way round.
SENSOR_ANGLE_DEG = Range("sensor angle", -360.0, 360.0, "deg", "one output turn either way")
# TCP ports are 16-bit numbers; 0 asks the system for a free one.
TCP_PORT = Range("TCP port", 0, 65535, "", "TCP port numbers are 0 ... 65535 (0: any free port)")
SIM_RECORD_RATE_HZ = Range(
    "recording rate", 0.0, 1000.0, "Hz", "the simulated drive records from its 1 kHz supervision",
    open_minimum=True,
)

# Chapter 2 sizing inputs: wide bounds of what one FHA-C duty cycle can be.
SPEED_RPM = Range("speed", 0.0, 1000.0, "r/min", "ten times the highest FHA-C maximum speed, 96 r/min",
                  open_minimum=True)
MOVE_ANGLE_DEG = Range("move angle", 0.0, 360.0 * 1000, "deg", "a thousand output turns per move",
                       open_minimum=True)
CYCLE_TIME_S = Range("cycle time", 0.001, 24 * 3600.0, "s",
                     "a move takes longer than a millisecond, and comes at least once a day")
ACCEL_TIME_S = Range("acceleration time", 0.0, 3600.0, "s",
                     "an hour to reach the speed; a longer time is a unit mistake (ms for s)",
                     open_minimum=True)
LOAD_TORQUE_NM = Range("load torque", -8200.0, 8200.0, "N m",
                       "ten times the largest FHA-C maximum torque, 820 N m")
DUTY_FACTOR = Range("duty factor", 0.0, 100.0, "", "the manual's graphs (2-4-5) stay far below")
BEARING_LOAD_N = Range("bearing load", 0.0, 1.0e6, "N",
                       "far above the largest FHA-C allowable radial and axial loads")
LOAD_OFFSET_MM = Range("loading point", 0.0, 10000.0, "mm", "ten metres from the bearing")
LOAD_FACTOR = Range("load factor fw", 1.0, 10.0, "",
                    "the manual gives 1 ... 3 (smooth 1-1.2, normal 1.2-1.5, shock 1.5-3)")
REQUIRED_LIFE_H = Range("required life", 0.0, 1.0e6, "h", "more than a hundred years of running",
                        open_minimum=True)

#: Effect parameter name -> its range (names are the model check's contract, physics.effects).
EFFECT_PARAMETER_RANGES: dict[str, Range] = {
    "torque_nm": EFFECT_TORQUE_NM,
    "amplitude_nm": EFFECT_TORQUE_NM,
    "t1_nm": EFFECT_TORQUE_NM,
    "t2_nm": EFFECT_TORQUE_NM,
    "coefficient_nm_s_per_rad": EFFECT_VISCOUS_NM_S_PER_RAD,
    "inertia_kgm2": EFFECT_INERTIA_KGM2,
    "amplitude_arcsec": EFFECT_ANGLE_ARCSEC,
    "width_arcsec": EFFECT_ANGLE_ARCSEC,
    "cycles_per_motor_rev": EFFECT_CYCLES_PER_MOTOR_REV,
    "phase_deg": EFFECT_PHASE_DEG,
    "stiffness_nm_per_rad": EFFECT_STIFFNESS_NM_PER_RAD,
    "k2_nm_per_rad": EFFECT_STIFFNESS_NM_PER_RAD,
    "k3_nm_per_rad": EFFECT_STIFFNESS_NM_PER_RAD,
}

CURRENT_PROBE_A_PER_V = Range("current probe scale", 1e-6, 1000.0, "A/V",
                              "current probes and shunt amplifiers give 1 mA/V ... 1000 A/V")
LOAD_ENCODER_COUNTS = Range("load encoder counts per turn", 4.0, 2.0**32, "counts",
                            "a quadrature encoder counts at least 4 per turn; 32-bit absolute encoders "
                            "count 4294967296")
