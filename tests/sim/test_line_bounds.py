"""The simulated drive's line is bounded like a serial adapter's buffers: a flood neither grows
memory nor keeps the drive busy after the sender has gone, and no byte of one connection reaches
the next."""

from __future__ import annotations

import socket
import threading
import time
import tracemalloc

import pytest

from fha_studio.hardware.protocol import character_time_s
from fha_studio.hardware.sim import SimProtocolServer
from fha_studio.hardware.sim.serve import serve_tcp
from fha_studio.hardware.sim.server import INPUT_BACKLOG_BYTES
from tests.support.clock import FakeClock

IDN_REPLY = b"HA-655-2-200\rFHA-25C-50-US250\rFHA Studio simulated drive"


def _time_to_answer(server: SimProtocolServer, clock: FakeClock, limit_s: float) -> float:
    """Line seconds until IDN is answered, asked as a client does: again every 0.2 s."""
    start, got = clock.now, b""
    while IDN_REPLY not in got:
        assert clock.now - start < limit_s, f"IDN not answered within {limit_s} s of line time"
        if round((clock.now - start) / 0.2, 6) % 1 == 0:
            server.reset_output()
            server.feed(b"IDN+00000\r")
        clock.now += 0.01
        got += server.read_ready()
    return clock.now - start


def test_a_megabyte_burst_grows_memory_by_little_and_is_counted(make_drive):
    clock = FakeClock()
    server = SimProtocolServer(make_drive(), clock=clock)
    burst = b"A" * 1_000_000
    tracemalloc.start()
    try:
        for i in range(0, len(burst), 4096):  # as the pty or socket loop hands it over
            server.feed(burst[i:i + 4096])
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 5_000_000  # was about 150 MB: one queue entry per byte
    assert server.overrun_bytes == len(burst) - INPUT_BACKLOG_BYTES


@pytest.mark.parametrize("burst_bytes", [20_000, 1_000_000])
def test_the_drive_answers_soon_after_a_burst(make_drive, burst_bytes):
    """After a burst the next command is answered within the bounded backlog's line time
    (about half a second), not after the whole burst has crawled through (10 s for 20 kB)."""
    clock = FakeClock()
    server = SimProtocolServer(make_drive(), clock=clock)
    burst = b"garbage!" * (burst_bytes // 8)
    for i in range(0, len(burst), 4096):
        server.feed(burst[i:i + 4096])
    waited = _time_to_answer(server, clock, limit_s=30.0)
    assert waited < INPUT_BACKLOG_BYTES * character_time_s() + 0.5


@pytest.fixture
def tcp_drive(make_drive):
    server = SimProtocolServer(make_drive(), paced=True)
    stop = threading.Event()
    address: list[str] = []
    ready = threading.Event()

    def announce(url: str) -> None:
        address.append(url)
        ready.set()

    thread = threading.Thread(target=serve_tcp, args=(server, 0, stop, announce), daemon=True)
    thread.start()
    assert ready.wait(10)
    host, port = address[0].removeprefix("socket://").split(":")
    yield server, (host, int(port))
    stop.set()
    thread.join(10)


def _ask(conn: socket.socket, frame: bytes, wanted: bytes, limit_s: float = 15.0) -> bytes:
    conn.sendall(frame)
    conn.settimeout(0.5)
    got, deadline = b"", time.monotonic() + limit_s
    while not (wanted in got and got.endswith(b"q\r")) and time.monotonic() < deadline:
        try:
            chunk = conn.recv(4096)
        except TimeoutError:
            continue
        if not chunk:
            break
        got += chunk
    return got


def test_nothing_of_a_closed_connection_reaches_the_next(tcp_drive, time_ceiling):
    _server, address = tcp_drive
    with socket.create_connection(address, timeout=10) as first:
        first.sendall(b"x" * 100_000)  # a flood (most of it dropped) ...
        first.sendall(b"PSL+00008\rPRD+000")  # ... a command whose reply it never reads, half a frame
    with socket.create_connection(address, timeout=10) as second:
        started = time.monotonic()
        got = _ask(second, b"00\rIDN+00000\r", IDN_REPLY)
        # the first host's half frame did not join this one's "00\r": the only reply is to IDN
        assert got.startswith(IDN_REPLY), got[:80]
        # the bound backlog's line time is asserted on a fake clock above; here only a hang fails
        time_ceiling("the next host's answer after a flood", time.monotonic() - started, 10.0)


def test_a_second_host_is_told_at_once_that_the_line_is_taken(tcp_drive):
    _server, address = tcp_drive
    with socket.create_connection(address, timeout=10) as first:
        assert _ask(first, b"IDN+00000\r", IDN_REPLY).startswith(IDN_REPLY)
        with socket.create_connection(address, timeout=10) as second:
            second.settimeout(10)
            with _closed() as closed:
                second.sendall(b"CAP+00000\r")
                closed.data = second.recv(100)
            assert closed.data == b""
        assert _ask(first, b"IDN+00000\r", IDN_REPLY).startswith(IDN_REPLY)  # the first goes on


class _closed:
    """Either an orderly close (recv gives b"") or a reset: both tell the host the line is taken."""

    data: bytes | None = None

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if kind is not None and issubclass(kind, ConnectionResetError | BrokenPipeError):
            self.data = b""
            return True
        return False


def test_the_next_client_after_a_flood_finds_every_capability(tcp_drive):
    """A host floods the line and leaves; the next DriveClient.open probes CAP and finds MON,
    instead of reading the flood's late answers as the probe's."""
    from fha_studio.hardware.client import DriveClient
    from fha_studio.hardware.protocol import Command

    _server, (host, port) = tcp_drive
    with socket.create_connection((host, port), timeout=10) as flooder:
        flooder.sendall(b"IDN+00000\rCAP+00000\r" * 1000)  # 20 kB of commands it never reads
    client = DriveClient.open(f"socket://{host}:{port}")
    try:
        assert client.capabilities.supports(Command.MON)
        assert client.capabilities.supports(Command.CAP)
    finally:
        client.close()
