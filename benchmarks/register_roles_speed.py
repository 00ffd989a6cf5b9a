"""What the roles' checks cost a write on a PostgreSQL server (prints figures).

Run from the checkout: PYTHONPATH=. python benchmarks/register_roles_speed.py [FACTS]

Starts a throw-away cluster (as the tests do: tests/support/postgres.py) with two registers: one
used by its owner without roles, one with its roles set up, written by a technician's login (each
fact then also checked for its times and given its receipt by the server). Per register: one
alarm per transaction and one snapshot of 100 values per transaction (the median of FACTS each,
300), then twenty writers at once, each on its own connection, 20 snapshots of 20 values each.
"""

from __future__ import annotations

import contextlib
import statistics
import sys
import threading
import time

from fha_studio.logic.register import Register
from fha_studio.logic.register.roles_admin import grant, setup

AXIS = "Bench/axis"


def _median_ms(fn, n: int) -> float:
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1000 * statistics.median(times)


def _concurrent(url: str, writers: int = 20, each: int = 20) -> float:
    """Facts a second with ``writers`` writing at once."""
    start = threading.Barrier(writers + 1, timeout=60)

    def write(n: int) -> None:
        with Register(url) as reg:
            start.wait()
            for k in range(each):
                reg.record_snapshot(AXIS, [("tune", i, f"item_{i}", n + k) for i in range(20)], "link")

    threads = [threading.Thread(target=write, args=(n,)) for n in range(writers)]
    for t in threads:
        t.start()
    start.wait()
    t0 = time.perf_counter()
    for t in threads:
        t.join(timeout=300)
    return writers * each / (time.perf_counter() - t0)


def measure(url: str, facts: int) -> dict[str, float]:
    with Register(url) as reg:
        alarm = _median_ms(lambda: reg.record_alarm(AXIS, 10, "overspeed"), facts)
        values = [("tune", i, f"item_{i}", i) for i in range(100)]
        snapshot = _median_ms(lambda: reg.record_snapshot(AXIS, values, "link"), facts)
    return {"alarm_ms": alarm, "snapshot_100_ms": snapshot, "concurrent_per_s": _concurrent(url)}


def main() -> None:
    import psycopg

    from tests.support.postgres import SUPER_PASSWORD, throwaway_cluster

    facts = int(sys.argv[1]) if len(sys.argv) > 1 else 300
    with contextlib.ExitStack() as stack:
        cluster = stack.enter_context(throwaway_cluster())
        with psycopg.connect(cluster.url("postgres", "postgres", SUPER_PASSWORD), autocommit=True) as db:
            db.execute("ALTER ROLE fha CREATEROLE")
            db.execute("CREATE ROLE bench_technician LOGIN PASSWORD 'bench'")
        figures = {}
        for name, roles in (("owner, no roles", False), ("technician, roles", True)):
            url = cluster.new_database()
            with Register(url) as reg:
                reg.add_machine("Bench")
                reg.add_axis("Bench", "axis", "FHA-25C-50-US250")
            if roles:
                setup(url)
                grant(url, "bench_technician", "technician", "Bench Technician")
                url = url.replace("fha:fha-test-password@", "bench_technician:bench@")
            figures[name] = measure(url, facts)
    print(f"register writes on a PostgreSQL server (median of {facts}; twenty writers x 20 snapshots):")
    for name, f in figures.items():
        print(f"  {name:<18}  alarm {f['alarm_ms']:5.2f} ms   snapshot of 100 values "
              f"{f['snapshot_100_ms']:6.2f} ms   twenty writers {f['concurrent_per_s']:6.0f} snapshots/s")


if __name__ == "__main__":
    main()
