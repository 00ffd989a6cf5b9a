"""Live bench stream: samples per second sigrok-cli's demo driver delivers through
``fha_studio.hardware.bench.sigrok.Acquisition``, and how many it dropped (fell behind real time).

Run: python benchmarks/sigrok_stream.py [--seconds S] [--rate HZ ...] [--channels N]
(prints figures; nothing is asserted).

For each rate (default: 24 MHz, the common USB logic analyzers', and the demo driver's highest,
1 GHz) the demo streams N logic channels (default 8: one byte a sample) for S seconds (default 10).
``delivered``: samples handed over as blocks, per second of wall time. ``dropped``: what real
time asked for and never came (rate x seconds - delivered): the demo driver paces its pattern by
the clock, and a producer or a consumer too slow for the rate falls behind. A real instrument
that falls behind overruns its buffer instead, which sigrok-cli reports as an error.
"""

from __future__ import annotations

import argparse
import os
import time

from fha_studio.hardware.bench import sigrok


def stream(rate_hz: float, seconds: float, channels: int) -> dict[str, float]:
    names = [f"D{i}" for i in range(channels)]
    acquisition = sigrok.Acquisition("demo", names, rate_hz)
    acquisition.start()
    blocks = 0
    cpu0 = os.times()
    started = first = 0.0
    with acquisition:
        for block in acquisition.blocks():
            if not blocks:  # real time counts from the first block (sigrok-cli's start-up is not a drop)
                started, first = time.monotonic(), block.samples
            blocks += 1
            if time.monotonic() - started >= seconds:
                acquisition.stop()
    wall = time.monotonic() - started
    cpu = os.times()
    delivered = acquisition.samples - first
    asked = acquisition.sample_rate_hz * wall
    return {
        "rate_hz": acquisition.sample_rate_hz,
        "seconds": wall,
        "delivered_per_s": delivered / wall,
        "dropped_per_s": max(0.0, asked - delivered) / wall,
        "dropped_share": max(0.0, asked - delivered) / asked,
        "blocks_per_s": blocks / wall,
        "reader_cpu": (cpu.user - cpu0.user + cpu.system - cpu0.system) / wall,
        "sigrok_cpu": (cpu.children_user - cpu0.children_user + cpu.children_system
                       - cpu0.children_system) / wall,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--rate", type=float, action="append", help="sample rate [Hz] (repeatable)")
    parser.add_argument("--channels", type=int, default=8, help="logic channels (1 ... 16)")
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; sigrok-cli demo, "
          f"{args.channels} logic channels, {args.seconds:g} s each")
    for rate in args.rate or [24e6, 1e9]:
        f = stream(rate, args.seconds, args.channels)
        print(f"{sigrok.rate_text(f['rate_hz']):>8}: delivered {f['delivered_per_s'] / 1e6:7.2f} MS/s, "
              f"dropped {f['dropped_per_s'] / 1e6:7.2f} MS/s ({100 * f['dropped_share']:.1f} %), "
              f"{f['blocks_per_s']:.0f} blocks/s; CPU: reader {100 * f['reader_cpu']:.0f} %, "
              f"sigrok-cli {100 * f['sigrok_cpu']:.0f} % of a core")


if __name__ == "__main__":
    main()
