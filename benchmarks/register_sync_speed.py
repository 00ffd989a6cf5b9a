"""How fast a laptop's register syncs with the plant's register on a PostgreSQL server (prints
figures; target: 10,000 facts in under 5 s, each way).

Run from the checkout: PYTHONPATH=. python benchmarks/register_sync_speed.py [URL] [FACTS]

Without URL it starts a throw-away cluster of its own (as the tests do: tests/support/postgres.py,
a local socket, fsync off). A laptop's file is filled with FACTS facts (10,000) of 50 axes, as a
commissioning records them (:data:`MIX`: check answers, verified writes, procedure states, axis
entries, alarms, and 5 % parameter reads of 40 values each: 20,000 values beside the facts), and
once more with a fifth of the facts parameter reads (80,000 values). Then, each timed:

1. the laptop's file to an empty register on the server (every fact sent);
2. the server's register to a new laptop file (every fact received: "and back");
3. the same sync again (nothing to move: what a sync costs when both hold the same);
4. 100 new facts on the laptop, synced (a day's work after the big first sync).
"""

from __future__ import annotations

import contextlib
import random
import sys
import tempfile
import time
from pathlib import Path

from fha_studio.logic.register import Register
from fha_studio.logic.register.sync import SyncResult, sync_registers

AXES = 50
MACHINE = "Line 9"
VALUES = [("tune", n, f"tune_{n}", 0) for n in range(12)] + [
    ("system", n, f"system_{n}", 0) for n in range(28)
]


#: What a commissioning records, as shares of its facts (the machine window reads the parameters
#: once a connection and after a change; a procedure answers a check a step).
MIX = (("check", 0.35), ("write", 0.30), ("procedure", 0.12), ("note", 0.10), ("alarm", 0.08),
       ("snapshot", 0.05))
SNAPSHOT_HEAVY = (("check", 0.25), ("write", 0.25), ("procedure", 0.10), ("note", 0.10), ("alarm", 0.10),
                  ("snapshot", 0.20))


class _Check:
    def __init__(self, n: int, at: str):
        self.procedure_id, self.step_id, self.kind, self.section = "wiring", f"step-{n}", "measure", "4-2"
        self.text, self.value, self.expected, self.unit = "Insulation", 20.0 + n, ">= 10", "MΩ"
        self.passed, self.who, self.at_utc, self.detail = True, "bench", at, ""


def fill(path: Path, facts: int, rng: random.Random, start_day: int = 0,
         mix: tuple[tuple[str, float], ...] = MIX) -> int:
    """``facts`` facts into the file at ``path`` (one transaction), spread over the axes."""
    kinds, shares = zip(*mix, strict=True)
    with Register(path) as reg, reg.batch():
        refs = [reg.ensure_axis(MACHINE, f"axis {i}", actuator_code="FHA-25C-50-US250").ref
                for i in range(AXES)]
        made = 0
        while made < facts:
            ref = rng.choice(refs)
            at = f"2026-{1 + (start_day + made // 400) % 12:02d}-01T00:00:00.{made % 1_000_000:06d}+00:00"
            kind = rng.choices(kinds, shares)[0]
            if kind == "snapshot":
                reg.record_snapshot(ref, [(m, n, k, rng.randint(0, 100)) for m, n, k, _ in VALUES], "link",
                                    who="bench", at_utc=at)
            elif kind == "write":
                value = rng.randint(0, 100)
                reg.record_write(ref, "tune", 3, "tune_3", value, value - 1, value, True, who="bench",
                                 at_utc=at)
            elif kind == "check":
                reg.record_checks(ref, [_Check(made, at)])
            elif kind == "alarm":
                reg.record_alarm(ref, 20, "overload", who="bench", at_utc=at)
            elif kind == "note":
                reg.add_axis_note(ref, f"note {made}", who="bench", at_utc=at)
            else:
                reg.record_procedure_status(ref, "wiring", "Wiring", f"step {made}", at_utc=at)
            made += 1
    return made


def line(what: str, result: SyncResult, seconds: float) -> None:
    moved = result.sent + result.received
    rate = f", {moved / seconds:,.0f} facts/s" if moved else ""
    print(f"{what}: {seconds:.2f} s ({result.sent:,} sent, {result.received:,} received, "
          f"{result.already_there:,} already in both, {result.batches} batches{rate})")


def measure(url: str, facts: int, mix: tuple[tuple[str, float], ...], what: str) -> float:
    """The syncs of a laptop of ``facts`` facts of ``mix``; the longer of the first two (s)."""
    rng = random.Random(26)
    with tempfile.TemporaryDirectory() as folder:
        laptop, fresh = Path(folder) / "laptop.sqlite", Path(folder) / "fresh.sqlite"
        t0 = time.perf_counter()
        made = fill(laptop, facts, rng, mix=mix)
        size = laptop.stat().st_size / 1e6
        with Register(laptop) as reg:
            values = reg._db.execute("SELECT COUNT(*) FROM snapshot_value").fetchone()[0]
        print(f"{what}: a laptop's register of {made:,} facts of {AXES} axes and {values:,} snapshot values "
              f"({size:.1f} MB), filled in {time.perf_counter() - t0:.1f} s")
        for made_before in (url, fresh):  # the plant's register is there; a new file is made by the sync
            Register(made_before).close()
        timings = []
        for what, source, target in (
            ("laptop -> server (every fact sent)", laptop, url),
            ("server -> new laptop file (every fact received)", url, fresh),
            ("laptop -> server again (nothing to move)", laptop, url),
        ):
            t0 = time.perf_counter()
            result = sync_registers(source, target)
            seconds = time.perf_counter() - t0
            timings.append(seconds)
            line(what, result, seconds)
        fill(laptop, 100, rng, start_day=400 * 12, mix=mix)
        t0 = time.perf_counter()
        line("100 new facts on the laptop -> server", sync_registers(laptop, url), time.perf_counter() - t0)
    return max(timings[:2])


def main() -> None:
    url = sys.argv[1] if len(sys.argv) > 1 and "://" in sys.argv[1] else ""
    numbers = [int(a) for a in sys.argv[1:] if a.isdigit()]
    facts = numbers[0] if numbers else 10_000
    with contextlib.ExitStack() as stack:
        if not url:
            from tests.support.postgres import throwaway_cluster

            cluster = stack.enter_context(throwaway_cluster())
            url = cluster.new_database()
            heavy_url = cluster.new_database()
        else:
            heavy_url = ""
        seconds = measure(url, facts, MIX, "commissioning")
        verdict = "under" if seconds < 5.0 else "OVER"
        print(f"{facts:,} facts each way: {verdict} the 5 s target (the longer way: {seconds:.2f} s)")
        if heavy_url:
            print()
            measure(heavy_url, facts, SNAPSHOT_HEAVY, "a fifth of the facts parameter reads")


if __name__ == "__main__":
    main()
