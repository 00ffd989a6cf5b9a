"""The scope's figures in one run: each beside its goal, the ratio to the goal, and the figure
measured before the scope was reworked (2 cores, load average ~5).

Run: QT_QPA_PLATFORM=offscreen python benchmarks/run_all.py [--seconds S] [--json FILE]

Polling and drawing: ``scope_throughput.py``; trace read-out: ``trace_readout.py``; start-up:
``gui_startup.py``. ``--json FILE`` writes ``{"figures": {NAME: {"value", "goal", "unit",
"better": "higher" | "lower", "before", "note"}}, "load_average": ..., "cores": ...}``.
Each polling case runs ``--repeat`` times (interleaved) and its figure is the median run.
The machine is shared: the load average before and after the run is printed and written; a
figure measured under load is lower than on a quiet machine. The start-up goal is 1 s on a
quiet machine (load average below the number of cores) and 2 s under load.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
sys.path.insert(0, str(Path(__file__).resolve().parent))

import gui_startup
import scope_throughput as scope
import trace_readout

from fha_studio.gui.app import make_application

STANDSTILL = ("feedback_position", "command_position", "output_speed", "motor_current")


@dataclass
class Figure:
    value: float
    goal: float
    unit: str
    better: str  # "higher" or "lower"
    before: float  # the figure before the rework
    what: str

    @property
    def ratio(self) -> float:
        """>= 1 when the goal is met."""
        if self.better == "higher":
            return self.value / self.goal
        return self.goal / self.value if self.value else float("inf")


def _median_run(runs: list[dict]) -> tuple[dict, str]:
    """The run with the median share of the line, and all shares as text."""
    ordered = sorted(runs, key=lambda r: r["pct"])
    return ordered[len(ordered) // 2], "/".join(f"{r['pct']:.0f}" for r in runs)


def measure(seconds: float, startup_runs: int, load: float, repeat: int = 3) -> dict[str, Figure]:
    figures: dict[str, Figure] = {}
    make_application()  # as the GUI makes it (GIL switch interval included)
    scope.isolate_settings()
    cases = (
        ("poll_1_item_pct_of_limit", ("feedback_position",), 0.0, 67.0, "polling 1 item, standstill"),
        ("poll_4_items_pct_of_limit", STANDSTILL, 0.0, 72.0, "polling 4 items, standstill"),
        ("poll_4_items_jogging_pct_of_limit", STANDSTILL, 20.0, 63.0, "polling 4 items, jogging 20 r/min"),
    )
    polled: dict[str, list[dict]] = {name: [] for name, *_ in cases}
    gui: list[dict] = []
    for _ in range(repeat):  # interleaved, so a burst of load does not fall on one case only
        for name, keys, jog, _before, _what in cases:
            polled[name].append(scope.polling(keys, seconds, jog))
        gui.append(scope.gui_polling(seconds))
    for name, _keys, _jog, before, what in cases:
        r, shares = _median_run(polled[name])
        figures[name] = Figure(r["pct"], 90.0, "%", "higher", before,
                               f"{what}: median of {repeat} runs ({shares} %): {r['rate']:.1f} samples/s, "
                               f"limit {r['limit']:.1f}/s")
    g, shares = _median_run(gui)
    figures["gui_poll_pct_of_limit"] = Figure(
        g["pct"], 90.0, "%", "higher", 34.0,
        f"GUI, Scope page showing and plotting {g['items']} channels: median of {repeat} runs "
        f"({shares} %): {g['rate']:.1f} samples/s, limit {g['limit']:.1f}/s, {g['fps']:.0f} frames/s")
    v = scope.view_load(seconds)
    figures["view_fps_4x60s_1khz"] = Figure(v["fps"], 30.0, "frames/s", "higher", 8.3,
                                            f"live view, {v['points']} points on show")
    figures["view_cpu_pct_of_one_core"] = Figure(
        v["cpu"], 50.0, "%", "lower", 36.5,
        f"whole process while drawing it ({v['cpu_per_frame_ms']:.1f} ms CPU per frame)")
    t = trace_readout.speedup()
    figures["trace_readout_speedup"] = Figure(
        t["speedup"], 1.8, "x", "higher", 1.0,
        f"4 channels x {t['packed']['samples']} samples of a move: {t['packed']['rate']:.0f} samples/s "
        f"({t['packed']['chars_per_sample']:.1f} characters each) against {t['text']['rate']:.0f}/s "
        f"({t['text']['chars_per_sample']:.1f}) in text")
    figures["trace_readout_samples_per_s"] = Figure(
        t["packed"]["rate"], 1.8 * t["text"]["rate"], "samples/s", "higher", t["text"]["rate"],
        "the same, packed encoding")
    runs = gui_startup.measure(startup_runs)
    usable = statistics.median(r["usable_s"] for r in runs)
    quiet = load < (os.cpu_count() or 1)
    figures["startup_usable_s"] = Figure(
        usable, 1.0 if quiet else 2.0, "s", "lower", 0.66 if quiet else 2.04,
        f"start-up to a usable window, median of {startup_runs} "
        f"({'quiet machine: goal 1 s' if quiet else 'under load: goal 2 s'}), "
        f"[{min(r['usable_s'] for r in runs):.2f}-{max(r['usable_s'] for r in runs):.2f}] s")
    return figures


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--seconds", type=float, default=6.0,
                        help="measuring time per polling/drawing case [s]")
    parser.add_argument("--startup-runs", type=int, default=5, help="fresh GUI processes for the start-up")
    parser.add_argument("--repeat", type=int, default=3,
                        help="runs of each polling case (the median is the figure)")
    parser.add_argument("--json", type=Path, help="also write the figures to this file")
    args = parser.parse_args()
    load_before = os.getloadavg()
    print(f"machine: {os.cpu_count()} cores, load average {load_before[0]:.2f} {load_before[1]:.2f} "
          f"{load_before[2]:.2f} (1, 5, 15 min)")
    figures = measure(args.seconds, args.startup_runs, load_before[0], args.repeat)
    load_after = os.getloadavg()
    print(f"{'figure':<34} {'value':>9} {'unit':<9} {'goal':>10} {'ratio':>6} {'before':>8}")
    for name, f in figures.items():
        sign = ">=" if f.better == "higher" else "<="
        met = "met" if f.ratio >= 1 else "NOT MET"
        print(f"{name:<34} {f.value:>9.2f} {f.unit:<9} {sign}{f.goal:>8.2f} {f.ratio:>6.2f} "
              f"{f.before:>8.2f}  {met}")
        print(f"    {f.what}")
    print(f"load average after the run: {load_after[0]:.2f} {load_after[1]:.2f} {load_after[2]:.2f}")
    if args.json:
        out = {"figures": {name: {k: v for k, v in asdict(f).items() if k != "what"} | {"note": f.what}
                           for name, f in figures.items()},
               "load_average": {"before": list(load_before), "after": list(load_after)},
               "cores": os.cpu_count()}
        args.json.write_text(json.dumps(out, indent=2) + "\n")
        print(f"written: {args.json}")
    return 0 if all(f.ratio >= 1 for f in figures.values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
