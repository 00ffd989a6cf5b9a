"""Physics speed: simulated time per wall-clock time at the servo rate (5 kHz), per case.

Run from the checkout: PYTHONPATH=. python benchmarks/physics_speed.py
Prints, for several actuators and effect sets, the multiple of real time of ServoAxis.step and
the time of simulate() for a 20 s recording at 1 kHz (the model check's re-simulation).
Times are CPU seconds of this process (time.process_time), so other load on the machine
disturbs them less than wall time; the load average is printed alongside.
"""

from __future__ import annotations

import math
import os
import time

import numpy as np

from fha_studio.physics import AxisModel, Effects, ServoAxis, catalogue_effects, simulate


def model_for(code: str, load: float) -> AxisModel:
    return AxisModel.from_code(code, load)


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
    t0 = time.process_time()
    for _ in range(n // 500):  # the sim steps in blocks (here 0.1 s)
        axis.step(500)
    cpu = time.process_time() - t0
    return seconds / cpu, axis.substeps


def simulate_time(model: AxisModel) -> float:
    t = np.arange(0, 20.0, 1e-3)
    cmd = math.radians(90) * np.sin(2 * np.pi * 0.2 * t)
    t0 = time.process_time()
    simulate(model, None, t, cmd)
    return time.process_time() - t0


def main() -> None:
    print("physics speed at a 5 kHz servo rate (multiple of real time; higher is better)")
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; CPU seconds of this process")
    print(f"{'case':56s} {'substeps':>8s} {'x real time':>12s} {'simulate 20 s @1 kHz (CPU)':>28s}")
    for code, load in (("FHA-25C-50-US250", 1.5), ("FHA-40C-50-US250", 0.0), ("FHA-17C-50-US250", 0.05)):
        base = model_for(code, load)
        for label, effects in (("nominal (rigid)", Effects()), ("catalogue friction+stiffness",
                                                                 catalogue_effects(base)),
                               ("all effects", everything(base))):
            model = base.with_effects(effects)
            rt, nsub = step_speed(model)
            sim_s = simulate_time(model)
            print(f"{code + ' JL=' + str(load) + ' ' + label:56s} {nsub:8d} {rt:11.0f}x {sim_s:26.2f} s")


if __name__ == "__main__":
    main()
