"""The duty-cycle formulas of FHA-C manual section 2-4, as pure functions of SI numbers.

Speeds in r/min (the manual's unit, output side), times in s, torques in N m, inertia in
kg m^2. Where the printed formula is physically wrong the function says so and computes the
right quantity; the printed variant is kept where a test or a note needs it.
"""

from __future__ import annotations

import math

# The manual's g in 2-4-3 (T = 9.8 x mu x W x r).
GRAVITY_M_S2 = 9.8
_RPM_TO_RAD_S = 2 * math.pi / 60


# 2-4-1 ----------------------------------------------------------------------------------------
def speed_from_linear_rpm(linear_speed_mm_per_min: float, screw_pitch_mm: float) -> float:
    """Actuator speed in r/min for a screw feed: linear speed (mm/min) / pitch (mm) (2-4-1)."""
    if screw_pitch_mm <= 0:
        raise ValueError(f"screw_pitch_mm must be > 0, got {screw_pitch_mm!r}")
    return linear_speed_mm_per_min / screw_pitch_mm


# 2-4-3 ----------------------------------------------------------------------------------------
def rotary_friction_torque_nm(friction_coefficient: float, mass_kg: float, radius_m: float) -> float:
    """T = 9.8 μ W r: a mass W (kg) turning on a friction ring of radius r (m) (2-4-3)."""
    return GRAVITY_M_S2 * friction_coefficient * mass_kg * radius_m


def horizontal_screw_torque_nm(friction_coefficient: float, mass_kg: float, screw_pitch_m: float) -> float:
    """T = 9.8 μ W P / 2π: a mass W (kg) fed horizontally by a screw of pitch P (m) (2-4-3)."""
    return GRAVITY_M_S2 * friction_coefficient * mass_kg * screw_pitch_m / (2 * math.pi)


def vertical_screw_torque_nm(mass_kg: float, screw_pitch_m: float) -> float:
    """T = 9.8 W P / 2π: a mass W (kg) lifted by a screw of pitch P (m) (2-4-3)."""
    return GRAVITY_M_S2 * mass_kg * screw_pitch_m / (2 * math.pi)


# 2-4-4 ----------------------------------------------------------------------------------------
def friction_torque_nm(torque_constant_nm_per_a: float, max_current_a: float, max_torque_nm: float) -> float:
    """TF = KT x Im - TM: the actuator's friction torque at maximum speed (2-4-4)."""
    return torque_constant_nm_per_a * max_current_a - max_torque_nm


def accel_time_s(
    actuator_inertia_kgm2: float,
    load_inertia_kgm2: float,
    speed_rpm: float,
    max_torque_nm: float,
    load_torque_nm: float = 0.0,
) -> float:
    """ta = (JA + JL) 2π/60 N / (TM - TL) (2-4-4).

    TL is positive when it opposes the rotation. ``math.inf`` when TM <= TL (the actuator cannot
    accelerate the load).
    """
    net = max_torque_nm - load_torque_nm
    if net <= 0:
        return math.inf
    return (actuator_inertia_kgm2 + load_inertia_kgm2) * _RPM_TO_RAD_S * speed_rpm / net


def accel_torque_nm(
    actuator_inertia_kgm2: float,
    load_inertia_kgm2: float,
    speed_rpm: float,
    accel_time_s: float,
    load_torque_nm: float = 0.0,
) -> float:
    """Ta = (JA + JL) 2π/60 N / ta + TL: the torque that reaches N in ta (2-4-4 solved for the
    torque; TL positive when it opposes the rotation)."""
    inertia_kgm2 = actuator_inertia_kgm2 + load_inertia_kgm2
    return inertia_kgm2 * _RPM_TO_RAD_S * speed_rpm / accel_time_s + load_torque_nm


DECEL_LOAD_TORQUE_NOTE = (
    "the manual prints td = (JA + JL) 2π/60 N / (TM + 2 TF - TL); a load torque opposing the rotation "
    "(TL > 0) helps braking, so TM + 2 TF + TL is used (the same when TL = 0)"
)


def decel_time_s(
    actuator_inertia_kgm2: float,
    load_inertia_kgm2: float,
    speed_rpm: float,
    max_torque_nm: float,
    friction_torque_nm: float,
    load_torque_nm: float = 0.0,
) -> float:
    """td = (JA + JL) 2π/60 N / (TM + 2 TF + TL) (2-4-4, sign of TL corrected).

    Braking, the motor's full torque KT Im = TM + TF and the friction TF both slow the load, and a
    load torque opposing rotation (TL > 0) helps; see :data:`DECEL_LOAD_TORQUE_NOTE`.
    ``math.inf`` when the braking torque is not positive.
    """
    net = max_torque_nm + 2 * friction_torque_nm + load_torque_nm
    if net <= 0:
        return math.inf
    return (actuator_inertia_kgm2 + load_inertia_kgm2) * _RPM_TO_RAD_S * speed_rpm / net


# 2-4-5 ----------------------------------------------------------------------------------------
def run_time_s(angle_deg: float, speed_rpm: float, accel_time_s: float, decel_time_s: float) -> float:
    """tr = θ / (6 N) - (ta + td) / 2: time at constant speed for a trapezoidal move (2-4-5).

    Negative when the move is too short to reach N (the caller reports that as a failed check).
    """
    if speed_rpm <= 0:
        raise ValueError(f"speed_rpm must be > 0, got {speed_rpm!r}")
    return angle_deg / (6 * speed_rpm) - (accel_time_s + decel_time_s) / 2


def min_angle_to_reach_speed_deg(speed_rpm: float, accel_time_s: float, decel_time_s: float) -> float:
    """The shortest move (deg) that reaches N: the triangle θ = 6 N (ta + td) / 2."""
    return 6 * speed_rpm * (accel_time_s + decel_time_s) / 2


def percent_ed(
    kla: float,
    klr: float,
    kld: float,
    accel_time_s: float,
    run_time_s: float,
    decel_time_s: float,
    cycle_time_s: float,
) -> float:
    """%ED = (KLa ta + KLr tr + KLd td) / t x 100, duty factors from the manual's graphs (2-4-5)."""
    return (kla * accel_time_s + klr * run_time_s + kld * decel_time_s) / cycle_time_s * 100


# 2-4-6 ----------------------------------------------------------------------------------------
def effective_torque_nm(
    accel_torque_nm: float,
    load_torque_nm: float,
    accel_time_s: float,
    run_time_s: float,
    decel_time_s: float,
    cycle_time_s: float,
) -> float:
    """Tm = sqrt((Ta^2 (ta + td) + Tr^2 tr) / t) (2-4-6); Ta the torque while accelerating and braking."""
    return math.sqrt(
        (accel_torque_nm**2 * (accel_time_s + decel_time_s) + load_torque_nm**2 * run_time_s) / cycle_time_s
    )


def average_speed_rpm(
    speed_rpm: float, accel_time_s: float, run_time_s: float, decel_time_s: float, cycle_time_s: float
) -> float:
    """Nav = (N/2 ta + N tr + N/2 td) / t (2-4-6)."""
    return (
        speed_rpm / 2 * accel_time_s + speed_rpm * run_time_s + speed_rpm / 2 * decel_time_s
    ) / cycle_time_s


def min_cycle_time_s(
    accel_torque_nm: float,
    load_torque_nm: float,
    accel_time_s: float,
    run_time_s: float,
    decel_time_s: float,
    continuous_torque_nm: float,
) -> float:
    """T = (Ta^2 (ta + td) + Tr^2 tr) / Tm^2 with Tm the continuous torque: the shortest cycle (2-4-6)."""
    return (
        accel_torque_nm**2 * (accel_time_s + decel_time_s) + load_torque_nm**2 * run_time_s
    ) / continuous_torque_nm**2


# 2-4-8 ----------------------------------------------------------------------------------------
REGENERATION_NOTE = (
    "the manual prints Wr = 1/2 (JA + JL)^2 (2πN/60) / t - 40, squaring the inertia instead of the "
    "speed; used the kinetic energy 1/2 (JA + JL) ω^2 returned once per cycle"
)


def regeneration_energy_j(total_inertia_kgm2: float, speed_rpm: float) -> float:
    """E = 1/2 (JA + JL) ω^2: the energy one stop from N returns to the driver (2-4-8, corrected)."""
    return 0.5 * total_inertia_kgm2 * (speed_rpm * _RPM_TO_RAD_S) ** 2


def regeneration_power_w(total_inertia_kgm2: float, speed_rpm: float, cycle_time_s: float) -> float:
    """Average regenerated power over one cycle with one stop: E / t (W)."""
    return regeneration_energy_j(total_inertia_kgm2, speed_rpm) / cycle_time_s


def external_resistor_w(
    total_inertia_kgm2: float, speed_rpm: float, cycle_time_s: float, builtin_resistor_w: float
) -> float:
    """Wr = E / t - built-in capacity (W); zero or less: no external resistor is needed (2-4-8)."""
    return regeneration_power_w(total_inertia_kgm2, speed_rpm, cycle_time_s) - builtin_resistor_w


def printed_external_resistor_w(
    total_inertia_kgm2: float, speed_rpm: float, cycle_time_s: float, builtin_resistor_w: float
) -> float:
    """The manual's printed Wr = 1/2 (JA + JL)^2 (2πN/60) / t - 40 (dimensionally wrong; for notes)."""
    return 0.5 * total_inertia_kgm2**2 * speed_rpm * _RPM_TO_RAD_S / cycle_time_s - builtin_resistor_w
