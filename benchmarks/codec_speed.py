"""How fast the CN3 codec is, against what the line can carry (19200 bit/s 8N1 = 1920 characters/s).

Run from the checkout: PYTHONPATH=. python benchmarks/codec_speed.py (prints figures). Also the cost of
the client's transaction layer over an in-process pipe (no line pacing): the overhead FHA Studio
adds on top of the line's own time.
"""

from __future__ import annotations

import time

from fha_studio.hardware import protocol as p
from fha_studio.hardware.client import DriveClient, LinkSettings
from fha_studio.hardware.transport import pipe_pair
from tests.support.scripted import ScriptedDrive


def rate(fn, n: int) -> float:
    t0 = time.perf_counter()
    for _ in range(n):
        fn()
    return n / (time.perf_counter() - t0)


def main() -> None:
    line_chars_s = p.BAUDRATE / p.BITS_PER_CHARACTER
    frame = p.Request(p.Command.MMR, 9).encode()
    reply = p.Reply(("123456,-1250",)).encode()
    trb = p.Reply(tuple("1,2,3,4" for _ in range(p.TRACE_BLOCK_SAMPLES))).encode()
    n = 20_000
    enc = rate(lambda: p.Request(p.Command.MMR, 9).encode(), n)
    dec_req = rate(lambda: p.decode_request(frame), n)
    dec_rep = rate(lambda: p.decode_reply(reply), n)
    dec_trb = rate(lambda: p.decode_reply(trb), 2000)
    print(f"line limit: {line_chars_s:.0f} characters/s")
    print(f"encode request: {enc:,.0f}/s = {enc * 10 / line_chars_s:,.0f} x the line")
    print(f"decode request: {dec_req:,.0f}/s = {dec_req * 10 / line_chars_s:,.0f} x the line")
    mmr_x = dec_rep * len(reply) / line_chars_s
    trb_x = dec_trb * len(trb) / line_chars_s
    print(f"decode reply (MMR, {len(reply)} chars): {dec_rep:,.0f}/s = {mmr_x:,.0f} x the line")
    print(f"decode TRB block ({len(trb)} chars): {dec_trb:,.0f}/s = {trb_x:,.1f} x the line")

    host, drive_end = pipe_pair("bench")
    drive = ScriptedDrive(drive_end, lambda r: p.Reply(("0",)))
    client = DriveClient(host, LinkSettings())
    try:
        m = 2000
        t0 = time.perf_counter()
        for _ in range(m):
            client._transact(p.Command.ALM, parse=lambda r: r)
        tx = m / (time.perf_counter() - t0)
        chars = 10 + 4
        print(f"client transactions over an unpaced pipe: {tx:,.0f}/s "
              f"(the line allows {line_chars_s / chars:.0f}/s for {chars} characters)")
    finally:
        client.close()
        drive.close()


if __name__ == "__main__":
    main()
