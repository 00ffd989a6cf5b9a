"""The times the tests bound by a ceiling: how long they typically take, beside the ceiling.

Run from the checkout: QT_QPA_PLATFORM=offscreen PYTHONPATH=. python benchmarks/timing_ceilings.py [--runs N]

A test that measures a time (the link lamp turning red after a drive fell silent, STOP during a
trace read-out, closing the window while it connects, a link error after the simulated drive is
killed, ...) asserts only a ceiling that a hang reaches, at least 10 x the typical figure
(``time_ceiling`` in tests/conftest.py). This script runs every such test ``--runs`` times (the
test files that call ``time_ceiling``, only the tests that use the fixture) and prints, per
figure, the median and the longest of the runs, the ceiling, and how many times the median the
ceiling is ("NOT 10 x" when less). Nothing is asserted; the load average is printed alongside,
since a loaded machine makes every figure longer.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
HEADROOM = 10.0  # the ceiling is at least this many times the typical figure


def pytest_collection_modifyitems(config, items):
    """As a pytest plugin (``-p timing_ceilings``): keep only the tests that use time_ceiling."""
    kept = [item for item in items if "time_ceiling" in getattr(item, "fixturenames", ())]
    config.hook.pytest_deselected(items=[item for item in items if item not in kept])
    items[:] = kept


def test_files() -> list[str]:
    return sorted(str(path.relative_to(ROOT)) for path in (ROOT / "tests").rglob("test_*.py")
                  if "time_ceiling(" in path.read_text(encoding="utf-8"))


def run_once(files: list[str], timings: Path) -> int:
    env = {**os.environ, "FHA_TEST_TIMINGS": str(timings), "QT_QPA_PLATFORM": os.environ.get(
        "QT_QPA_PLATFORM", "offscreen"), "PYTHONPATH": os.pathsep.join([str(ROOT / "benchmarks"), str(ROOT)])}
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "timing_ceilings", *files],
                          cwd=ROOT, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        print(done.stdout[-3000:], file=sys.stderr)
    return done.returncode


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="runs of each test (default %(default)s)")
    args = parser.parse_args()
    files = test_files()
    load = os.getloadavg()
    print(f"machine: {os.cpu_count()} cores, load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print(f"tests from: {', '.join(files)}; {args.runs} runs")
    figures: dict[tuple[str, str], list[float]] = defaultdict(list)
    ceilings: dict[tuple[str, str], float] = {}
    failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        timings = Path(tmp) / "timings.jsonl"
        for _ in range(args.runs):
            failed += run_once(files, timings) != 0
        for line in timings.read_text(encoding="utf-8").splitlines() if timings.exists() else []:
            fact = json.loads(line)
            key = (fact["what"], fact["test"].split("::", 1)[1])
            figures[key].append(fact["seconds"])
            ceilings[key] = fact["ceiling_s"]
    print(f"{'figure':<48} {'runs':>4} {'median':>8} {'longest':>8} {'ceiling':>8} {'x median':>9}")
    for key in sorted(figures):
        seconds = figures[key]
        median = statistics.median(seconds)
        headroom = ceilings[key] / median if median > 0 else float("inf")
        note = "" if headroom >= HEADROOM else f"  NOT {HEADROOM:g} x"
        print(f"{key[0]:<48} {len(seconds):>4} {median:>7.3f}s {max(seconds):>7.3f}s "
              f"{ceilings[key]:>7.1f}s {headroom:>8.1f}x{note}")
        print(f"    {key[1]}")
    load = os.getloadavg()
    print(f"load average after the runs: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}"
          + (f"; {failed} run(s) had failures (above)" if failed else ""))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
