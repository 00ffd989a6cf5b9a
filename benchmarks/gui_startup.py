"""Start-up time of the GUI: from a fresh interpreter to a usable main window.

    QT_QPA_PLATFORM=offscreen python benchmarks/gui_startup.py [RUNS]

Each run is a new process (imports included, as a user starts it). "Usable" = the main window
is shown and painted; "connected" = the embedded simulated drive has answered and its
parameters are read. Prints the median and the spread of the runs. Target: usable in < 1 s
(median) on a quiet machine, < 2 s under load.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import time
t0 = time.perf_counter()
import os, sys, json
sys.path.insert(0, sys.argv[1])
from PySide6.QtCore import QCoreApplication, QTimer
from PySide6.QtWidgets import QApplication
app = QApplication([])
QCoreApplication.setOrganizationName("FHA Studio Benchmark")
QCoreApplication.setApplicationName("fha-studio-benchmark")
t_qt = time.perf_counter()
from fha_studio.gui.main_window import MainWindow
t_import = time.perf_counter()
window = MainWindow()
window.show()
window.connect_to("sim://FHA-25C-50-US250")
out = {}
def usable():
    window.grab()  # painted once
    out["usable_s"] = time.perf_counter() - t0
window.link.sigConnected.connect(lambda _i: out.setdefault("link_s", time.perf_counter() - t0))
def check():
    if len(window.state.drive_values) >= 14 and "usable_s" in out:
        out["connected_s"] = time.perf_counter() - t0
        window._closing_confirmed = True
        window.close()
        app.quit()
    else:
        QTimer.singleShot(5, check)
QTimer.singleShot(0, usable)
QTimer.singleShot(0, check)
QTimer.singleShot(20000, app.quit)
app.exec()
window.shutdown()
out.update(qt_s=t_qt - t0, imports_s=t_import - t0)
print(json.dumps(out))
"""


def measure(runs: int = 5) -> list[dict]:
    """Start the GUI ``runs`` times in fresh processes; one dict of times [s] per run."""
    env = dict(os.environ)
    env.setdefault("QT_QPA_PLATFORM", "offscreen")
    tmp = tempfile.mkdtemp(prefix="fha-bench-")
    env["XDG_CONFIG_HOME"] = f"{tmp}/config"
    env["XDG_DATA_HOME"] = f"{tmp}/data"
    results = []
    for _ in range(runs):
        done = subprocess.run(
            [sys.executable, "-c", CHILD, str(ROOT)], capture_output=True, text=True, env=env, timeout=60
        )
        line = [ln for ln in done.stdout.splitlines() if ln.startswith("{")]
        if done.returncode or not line:
            raise RuntimeError(f"the GUI did not start: {done.stdout}\n{done.stderr}")
        results.append(json.loads(line[-1]))
    return results


def main() -> int:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    env = {"QT_QPA_PLATFORM": os.environ.get("QT_QPA_PLATFORM", "offscreen")}
    try:
        results = measure(runs)
    except RuntimeError as exc:
        print(exc, file=sys.stderr)
        return 1
    print(f"GUI start-up, {runs} fresh processes, platform {env['QT_QPA_PLATFORM']} (median [min-max]):")
    for key, what in (
        ("qt_s", "QApplication created"),
        ("imports_s", "GUI modules imported"),
        ("usable_s", "main window shown and painted (usable)"),
        ("link_s", "embedded simulated drive connected"),
        ("connected_s", "parameters read (paced 19200 baud line)"),
    ):
        values = [r[key] for r in results if key in r]
        print(f"  {what:<45} {statistics.median(values):6.3f} s  [{min(values):.3f}-{max(values):.3f}]")
    print("  target: usable in under 1 s on a quiet machine, under 2 s under load")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
