"""Issue 25's twelve cases on the stepped simulated drive (tests/tuning/test_tuning_cases.py's
``run_case``): per case the figures the test asserts and the time it took.

    python benchmarks/tuning_cases.py [CODE-RATIO ...]      e.g. FHA-25C-50-US250-10
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from fha_studio.logic.tuning.linear import two_mass_prediction
from fha_studio.logic.tuning.move import MoveFigures
from tests.tuning.test_tuning_cases import CASES, run_case


def _move(m: object) -> str:
    if isinstance(m, MoveFigures):
        return "not settled" if m.settling_ms is None else f"{m.settling_ms:.1f} ms / {m.overshoot_pct:.3f} %"
    return str(m)


def main(argv: list[str]) -> int:
    wanted = {a.rsplit("-", 1)[0] + "-" + a.rsplit("-", 1)[1] for a in argv}
    print("case | resonance meas/pred Hz | load est/declared kg m^2 | GM dB / PM deg | "
          "settle before -> after (overshoot) | items | s")
    for code, ratio in CASES:
        if wanted and f"{code}-{ratio:g}" not in wanted:
            continue
        started = time.perf_counter()
        with tempfile.TemporaryDirectory() as tmp:
            case = run_case(code, ratio, Path(tmp))
        took = time.perf_counter() - started
        m, p = case.measured, case.proposal.proposed
        pred = two_mass_prediction(case.model).resonance_hz
        res = "none" if m["resonance_hz"] is None else f"{m['resonance_hz']:.1f}"
        print(f"{code} {ratio:g}x | {res}/{pred:.1f} | {m['load_inertia_estimate_kgm2']:.4g}/"
              f"{case.model.load_inertia_kgm2:.4g} | {p.gain_margin_db:.1f} / {p.phase_margin_deg:.1f} | "
              f"{_move(case.before)} -> {_move(case.after)} | "
              f"{'/'.join(str(v) for v in p.items.values())} | {took:.1f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
