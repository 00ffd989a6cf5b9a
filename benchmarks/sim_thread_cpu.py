"""The simulated drive's thread: its CPU share of one core while it jogs, per effect set.

Run from the checkout: PYTHONPATH=. python benchmarks/sim_thread_cpu.py [SECONDS]
The embedded drive runs in real time in its own thread, advancing every TICK_S (2 ms) by the
time that passed (hardware/sim/realtime.py). This drives a stepped SimDrive exactly that way
(servo on, JOG repeated every 50 ms at half the maximum speed, advance(TICK_S) per tick) for
SECONDS of drive time (default 5) and prints the CPU seconds it took per drive second: the
share of a core the thread needs on this machine (above 100 % it cannot keep real time).
Cases: frictionless (a bare sim://), the catalogue friction (TF of 2-4-4 as Coulomb + viscous),
and that friction with the gear's torsional compliance (1-9-2). CPU seconds of this process
(time.process_time), so other load disturbs them less than wall time; the load average is shown.
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any

from fha_studio.hardware.sim import SimDrive
from fha_studio.hardware.sim.realtime import TICK_S

JOG_REPEAT_S = 0.05
CASES: tuple[tuple[str, dict[str, Any]], ...] = (
    ("frictionless (a bare sim://)", {}),
    ("catalogue_friction=1", {"catalogue_friction": True}),
    ("... + effects=torsional_compliance",
     {"catalogue_friction": True, "effects": {"torsional_compliance": {}}}),
)


def cpu_share(code: str, load_kgm2: float, options: dict[str, Any], seconds: float) -> tuple[float, int]:
    drive = SimDrive(code, load_inertia_kgm2=load_kgm2, stepped=True, **options)
    try:
        drive.set_servo(True)
        speed = 0.5 * (drive.model.max_speed_rpm or 10.0)
        ticks_per_jog = round(JOG_REPEAT_S / TICK_S)
        ticks = round(seconds / TICK_S)
        t0 = time.process_time()
        for i in range(ticks):
            if i % ticks_per_jog == 0:
                drive.jog(speed)
            drive.advance(TICK_S)
        cpu = time.process_time() - t0
        return cpu / seconds, drive.axis.substeps
    finally:
        drive.close()


def main() -> None:
    seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 5.0
    print(f"simulated drive thread: CPU share of one core while jogging ({seconds:g} s of drive time each)")
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; CPU seconds of this process")
    print(f"{'case':62s} {'substeps':>8s} {'CPU share':>10s}")
    for code, load in (("FHA-17C-50-US250", 0.05), ("FHA-25C-50-US250", 0.0), ("FHA-25C-50-US250", 1.5),
                       ("FHA-40C-50-US250", 0.0)):
        for label, options in CASES:
            share, nsub = cpu_share(code, load, options, seconds)
            print(f"{code + ' JL=' + str(load) + ' ' + label:62s} {nsub:8d} {100 * share:9.1f}%")


if __name__ == "__main__":
    main()
