"""Link throughput: CN3 transactions per second against the 19200 8N1 limit, and trace readout.

Run from the checkout: PYTHONPATH=. python benchmarks/link_throughput.py [--seconds 3]

Starts ``fha-studio sim --pty`` (paced like a 19200 baud line) in its own process and measures
over the pty:

1. raw request/reply transactions per second (pyserial, one command in flight), for a short
   reply (``ALM`` -> ``0 q``) and a long one (``MMR`` of 4 monitor items), next to the limit
   ``1920 / (10 + reply characters)`` transactions/s of a half-duplex exchange at 1920 chars/s;
2. the same through DriveClient (its locking, timeouts and reply checks included), if present;
3. trace capture: samples per second delivered by TRB (text blocks) and TRP (packed blocks), 4
   channels and 1 channel, next to the line's limit for the characters actually sent.
Also once unpaced (memory speed), to show what the software itself costs.
"""

from __future__ import annotations

import argparse
import os
import select
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import serial

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from fha_studio.hardware import protocol as p  # noqa: E402

CHARS_PER_S = p.BAUDRATE / p.BITS_PER_CHARACTER


def start_sim(eeprom: Path, paced: bool) -> tuple[subprocess.Popen, str]:
    cmd = [sys.executable, "-m", "fha_studio", "sim", "--pty", "--eeprom", str(eeprom)]
    if not paced:
        cmd.append("--unpaced")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env)
    ready, _, _ = select.select([proc.stdout], [], [], 30.0)
    if not ready:
        proc.kill()
        raise SystemExit("the sim did not start within 30 s")
    return proc, proc.stdout.readline().decode().strip()


def transact(port: serial.Serial, frame: bytes) -> bytes:
    port.write(frame)
    return port.read_until(b"q\r")


def raw_rate(port: serial.Serial, frame: bytes, seconds: float) -> tuple[float, int]:
    reply = transact(port, frame)
    n = 0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        transact(port, frame)
        n += 1
    return n / (time.perf_counter() - start), len(reply)


def client_rate(path: str, seconds: float) -> float | None:
    try:
        from fha_studio.hardware.client import DriveClient
    except ImportError:
        return None
    with DriveClient.open(path) as client:
        n = 0
        start = time.perf_counter()
        while time.perf_counter() - start < seconds:
            client.alarm()
            n += 1
        return n / (time.perf_counter() - start)


def trace_rate(port: serial.Serial, mask: int, samples: int, command: str = "TRB") -> tuple[float, float]:
    """(samples/s delivered by ``command`` (TRB or TRP), the line's limit for the characters sent)."""
    for frame in (f"TCH+{mask:05d}\r", "TDV+00001\r", "TTG+00000\r", "TPR+00000\r", f"TAR+{samples:05d}\r"):
        assert transact(port, frame.encode()).endswith(b"q\r"), frame
    while not transact(port, b"TST+00000\r").startswith(b"3,"):
        time.sleep(0.01)
    chars = 0
    start = time.perf_counter()
    for block in range((samples + 63) // 64):
        reply = transact(port, f"{command}+{block:05d}\r".encode())
        chars += 10 + len(reply)
    elapsed = time.perf_counter() - start
    return samples / elapsed, samples / (chars / CHARS_PER_S)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--seconds", type=float, default=3.0, help="duration of each rate measurement")
    args = parser.parse_args()
    mmr = f"MMR+{p.monitor_mask([100, 101, 103, 104]) if hasattr(p, 'monitor_mask') else 0b11011:05d}\r"
    with tempfile.TemporaryDirectory() as tmp:
        for paced in (True, False):
            proc, path = start_sim(Path(tmp) / f"eeprom-{paced}.json", paced)
            try:
                print(f"== sim over a pty, {'paced at 19200 8N1' if paced else 'unpaced (memory speed)'}")
                with serial.Serial(path, p.BAUDRATE, timeout=2.0) as port:
                    transact(port, b"SVO+00001\r")
                    for name, frame in (("ALM", b"ALM+00000\r"), ("MMR x4", mmr.encode())):
                        rate, reply_chars = raw_rate(port, frame, args.seconds)
                        limit = CHARS_PER_S / (10 + reply_chars)
                        print(f"  raw {name:7s} {rate:8.1f} transactions/s   limit {limit:6.1f}/s "
                              f"({10 + reply_chars} chars each)   {100 * rate / limit:5.1f} % of the limit")
                    for label, mask in (("4 channels", 0b11011), ("1 channel", 0b1)):
                        for command in ("TRB", "TRP"):
                            delivered, limit = trace_rate(port, mask, 1024 if paced else 4096, command)
                            print(f"  trace {command} {label:10s} {delivered:8.1f} samples/s   "
                                  f"line limit {limit:8.1f} samples/s")
                rate = client_rate(path, args.seconds)
                if rate is None:
                    print("  DriveClient: not available")
                else:
                    limit = CHARS_PER_S / (10 + 4)
                    print(f"  DriveClient.alarm() {rate:8.1f} transactions/s   limit {limit:6.1f}/s")
            finally:
                proc.terminate()
                proc.wait(5)


if __name__ == "__main__":
    main()
