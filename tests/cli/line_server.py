"""A line at the far end of a pty, run as its own process: ``python line_server.py MODE [options]``.

Prints the pty path, then serves until killed. MODE:
- ``documented``: a drive of the public HA-655 manual (``tests.support.documented.DocumentedDrive``):
  DGR and OWW, ``x`` to anything else, ``s`` to everything while the servo is on (``--servo-on``);
  ``--incremental`` answers ``x`` to DGR and OWW; OWW acknowledges ``--oww-s`` later and clears
  the multi-turn data.
- ``silent``: reads, never answers (a drive switched off).
- ``flood``: sends garbage without end.
- ``slow``: trickles a digit every 0.2 s without ever ending a reply (a line that never goes quiet).
- ``garbage``: answers each request with a malformed reply.
"""

from __future__ import annotations

import argparse
import os
import select
import signal
import sys
import time
import tty

from fha_studio.hardware import protocol as p
from tests.support.documented import DocumentedDrive


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("mode", choices=("documented", "silent", "flood", "slow", "garbage"))
    parser.add_argument("--servo-on", action="store_true")
    parser.add_argument("--incremental", action="store_true")
    parser.add_argument("--position", type=int, default=3 * 8192 + 1234)
    parser.add_argument("--oww-s", type=float, default=1.0)
    args = parser.parse_args()

    master, slave = os.openpty()
    tty.setraw(master)
    tty.setraw(slave)
    os.set_blocking(master, False)
    print(os.ttyname(slave), flush=True)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))

    decoder = p.StreamDecoder(p.decode_request)
    drive = DocumentedDrive(args.position, servo_on=args.servo_on, incremental=args.incremental,
                            oww_s=args.oww_s)
    out = b""
    next_trickle = time.monotonic()

    while True:
        readable, _, _ = select.select([master], [], [], 0.01)
        data = b""
        if readable:
            try:
                data = os.read(master, 4096)
            except (BlockingIOError, OSError):
                data = b""
        now = time.monotonic()
        if args.mode == "flood":
            out += b"A\x00#" * 512
        elif args.mode == "slow" and now >= next_trickle:
            out += b"7"
            next_trickle = now + 0.2
        for message in decoder.feed(data) if data else ():
            if isinstance(message, p.Garbage) or args.mode in ("silent", "flood", "slow"):
                continue
            if args.mode == "garbage":
                out += b"?!\x7f\r"
                continue
            reply = drive.answer(message, now)
            out += reply.encode() if reply is not None else b""
        for reply in drive.due(now) if args.mode == "documented" else ():
            out += reply.encode()
        if out:
            try:
                written = os.write(master, out)
            except (BlockingIOError, OSError):
                written = 0
            out = out[written:]
            if args.mode == "flood":
                out = out[:4096]  # keep flooding, do not pile up


if __name__ == "__main__":
    raise SystemExit(main())
