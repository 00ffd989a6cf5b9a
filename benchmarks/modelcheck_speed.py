"""Model-check speed: wall time of `fha-studio discrepancy` work on a 20 s recording at 1 kHz.

Run from the checkout: PYTHONPATH=. python benchmarks/modelcheck_speed.py
Generates recordings with the shared physics (closed loop, monitor quantisation and noise), writes
them as fha-recording/1 files, and times reading + run_modelcheck (with and without re-simulation)
for a torque-only recording and one with load_pos. The contract: under 5 s. Wall time and the
process's CPU time are printed: on a shared, loaded machine the wall time is several times the CPU.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "modelcheck"))

from modelcheck_gen import record, standard_moves, trapezoid_moves

from fha_studio.logic.modelcheck import run_modelcheck
from fha_studio.physics import AxisModel, Effects
from fha_studio.recording import read_recording, write_recording

CODE = "FHA-25C-50-US250"


def main() -> None:
    model = AxisModel.from_code(CODE, load_inertia_kgm2=1.5)
    moves = standard_moves() * 2
    t, cmd = trapezoid_moves(moves, 1000.0)
    n = 20_001  # 20 s: hold the last position after the moves
    t = np.arange(n) / 1000.0
    cmd = np.concatenate([cmd, np.full(max(0, n - len(cmd)), cmd[-1])])[:n]
    cases = {
        "torque: coulomb + gravity": (
            Effects()
            .with_effect("coulomb_friction", torque_nm=5.0)
            .with_effect("gravity_load", amplitude_nm=12.0, phase_deg=30.0),
            False,
        ),
        "torque + load_pos: + wind-up": (
            Effects().with_effect("coulomb_friction", torque_nm=5.0).with_effect("torsional_compliance"),
            True,
        ),
    }
    print(f"{CODE}, {len(t)} samples at 1 kHz ({t[-1]:.1f} s)")
    with tempfile.TemporaryDirectory() as tmp:
        for name, (effects, load_pos) in cases.items():
            gen = record(model, effects, t, cmd, actuator_code=CODE, with_load_pos=load_pos)
            path = Path(tmp) / "rec.csv"
            write_recording(path, gen.recording)
            for resim in (True, False):
                c0, t0 = time.process_time(), time.perf_counter()
                rec = read_recording(path)
                t1 = time.perf_counter()
                result = run_modelcheck(rec, resimulate=resim)
                c2, t2 = time.process_time(), time.perf_counter()
                named = ", ".join(e.id for e in result.effects) or "none"
                print(
                    f"  {name:32s} resim={'on ' if resim else 'off'}  read {t1 - t0:5.2f} s  "
                    f"check {t2 - t1:5.2f} s  total {t2 - t0:5.2f} s (cpu {c2 - c0:5.2f} s)  "
                    f"window {result.window_samples}  named: {named}"
                )


if __name__ == "__main__":
    main()
