"""Start-up time of the command line: from a fresh interpreter to the command's answer.

    python benchmarks/cli_startup.py [RUNS] [--root DIR]

Each run is a new process, as a user (or a script calling ``fha-studio`` in a loop) starts it:
``fha-studio --help`` (every command's parser is built), ``fha-studio register machines`` on a
register file (the register opened), ``fha-studio register keys list`` (the signing library
too). Prints the median and the spread of the wall time and of the process's CPU time (steadier on a
loaded machine), the modules each loaded, and whether
the register's store and the signing library (``cryptography``) were among them. ``--root``
measures another checkout (e.g. main, for a before/after figure); the processes write no
bytecode there.
"""

from __future__ import annotations

import argparse
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
t0, c0 = time.perf_counter(), time.process_time()
import json, sys
sys.path.insert(0, sys.argv[1])
from fha_studio.cli import main
try:
    code = main(sys.argv[2:])
except SystemExit as exc:  # --help
    code = exc.code
elapsed, cpu = time.perf_counter() - t0, time.process_time() - c0
sys.stdout.flush()
print("\n" + json.dumps({"s": elapsed, "cpu_s": cpu, "code": code, "modules": len(sys.modules),
                         "store": "fha_studio.logic.register.store" in sys.modules,
                         "cryptography": "cryptography" in sys.modules}), file=sys.stderr)
"""

COMMANDS = {
    "fha-studio --help": ["--help"],
    "fha-studio register machines": ["register", "--register", "{register}", "machines"],
    "fha-studio register keys list": ["register", "--register", "{register}", "keys", "list"],
}


def measure(root: Path, runs: int) -> dict[str, list[dict]]:
    """Each command ``runs`` times (interleaved) in fresh processes; per command one dict a run."""
    tmp = Path(tempfile.mkdtemp(prefix="fha-cli-bench-"))
    env = {**os.environ, "XDG_DATA_HOME": str(tmp / "data"), "XDG_CONFIG_HOME": str(tmp / "config"),
           "PYTHONDONTWRITEBYTECODE": "1"}
    env.pop("FHA_STUDIO_REGISTER", None)
    register = tmp / "register.sqlite"
    subprocess.run([sys.executable, "-c", CHILD, str(root), "register", "--register", str(register),
                    "add-machine", "Line 3"], env=env, capture_output=True, timeout=120, check=False)
    out: dict[str, list[dict]] = {name: [] for name in COMMANDS}
    for _ in range(runs):
        for name, args in COMMANDS.items():
            argv = [a.replace("{register}", str(register)) for a in args]
            done = subprocess.run([sys.executable, "-c", CHILD, str(root), *argv], env=env,
                                  capture_output=True, text=True, timeout=120, check=False)
            line = [ln for ln in done.stderr.splitlines() if ln.startswith("{")]
            if not line:
                raise RuntimeError(f"{name}: {done.stderr[-500:]}")
            out[name].append(json.loads(line[-1]))
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="?", type=int, default=9)
    parser.add_argument("--root", type=Path, default=ROOT, help="the checkout to measure")
    args = parser.parse_args()
    try:
        results = measure(args.root.resolve(), args.runs)
    except RuntimeError as exc:
        print(exc, file=sys.stderr)
        return 1
    load = os.getloadavg()[0]
    print(f"CLI start-up of {args.root.resolve()}, {args.runs} fresh processes each, load average {load:.1f} "
          "(median [min-max] of the wall time, then of the CPU time):")
    for name, runs in results.items():
        times, cpu = [r["s"] for r in runs], [r["cpu_s"] for r in runs]
        last = runs[-1]
        print(f"  {name:<30} {statistics.median(times):5.2f} s [{min(times):.2f}-{max(times):.2f}]"
              f"  CPU {statistics.median(cpu):5.2f} s [{min(cpu):.2f}-{max(cpu):.2f}]"
              f"  {last['modules']} modules, register store {'yes' if last['store'] else 'no'},"
              f" cryptography {'yes' if last['cryptography'] else 'no'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
