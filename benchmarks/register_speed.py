"""How fast the register records and answers, on this disk (prints figures).

Run from the checkout: PYTHONPATH=. python benchmarks/register_speed.py [DIR]

Every fact is one transaction committed with ``synchronous=FULL`` (it survives a crash), so a
write costs about one fsync of the disk the register is on. A commissioning session writes a few
facts per minute; the figures say how far that is from a limit, and how long the plant's
questions take on a register of a machine park (50 axes, 10 years of history at 4 entries a day).
"""

from __future__ import annotations

import random
import sys
import tempfile
import time
from pathlib import Path

from fha_studio.logic.register import Register
from fha_studio.logic.register.connection import FACT_ID_MARKS, FACT_IDS

ITEMS = [("tune", n, f"tune_{n}", 0) for n in range(6)] + [("system", n, f"system_{n}", 0) for n in range(8)]


def timed(fn, n: int = 1) -> float:
    """Seconds per call."""
    t0 = time.perf_counter()
    for _ in range(n):
        fn()
    return (time.perf_counter() - t0) / n


def main() -> None:
    base = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="fha-register-bench-"))
    reg = Register(base / "bench.sqlite")
    reg.add_machine("park")
    axes = [reg.add_axis("park", f"axis {i}", "FHA-25C-50-US250").ref for i in range(50)]
    rng = random.Random(1)

    def snapshot() -> None:
        values = [(m, n, k, rng.randint(0, 1)) for m, n, k, _ in ITEMS]
        reg.record_snapshot(rng.choice(axes), values, "link", who="bench")

    def write() -> None:
        reg.record_write(rng.choice(axes), "system", 8, "system_8", 1, 0, 1, True, who="bench")

    s_snapshot = timed(snapshot, 200)
    s_write = timed(write, 200)
    print(f"register on {base}")
    print(f"snapshot of {len(ITEMS)} values: {s_snapshot * 1000:.2f} ms each ({1 / s_snapshot:,.0f}/s)")
    print(f"verified write: {s_write * 1000:.2f} ms each ({1 / s_write:,.0f}/s)")

    # a machine park's history: 50 axes x 10 years x 4 entries a day, in one transaction per axis
    per_axis = 10 * 365 * 4
    t0 = time.perf_counter()
    for ref in axes:
        axis_id = reg.axis(ref).id
        with reg._transaction() as db:
            db.executemany(
                "INSERT INTO parameter_write (axis_id, at_utc, who, mode, number, key, old, new, read_back,"
                f" verified, {FACT_IDS}) VALUES (?, ?, 'bench', 'system', 8, 'system_8', 0, ?, ?, 1,"
                f" {FACT_ID_MARKS})",
                [
                    (axis_id, f"2016-01-01T00:00:{i % 60:02d}.{i:06d}+00:00", i % 2, i % 2, *reg._fact_ids())
                    for i in range(per_axis)
                ],
            )
    filled = time.perf_counter() - t0
    total = per_axis * len(axes)
    size_mb = (base / "bench.sqlite").stat().st_size / 1e6
    print(f"filled {total:,} entries in {filled:.1f} s ({size_mb:.0f} MB with the WAL checkpointed or not)")
    print(
        f"history of one axis ({per_axis:,} entries): {timed(lambda: reg.history(axes[7]), 3) * 1000:.0f} ms"
    )
    print(
        f"find system_8 = 1 over {len(axes)} axes: {timed(lambda: reg.find('system_8', 1), 3) * 1000:.0f} ms"
    )
    a, b = reg.parameter_set(axes[3]), reg.parameter_set(axes[4])
    print(f"diff of two axes' latest values: {timed(lambda: Register.diff(a, b), 100) * 1000:.2f} ms")
    print(f"open items of the park: {timed(lambda: reg.open_items('park'), 3) * 1000:.0f} ms")
    reg.close()


if __name__ == "__main__":
    main()
