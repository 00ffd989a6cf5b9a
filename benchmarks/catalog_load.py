"""How long the catalogue takes: first load of every table and every actuator, then cached look-ups.

Run: python benchmarks/catalog_load.py  (prints figures; nothing is asserted).
"""

from __future__ import annotations

import time

from fha_studio.catalog import all_model_codes, get_actuator, parse_model_code


def main() -> None:
    t0 = time.perf_counter()
    codes = all_model_codes()
    for code in codes:
        get_actuator(code)
    cold = time.perf_counter() - t0
    n = 20_000
    t0 = time.perf_counter()
    for i in range(n):
        get_actuator(codes[i % len(codes)])
    warm = (time.perf_counter() - t0) / n
    t0 = time.perf_counter()
    for _ in range(n):
        parse_model_code("FHA-17C-50-US250-B-L-F5")
    parse = (time.perf_counter() - t0) / n
    print(f"cold load of all tables + {len(codes)} actuators: {cold * 1e3:.1f} ms")
    print(f"cached get_actuator(str): {warm * 1e6:.1f} us")
    print(f"parse_model_code with 3 options: {parse * 1e6:.1f} us")


if __name__ == "__main__":
    main()
