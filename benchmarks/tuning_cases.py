"""Issue 25's twelve cases on the stepped simulated drive (tests/tuning/test_tuning_cases.py's
``run_case``): per case the figures the test asserts and the time it took. "measured with": the
items the response was measured with (the defaults, or the proposal where the defaults make the
loop unstable with the load and the drive is not excited); beyond 2-1 the standard aim's proposal
("standard") beside the softer one.

    python benchmarks/tuning_cases.py [--friction] [CODE-RATIO ...]      e.g. FHA-25C-50-US250-10

``--friction``: on a drive with the catalogue's friction (``catalogue_friction=1``, TF of FHA-C
manual 2-4-4, as the Connect dialog gives a simulated drive), the excitation on its bias speed.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np

from fha_studio.logic.tuning.linear import two_mass_prediction
from fha_studio.logic.tuning.move import MoveFigures
from fha_studio.logic.tuning.response import COHERENCE_TRUSTED
from tests.tuning.test_tuning_cases import CASES, Case, run_case


def _move(m: object) -> str:
    if isinstance(m, MoveFigures):
        return "not settled" if m.settling_ms is None else f"{m.settling_ms:.1f} ms / {m.overshoot_pct:.3f} %"
    return str(m)


def _worst(case: Case) -> str:
    """The largest magnitude (dB) and phase (deg) gap to the linearisation at trusted bins."""
    db = deg = 0.0
    for which, key in (("closed", "frequency_response"), ("plant", "plant_response")):
        data = case.measured[key]
        f = np.asarray(data["freq_hz"])
        ok = np.asarray(data["coherence"]) >= COHERENCE_TRUSTED
        mag, phase = case.linear.response(which, f)
        gap = (np.asarray(data["phase_deg"]) - phase + 180.0) % 360.0 - 180.0
        db = max(db, float(np.max(np.abs(np.asarray(data["magnitude_db"]) - mag)[ok])))
        deg = max(deg, float(np.max(np.abs(gap)[ok])))
    return f"{db:.2f} dB / {deg:.1f} deg"


def main(argv: list[str]) -> int:
    friction = "--friction" in argv
    argv = [a for a in argv if a != "--friction"]
    wanted = {a.rsplit("-", 1)[0] + "-" + a.rsplit("-", 1)[1] for a in argv}
    print("case | measured with | response gap | resonance meas/pred Hz | load est/declared kg m^2 | "
          "GM dB / PM deg | settle before -> after (overshoot) | items (standard) | s")
    for code, ratio in CASES:
        if wanted and f"{code}-{ratio:g}" not in wanted:
            continue
        started = time.perf_counter()
        with tempfile.TemporaryDirectory() as tmp:
            case = run_case(code, ratio, Path(tmp), friction)
        took = time.perf_counter() - started
        m, p = case.measured, case.proposal.proposed
        pred = two_mass_prediction(case.model).resonance_hz
        res = "none" if m["resonance_hz"] is None else f"{m['resonance_hz']:.1f}"
        load = m["load_inertia_estimate_kgm2"]
        ref = case.proposal.reference
        items = "/".join(str(v) for v in p.items.values())
        if ref is not None:
            items += f" ({'/'.join(str(v) for v in ref.items.values())})"
        print(f"{code} {ratio:g}x | {'defaults' if case.refused is None else 'proposal'} | {_worst(case)} | "
              f"{res}/{pred:.1f} | {load:.4g}/{case.model.load_inertia_kgm2:.4g} | "
              f"{p.gain_margin_db:.1f} / {p.phase_margin_deg:.1f} | "
              f"{_move(case.before)} -> {_move(case.after)} | {items} | {took:.1f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
