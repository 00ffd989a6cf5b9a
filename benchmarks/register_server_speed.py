"""How fast a plant's register on a PostgreSQL server answers (prints figures; target < 0.5 s).

Run from the checkout: PYTHONPATH=. python benchmarks/register_server_speed.py [URL] [AXES] [PER_DAY]

Without URL it starts a throw-away cluster of its own (as the tests do: tests/support/postgres.py,
Debian's postgresql, run as ``postgres`` when this runs as root). The register holds AXES axes
(1000) with 10 years of facts each: PER_DAY verified writes a day (1) and a snapshot of 14 values
a month, filled on the server with INSERT ... SELECT (the register's own writes are timed
separately, one transaction each). Then ``find`` over every axis and one axis's ``history``, each
the best of three.
"""

from __future__ import annotations

import random
import sys
import time

from fha_studio.logic.register import Register
from fha_studio.logic.register.connection import FACT_IDS

ITEMS = [("tune", n, f"tune_{n}", 0) for n in range(6)] + [("system", n, f"system_{n}", 0) for n in range(8)]
YEARS = 10


def best(fn, n: int = 3) -> float:
    """The fastest of ``n`` calls, in seconds."""
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def fill(url: str, axes: int, per_day: int) -> tuple[list[str], int, float]:
    import psycopg

    with Register(url) as reg:
        reg.add_machine("park")
        refs = [reg.add_axis("park", f"axis {i}", "FHA-25C-50-US250").ref for i in range(axes)]
        register_id = reg.register_id
    t0 = time.perf_counter()
    at = "to_char(timestamptz '2016-01-01 00:00:00+00' + {}, 'YYYY-MM-DD\"T\"HH24:MI:SS.US\"+00:00\"')"
    write_at = at.format("d * interval '1 day' + k * interval '1 second'")
    snapshot_at = at.format("m * interval '30 days' + interval '12 hours'")
    with psycopg.connect(url, autocommit=True) as db:
        db.execute("SET TIME ZONE 'UTC'")
        # each fact its stable id, recorded in this register (as the register's own writes make
        # them), and its uid_hash in the same INSERT (the register's facts are never updated)
        number = "('x' || substr(uid, 1, 8))::bit(32)::bigint & 2147483647"
        ids = f"uid, '{register_id}', '2016-01-01T00:00:00.000000+00:00', {number}"
        db.execute(
            "INSERT INTO parameter_write (axis_id, at_utc, who, mode, number, key, old, new, read_back,"
            f" verified, {FACT_IDS}) SELECT id, at, 'bench', 'system', 8, 'system_8', old, new, new, 1,"
            f" {ids} FROM (SELECT a.id, {write_at} AS at, (d + a.id) %% 2 AS old, (d + a.id + 1) %% 2 AS new,"
            " gen_random_uuid()::text AS uid FROM axis a, generate_series(0, %s) d,"
            " generate_series(0, %s) k) f",
            (YEARS * 365 - 1, per_day - 1),
        )
        db.execute(
            f"INSERT INTO snapshot (axis_id, at_utc, who, source, {FACT_IDS}) SELECT id, at, 'bench',"
            f" 'link', {ids} FROM (SELECT a.id, {snapshot_at} AS at, gen_random_uuid()::text AS uid"
            " FROM axis a, generate_series(0, %s) m) f",
            (YEARS * 12 - 1,),
        )
        values = ", ".join(f"('{m}', {n}, '{k}')" for m, n, k, _ in ITEMS)
        db.execute(
            "INSERT INTO snapshot_value (snapshot_id, mode, number, key, value) SELECT s.id, i.mode,"
            f" i.number, i.key, (s.id + i.number) % 2 FROM snapshot s,"
            f" (VALUES {values}) AS i (mode, number, key)"
        )
        db.execute("VACUUM ANALYZE")
        rows = sum(
            db.execute(f"SELECT COUNT(*) FROM {t}").fetchone()[0]  # type: ignore[index]
            for t in ("parameter_write", "snapshot", "snapshot_value")
        )
    return refs, rows, time.perf_counter() - t0


def measure(url: str, axes: int, per_day: int) -> None:
    refs, rows, filled = fill(url, axes, per_day)
    print(f"register on the server: {axes} axes x {YEARS} years ({per_day} writes a day, a snapshot "
          f"of {len(ITEMS)} values a month): {rows:,} rows, filled in {filled:.1f} s "
          "(on the server, an INSERT ... SELECT a table)")
    with Register(url) as reg:
        rng = random.Random(2)
        t0 = time.perf_counter()
        for _ in range(100):
            reg.record_write(rng.choice(refs), "system", 8, "system_8", 1, 0, 1, True, who="bench")
        print(f"verified write (one transaction): {(time.perf_counter() - t0) * 10:.2f} ms each")
        found = reg.find("system_8", 1)
        s_find = best(lambda: reg.find("system_8", 1))
        print(f"find system_8 = 1 over {axes} axes ({len(found)} found): {s_find * 1000:.0f} ms")
        s_find_key = best(lambda: reg.find("tune_3"))
        print(f"find tune_3 (snapshots only) over {axes} axes: {s_find_key * 1000:.0f} ms")
        one = refs[min(7, len(refs) - 1)]  # an axis from the middle of the filling, when there are 8
        entries = len(reg.history(one))
        s_history = best(lambda: reg.history(one))
        print(f"history of one axis ({entries:,} entries): {s_history * 1000:.0f} ms")
        s_current = best(lambda: reg.current_values(one))
        print(f"latest known values of one axis: {s_current * 1000:.0f} ms")
    verdict = "under" if max(s_find, s_find_key, s_history) < 0.5 else "OVER"
    print(f"find and history: {verdict} the 0.5 s target")


def main() -> None:
    url = sys.argv[1] if len(sys.argv) > 1 and "://" in sys.argv[1] else ""
    numbers = [int(a) for a in sys.argv[1:] if a.isdigit()]
    axes = numbers[0] if numbers else 1000
    if axes < 1:
        sys.exit("register_server_speed: give at least one axis")
    per_day = numbers[1] if len(numbers) > 1 else 1
    from tests.support.postgres import given_or_throwaway

    with given_or_throwaway(url) as server:
        measure(server, axes, per_day)


if __name__ == "__main__":
    main()
