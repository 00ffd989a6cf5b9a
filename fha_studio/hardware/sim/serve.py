"""Serving a simulated drive to another process: over a pseudo-terminal or a TCP socket.

Both loops move bytes between a file descriptor and a :class:`SimProtocolServer` until ``stop``
is set; the drive runs in real time in its own thread meanwhile.
"""

from __future__ import annotations

import contextlib
import os
import select
import socket
import threading
import tty
from collections.abc import Callable

from fha_studio.hardware.sim.server import SimProtocolServer

_POLL_S = 0.005  # longest wait between looks (a deferred reply such as OWW's is not foreseen)


class PtyEndpoint:
    """A pseudo-terminal pair in raw mode: the host opens :attr:`path`, the sim uses the master.

    The sim keeps the slave open too, so a host that closes and re-opens the path finds the drive
    still there (as with a real serial port).
    """

    def __init__(self) -> None:
        self.master_fd, self.slave_fd = os.openpty()
        # raw: no echo, no CR -> LF translation, bytes as they are (a serial line)
        tty.setraw(self.slave_fd)
        tty.setraw(self.master_fd)
        os.set_blocking(self.master_fd, False)
        self.path = os.ttyname(self.slave_fd)

    def close(self) -> None:
        for fd in (self.master_fd, self.slave_fd):
            with contextlib.suppress(OSError):
                os.close(fd)


def _wait_s(server: SimProtocolServer) -> float:
    event = server.next_event_s()
    return _POLL_S if event is None else min(max(event, 0.0), _POLL_S)


def serve_fd(server: SimProtocolServer, fd: int, stop: threading.Event) -> None:
    """Move bytes between ``fd`` (non-blocking) and ``server`` until ``stop`` is set."""
    pending = b""
    while not stop.is_set():
        readable, _, _ = select.select([fd], [], [], _wait_s(server))
        if readable:
            try:
                data = os.read(fd, 4096)
            except (BlockingIOError, InterruptedError):
                data = b""
            except OSError:  # EIO: no host has the slave open (only our own copy)
                data = b""
            if data:
                server.feed(data)
        pending += server.read_ready()
        if pending:
            try:
                written = os.write(fd, pending)
            except (BlockingIOError, InterruptedError):
                written = 0
            pending = pending[written:]


def serve_pty(server: SimProtocolServer, stop: threading.Event,
              announce: Callable[[str], None]) -> None:
    """Serve on a new pty; ``announce(path)`` is called once it can be opened."""
    endpoint = PtyEndpoint()
    try:
        announce(endpoint.path)
        serve_fd(server, endpoint.master_fd, stop)
    finally:
        endpoint.close()


def serve_tcp(server: SimProtocolServer, port: int, stop: threading.Event,
              announce: Callable[[str], None], host: str = "127.0.0.1") -> None:
    """Serve ``socket://host:port``, one host connection at a time (as one serial cable)."""
    listener = socket.create_server((host, port))
    listener.settimeout(0.1)
    try:
        announce(f"socket://{host}:{listener.getsockname()[1]}")
        while not stop.is_set():
            try:
                conn, _ = listener.accept()
            except TimeoutError:
                continue
            with conn:
                conn.setblocking(False)
                conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                _serve_socket(server, conn, stop)
    finally:
        listener.close()


def _serve_socket(server: SimProtocolServer, conn: socket.socket, stop: threading.Event) -> None:
    server.reset_output()
    while not stop.is_set():
        readable, _, _ = select.select([conn], [], [], _wait_s(server))
        if readable:
            try:
                data = conn.recv(4096)
            except (BlockingIOError, InterruptedError):
                data = None
            except OSError:
                return
            if data == b"":
                return  # the host hung up
            if data:
                server.feed(data)
        out = server.read_ready()
        if out:
            try:
                conn.sendall(out)
            except OSError:
                return
