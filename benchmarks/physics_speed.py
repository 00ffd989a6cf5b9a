"""Physics speed: simulated time per wall-clock time at the servo rate (5 kHz), per case.

Run from the checkout: PYTHONPATH=. python benchmarks/physics_speed.py
Prints, for several actuators and effect sets, the multiple of real time of ServoAxis.step and
the wall time of simulate() for a 20 s recording at 1 kHz (the model check's re-simulation).
"""

from __future__ import annotations

import math
import time

import numpy as np

from fha_studio.physics import AxisModel, Effects, ServoAxis, catalogue_effects, simulate

try:
    from fha_studio.catalog import get_actuator
except ImportError:  # before the catalogue lands
    get_actuator = None

MANUAL = {  # Kt, Im, JA, ratio, ppr, rpm, TM, R, T1, T2, K1, K2, K3 (FHA-C manual 1-4-1, 1-9-2)
    "FHA-25C-50-US250": (22, 7.3, 0.81, 50, 500_000, 90, 150, 2.6, 29, 108, 4.7e4, 6.1e4, 8.4e4),
    "FHA-40C-50-US250": (31, 17.3, 4.9, 50, 500_000, 70, 500, 0.73, 108, 382, 17e4, 21e4, 30e4),
    "FHA-17C-50-US250": (21, 2.1, 0.17, 50, 500_000, 96, 39, 7.9, 7.0, 25, 1.1e4, 1.3e4, 2.0e4),
}


def model_for(code: str, load: float) -> AxisModel:
    if get_actuator is not None:
        return AxisModel.from_code(code, load)
    from fha_studio.physics import GearStiffness

    kt, im, ja, ratio, ppr, rpm, tm, r, t1, t2, k1, k2, k3 = MANUAL[code]
    return AxisModel(kt, im, ja, load, ratio, ppr, rpm, tm, r, GearStiffness(t1, t2, k1, k2, k3),
                     actuator_code=code)


def everything(model: AxisModel) -> Effects:
    return (catalogue_effects(model).with_effect("gravity_load", amplitude_nm=10.0, phase_deg=30.0)
            .with_effect("torque_ripple", amplitude_nm=0.5, cycles_per_motor_rev=2)
            .with_effect("kinematic_error", amplitude_arcsec=20.0, cycles_per_motor_rev=2)
            .with_effect("lost_motion", width_arcsec=30.0))


def step_speed(model: AxisModel, seconds: float = 4.0) -> tuple[float, int]:
    axis = ServoAxis(model)
    axis.servo_on()
    axis.jog(0.5 * (model.max_speed_rad_s or 1.0))
    n = round(seconds / axis.servo_period_s)
    t0 = time.perf_counter()
    for _ in range(n // 500):  # the sim steps in blocks (here 0.1 s)
        axis.step(500)
    wall = time.perf_counter() - t0
    return seconds / wall, axis.substeps


def simulate_time(model: AxisModel) -> float:
    t = np.arange(0, 20.0, 1e-3)
    cmd = math.radians(90) * np.sin(2 * np.pi * 0.2 * t)
    t0 = time.perf_counter()
    simulate(model, None, t, cmd)
    return time.perf_counter() - t0


def main() -> None:
    print("physics speed at a 5 kHz servo rate (multiple of real time; higher is better)")
    print(f"{'case':56s} {'substeps':>8s} {'x real time':>12s} {'simulate 20 s @1 kHz':>22s}")
    for code, load in (("FHA-25C-50-US250", 1.5), ("FHA-40C-50-US250", 0.0), ("FHA-17C-50-US250", 0.05)):
        base = model_for(code, load)
        for label, effects in (("nominal (rigid)", Effects()), ("catalogue friction+stiffness",
                                                                 catalogue_effects(base)),
                               ("all effects", everything(base))):
            model = base.with_effects(effects)
            rt, nsub = step_speed(model)
            sim_s = simulate_time(model)
            print(f"{code + ' JL=' + str(load) + ' ' + label:56s} {nsub:8d} {rt:11.0f}x {sim_s:20.2f} s")


if __name__ == "__main__":
    main()
