"""Trace read-out: samples per second from a finished drive-side capture to the host.

Run: python benchmarks/trace_readout.py [--samples N]

A 4-channel capture (feedback and command position, speed, current) at 1 kHz of a 90 deg move
at 30 r/min on the embedded simulated drive paced like the 19200 bit/s line, read out by
``DriveClient.read_trace`` twice: from a drive that offers the packed block encoding (``TRP``,
announced in ``CAP``) and from one that offers only the text blocks (``TRB``, an older drive).
Prints samples/s, the line's characters per sample and the speed-up; nothing is asserted.
"""

from __future__ import annotations

import argparse
import time

from fha_studio.hardware import protocol as p
from fha_studio.hardware.client import DriveClient

ACTUATOR = "FHA-25C-50-US250"
ITEMS = (100, 101, 103, 104)


def readout(packed: bool, samples: int = 1024, rate_divider: int = 5) -> dict:
    """Capture a move and read it out; {"rate": samples/s, "seconds", "chars_per_sample", "packed"}."""
    url = f"sim://{ACTUATOR}?packed_trace={int(packed)}"
    counter = {"chars": 0}
    with DriveClient.open(url) as client:
        client.servo(True)
        client.set_move_speed(30.0)
        client.configure_trace(ITEMS, divider=rate_divider)
        client.arm_trace(samples)
        client.move_by(90.0)
        deadline = time.monotonic() + 60
        while client.trace_status().state is not p.TraceState.DONE:
            if time.monotonic() > deadline:
                raise SystemExit("the capture did not finish within 60 s")
            time.sleep(0.05)
        def count(_sending: bool, data: bytes) -> None:
            counter["chars"] += len(data)

        client.trace_packet = count
        start = time.monotonic()
        capture = client.read_trace()
        seconds = time.monotonic() - start
        client.trace_packet = None
        used = client.trace_encoding if hasattr(client, "trace_encoding") else "text"
    return {"rate": len(capture.samples) / seconds, "seconds": seconds, "samples": len(capture.samples),
            "chars_per_sample": counter["chars"] / len(capture.samples), "encoding": used}


def speedup(samples: int = 1024) -> dict:
    text = readout(False, samples)
    packed = readout(True, samples)
    return {"text": text, "packed": packed, "speedup": packed["rate"] / text["rate"]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--samples", type=int, default=1024, help="samples per capture (4 channels)")
    args = parser.parse_args()
    r = speedup(args.samples)
    for name in ("text", "packed"):
        x = r[name]
        print(f"  {name:6s} ({x['encoding']}): {x['samples']} samples x 4 channels in {x['seconds']:.1f} s = "
              f"{x['rate']:.0f} samples/s, {x['chars_per_sample']:.1f} line characters per sample")
    print(f"  speed-up {r['speedup']:.2f}x")


if __name__ == "__main__":
    main()
