"""Live bench stream drawn: the scope's Bench tab streaming sigrok-cli's demo driver at 24 MS/s
(8 logic channels, the common USB logic analyzers' rate), the encoder (D0/D1) counted x4 and the
command lines (D2/D3) decoded as the blocks come, the newest 2 s redrawn at every tick of the
scope's drain timer.

Run: QT_QPA_PLATFORM=offscreen python benchmarks/bench_live_draw.py [--seconds S] [--rate HZ]
(prints figures; nothing is asserted).

- ``samples dropped``: what real time asked of the instrument and the worker never took (the
  demo paces its pattern by the clock: a worker too slow for the stream falls behind);
- ``rows dropped``: display rows overwritten in the ring before the GUI drained them;
- ``frames/s``: redraws of the plot against the drain timer's rate (1000 / DRAIN_INTERVAL_MS),
  and the longest gap between two redraws;
- CPU of this process (worker thread and GUI) and of sigrok-cli, in % of one core.
"""

from __future__ import annotations

import argparse
import itertools
import os
import sys
import time

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QEventLoop, QTimer

from fha_studio.gui.app import make_application
from fha_studio.gui.pages.scope.bench_panel import BenchPanel
from fha_studio.gui.pages.scope.bench_source import DRAIN_INTERVAL_MS
from fha_studio.hardware.bench import sigrok


def thread_cpu_s(name: str) -> float:
    """CPU seconds of this process's threads named ``name`` (Qt names a QThread's native thread
    after its object name)."""
    total = 0
    for task in os.listdir("/proc/self/task"):
        try:
            with open(f"/proc/self/task/{task}/comm") as comm:
                if comm.read().strip() != name:
                    continue
            with open(f"/proc/self/task/{task}/stat") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += int(fields[11]) + int(fields[12])  # utime, stime (clock ticks)
    return total / os.sysconf("SC_CLK_TCK")


def run(seconds: float, rate: float, decode: bool = True) -> dict[str, float]:
    panel = BenchPanel()
    panel.resize(1200, 700)
    panel.show()
    frames: list[float] = []
    original = panel._on_rows

    def counted(rows):  # every redraw, timed
        original(rows)
        frames.append(time.monotonic())

    panel.source.sigRows.disconnect(panel._on_rows)
    panel.source.sigRows.connect(counted)
    loop = QEventLoop()
    panel.source.sigStarted.connect(lambda _s: QTimer.singleShot(int(seconds * 1000), panel.stop))
    panel.source.sigStopped.connect(lambda _w: loop.quit())
    cpu0, t0 = os.times(), time.monotonic()
    gui0, worker0 = time.thread_time(), thread_cpu_s("bench-sigrok")
    panel.start("demo", ",".join(f"D{i}" for i in range(8)), f"{rate:g}", encoder="D0,D1" if decode else "",
                command="D2,D3" if decode else "")
    QTimer.singleShot(int((seconds + 30) * 1000), loop.quit)  # a ceiling only a hang reaches
    loop.exec()
    cpu, wall = os.times(), time.monotonic() - t0
    worker1 = thread_cpu_s("bench-sigrok")
    gui_cpu = time.thread_time() - gui0
    status = panel.source.status
    started = panel.source.started
    panel.shutdown()
    assert status is not None and started is not None and frames
    span = frames[-1] - frames[0]
    gaps = [b - a for a, b in itertools.pairwise(frames)]
    asked = started.sample_rate_hz * span
    return {
        "rate_hz": started.sample_rate_hz,
        "seconds": span,
        "samples": status.samples,
        "samples_per_s": status.samples / max(wall, 1e-9),
        "asked_per_s": started.sample_rate_hz,
        "dropped_share": max(0.0, asked - status.samples) / asked if asked else 0.0,
        "rows": status.rows,
        "rows_dropped": status.dropped,
        "fps": (len(frames) - 1) / span if span else 0.0,
        "longest_gap_ms": 1000 * max(gaps, default=0.0),
        "worker_cpu": (worker1 - worker0) / wall,
        "gui_cpu": gui_cpu / wall,
        "cpu": (cpu.user - cpu0.user + cpu.system - cpu0.system) / wall,
        "sigrok_cpu": (cpu.children_user - cpu0.children_user + cpu.children_system
                       - cpu0.children_system) / wall,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--rate", type=float, default=24e6, help="sample rate [Hz]")
    args = parser.parse_args()
    make_application(sys.argv[:1])
    for decode in (False, True):
        report(run(args.seconds, args.rate, decode), decode)


def report(f: dict[str, float], decode: bool) -> None:
    what = "encoder (D0/D1) and command (D2/D3) decoded" if decode else "channels plotted only"
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; Bench tab, sigrok-cli demo, "
          f"8 logic channels at {sigrok.rate_text(f['rate_hz'])}, {what}, {f['seconds']:.1f} s")
    print(f"samples: {f['samples']:,} taken, {f['samples_per_s'] / 1e6:.2f} MS/s of "
          f"{f['asked_per_s'] / 1e6:.2f} asked; dropped {100 * f['dropped_share']:.1f} % (behind real time)")
    print(f"display rows: {f['rows']:,} written, {f['rows_dropped']} dropped before the GUI drained them")
    print(f"frames: {f['fps']:.1f} redraws/s of the drain timer's {1000 / DRAIN_INTERVAL_MS:.0f}/s, "
          f"longest gap {f['longest_gap_ms']:.0f} ms")
    print(f"CPU: FHA Studio {100 * f['cpu']:.0f} % (the bench worker's thread {100 * f['worker_cpu']:.0f} %, "
          f"the GUI thread {100 * f['gui_cpu']:.0f} %), sigrok-cli {100 * f['sigrok_cpu']:.0f} % of a core")


if __name__ == "__main__":
    main()
