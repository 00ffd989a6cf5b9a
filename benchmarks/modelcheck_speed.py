"""Model-check speed: CPU and wall time of `fha-studio discrepancy` work, and how it grows.

Run from the checkout: PYTHONPATH=. python benchmarks/modelcheck_speed.py
Generates recordings with the shared physics (closed loop, monitor quantisation and noise), writes
them as fha-recording/1 files, and times reading + run_modelcheck (with and without re-simulation)
for a torque-only recording, one with load_pos and one without current (a bench capture, read through
the closed loop), 20 s at 1 kHz. The target: under 1 s of CPU with
the re-simulation. Then the cost against the recording's length (5 to 80 s: it should grow linearly)
and the peak memory the analysis allocates (tracemalloc, numpy included; the re-simulation keeps one
chunk of servo periods, and covers at most the first RESIM_MAX_S seconds). Wall time and the
process's CPU time are printed: on a shared, loaded machine the wall time is several times the CPU.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "modelcheck"))

from modelcheck_gen import record, standard_moves, trapezoid_moves

from fha_studio.logic.modelcheck import run_modelcheck
from fha_studio.logic.modelcheck.workflow import RESIM_MAX_S
from fha_studio.physics import AxisModel, Effects
from fha_studio.recording import Recording, read_recording, write_recording

CODE = "FHA-25C-50-US250"

# CPU seconds of the same 20 s cases on a012ce5, before the speed work for recordings without
# current (best of 3, runs interleaved with the version after it on this 2-core machine at load
# 8-10; after: 1.01-1.07, 0.72-0.79, 1.13-1.26, 1.01-1.11, 0.73-0.80, 0.44-0.56). Load inflates every
# figure alike. The selection's projection, shape tolerance and cached held-out fits, and the
# bandwidth search at the fitted rows, then took the check with re-simulation (in memory, without
# reading the file; interleaved with f6f9799 at load 3.9-4.6) from 0.71-0.82 to 0.61-0.71 s with
# torque, 0.80-0.90 to 0.73-0.87 s with load_pos; this script at load 3.9-4.5, reading included:
# 0.82-0.87, 0.57, 0.85-0.89, 0.60-0.63, 0.48-0.60, 0.49-0.55; at load 7 the first was 1.09-1.14.
# Recording only the servo periods np.interp reads, reading the rows in whole-list passes and one
# trial per candidate beside the same model (a7a63ec..89e4883; every answer bit for bit the same)
# then took this script, interleaved with 98ec1a8 at load 1.2-1.4, from 0.70-0.73, 0.48-0.54,
# 0.80-0.90, 0.58-0.61, 0.46-0.49, 0.46-0.49 to 0.58-0.64, 0.42-0.46, 0.72-0.73, 0.52-0.56,
# 0.45-0.48, 0.46-0.50 s (reading 0.08-0.11 -> 0.04-0.06 s of it).
BEFORE_CPU_S = {
    ("torque: coulomb + gravity", True): (1.60, 1.67),
    ("torque: coulomb + gravity", False): (1.02, 1.10),
    ("torque + load_pos: + wind-up", True): (1.54, 1.70),
    ("torque + load_pos: + wind-up", False): (1.20, 1.32),
    ("no current: closed loop", True): (0.93, 0.98),
    ("no current: closed loop", False): (0.72, 1.06),
}


#: each 20 s case runs this often: its CPU is given as the least and the most of them (a busy machine
#: inflates single runs by half)
RUNS = 3


def _spread(cpus: list[float]) -> str:
    return f"{min(cpus):4.2f}-{max(cpus):4.2f} s of {len(cpus)}"


def _before(name: str, resim: bool) -> str:
    low, high = BEFORE_CPU_S[(name, resim)]
    return f"  [a012ce5: {low:.2f}-{high:.2f} s]"


def _command(duration_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Back-and-forth moves repeated to fill duration_s at 1 kHz."""
    _, one = trapezoid_moves(standard_moves(), 1000.0)
    n = round(duration_s * 1000.0) + 1
    reps = -(-n // len(one))
    # each repetition starts where the last ended
    parts = [one + k * one[-1] for k in range(reps)]
    cmd = np.concatenate(parts)[:n]
    return np.arange(n) / 1000.0, cmd


def main() -> None:
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    friction = Effects().with_effect("coulomb_friction", torque_nm=5.0)
    cases = {
        "torque: coulomb + gravity": (
            friction.with_effect("gravity_load", amplitude_nm=12.0, phase_deg=30.0),
            False,
        ),
        "torque + load_pos: + wind-up": (friction.with_effect("torsional_compliance"), True),
    }
    threads = os.environ.get("OPENBLAS_NUM_THREADS", "default")
    print(f"{CODE}, 1 kHz; BLAS threads: {threads}; load average {os.getloadavg()[0]:.1f}")
    t, cmd = _command(20.0)
    print(f"20 s ({len(t)} samples):")
    with tempfile.TemporaryDirectory() as tmp:
        for name, (effects, load_pos) in cases.items():
            gen = record(model, effects, t, cmd, actuator_code=CODE, with_load_pos=load_pos)
            path = Path(tmp) / "rec.csv"
            write_recording(path, gen.recording)
            run_modelcheck(read_recording(path), resimulate=False)  # imports and caches warm
            for resim in (True, False):
                cpus, walls = [], []
                for _ in range(RUNS):
                    c0, t0 = time.process_time(), time.perf_counter()
                    rec = read_recording(path)
                    t1 = time.perf_counter()
                    result = run_modelcheck(rec, resimulate=resim)
                    c2, t2 = time.process_time(), time.perf_counter()
                    cpus.append(c2 - c0)
                    walls.append((t1 - t0, t2 - t1))
                named = ", ".join(e.id for e in result.effects) or "none"
                read_s, check_s = min(walls, key=lambda w: w[0] + w[1])
                print(
                    f"  {name:30s} resim={'on ' if resim else 'off'}  read {read_s:5.2f} s  "
                    f"check {check_s:5.2f} s  (cpu {_spread(cpus)})  "
                    f"bandwidth {result.bandwidth_hz:5.1f} Hz  named: {named}{_before(name, resim)}"
                )

    # a bench capture: no current column, read through the closed loop identified from the recording
    without = record(model, friction.with_effect("gravity_load", amplitude_nm=12.0, phase_deg=30.0), t, cmd,
                     actuator_code=CODE).recording
    bench = Recording(without.metadata, {k: v for k, v in without.channels.items() if k != "current"})
    for resim in (True, False):
        cpus = []
        for _ in range(RUNS):
            c0 = time.process_time()
            result = run_modelcheck(bench, resimulate=resim)
            cpus.append(time.process_time() - c0)
        named = ", ".join(e.id for e in result.effects) or "none"
        on = "on " if resim else "off"
        name = "no current: closed loop"
        print(f"  {name:30s} resim={on}  (cpu {_spread(cpus)})  named: {named}{_before(name, resim)}")

    print(f"cost against length (torque + friction, re-simulation on; it covers at most {RESIM_MAX_S:g} s):")
    for duration in (5.0, 10.0, 20.0, 40.0, 80.0):
        t, cmd = _command(duration)
        rec = record(model, friction, t, cmd, actuator_code=CODE).recording
        c0 = time.process_time()
        run_modelcheck(rec)
        cpu = time.process_time() - c0
        tracemalloc.start()
        run_modelcheck(rec)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        print(
            f"  {duration:4.0f} s  cpu {cpu:5.2f} s  ({1000 * cpu / duration:5.1f} ms per second recorded)  "
            f"peak memory {peak / 1e6:6.1f} MB ({peak / len(t):6.0f} bytes per sample)"
        )


if __name__ == "__main__":
    main()
