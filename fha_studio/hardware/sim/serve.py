"""Serving a simulated drive to another process: over a pseudo-terminal or a TCP socket.

Both loops move bytes between a file descriptor and a :class:`SimProtocolServer` until ``stop``
is set; the drive runs in real time in its own thread meanwhile.
"""

from __future__ import annotations

import contextlib
import os
import select
import socket
import struct
import threading
import time
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
    """Serve ``socket://host:port``, one host connection at a time (as one serial cable).

    Each connection starts on a clean line (:meth:`SimProtocolServer.reset`): nothing a previous
    host wrote or did not read reaches it. A host that connects while another is served is
    closed at once, so it learns that the line is taken instead of waiting for answers that
    would come from someone else's conversation.
    """
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
                server.reset()
                try:
                    _serve_socket(server, conn, stop, listener)
                finally:
                    server.reset()
    finally:
        listener.close()


def _serve_socket(server: SimProtocolServer, conn: socket.socket, stop: threading.Event,
                  listener: socket.socket | None = None) -> None:
    watched = [conn] if listener is None else [conn, listener]
    while not stop.is_set():
        readable, _, _ = select.select(watched, [], [], _wait_s(server))
        if listener is not None and listener in readable:
            # a host that hung up and connects again at once: finish the old connection first
            if not _take_input(server, conn, wait_s=0.2):
                return
            _refuse(listener)
        if conn in readable and not _take_input(server, conn):
            return  # the host hung up
        out = server.read_ready()
        if out:
            try:
                conn.sendall(out)
            except OSError:
                return


def _take_input(server: SimProtocolServer, conn: socket.socket, wait_s: float = 0.0) -> bool:
    """Feed what the host has sent (waiting up to ``wait_s`` for more); False once it hung up."""
    deadline = time.monotonic() + wait_s
    while True:
        try:
            data = conn.recv(65536)
        except (BlockingIOError, InterruptedError):
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return True
            select.select([conn], [], [], remaining)
            continue
        except OSError:
            return False
        if not data:
            return False
        server.feed(data)
        if wait_s == 0.0:
            return True


def _refuse(listener: socket.socket) -> None:
    """Accept and close a second host at once (the line is taken)."""
    try:
        extra, _ = listener.accept()
    except (TimeoutError, BlockingIOError, OSError):
        return
    with contextlib.suppress(OSError):
        extra.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))  # RST, not FIN
    extra.close()
