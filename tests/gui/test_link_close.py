"""The window can be closed at any moment, even while it connects to a line that floods, trickles
or stays silent: the link thread ends (no "QThread: Destroyed while thread 'fha-link' is still
running" abort), and quickly, because the connect gives up at its next read."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator

import pytest

#: Only a hang takes this long (the close used to take a minute; typical figure:
#: benchmarks/timing_ceilings.py).
CLOSE_LIMIT_S = 8.0


class LineServer:
    """A TCP server on a free loopback port that answers every connection with ``pattern``
    (repeated without end; b"" = silence)."""

    def __init__(self, pattern: bytes):
        self.pattern = pattern
        self.accepted = threading.Event()
        self.stop = threading.Event()
        self.sock = socket.create_server(("127.0.0.1", 0))
        self.sock.settimeout(0.1)
        self.url = f"socket://127.0.0.1:{self.sock.getsockname()[1]}"
        self.thread = threading.Thread(target=self._run, name="line server", daemon=True)
        self.thread.start()

    def _run(self) -> None:
        conns = []
        while not self.stop.is_set():
            try:
                conn, _ = self.sock.accept()
            except TimeoutError:
                conn = None
            if conn is not None:
                conns.append(conn)
                self.accepted.set()
            for c in list(conns):
                if not self.pattern:
                    continue
                try:
                    c.sendall(self.pattern)
                except OSError:  # the client hung up
                    conns.remove(c)
                    c.close()
        for c in conns:
            c.close()

    def close(self) -> None:
        self.stop.set()
        self.thread.join(5)
        self.sock.close()


@pytest.fixture(params=[b"A" * 512, b"\0" * 512, b""], ids=["flood", "nul", "silent"])
def line(request) -> Iterator[LineServer]:
    server = LineServer(request.param)
    yield server
    server.close()


def test_the_window_closes_while_connecting_to_a_hostile_line(make_window, qtbot, line, time_ceiling):
    window = make_window()
    window.connect_to(line.url)
    qtbot.waitUntil(line.accepted.is_set, timeout=10000)  # the link thread is inside the connect
    window._closing_confirmed = True
    t0 = time.monotonic()
    window.close()
    elapsed = time.monotonic() - t0
    assert not window.link._thread.isRunning()
    time_ceiling("closing the window while it connects", elapsed, CLOSE_LIMIT_S)
    assert not window.link.connected


@pytest.mark.e2e
def test_the_program_exits_cleanly_when_closed_while_connecting_to_a_flood(tmp_path):
    """The whole program, in its own process: a TCP server that sends A without end, the GUI
    pointed at it, the window closed while it connects. It used to abort (exit 134, "QThread: Destroyed while
    thread 'fha-link' is still running")."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    server = LineServer(b"A" * 512)
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen", "PYTHONPATH": str(root),
           "XDG_CONFIG_HOME": str(tmp_path / "config"), "XDG_DATA_HOME": str(tmp_path / "data")}
    try:
        done = subprocess.run(
            [sys.executable, "-m", "fha_studio", "gui", "--url", server.url, "--quit-after-ms", "700"],
            cwd=root, env=env, capture_output=True, timeout=60,
        )
    finally:
        server.close()
    assert server.accepted.is_set()
    assert "QThread: Destroyed" not in done.stderr.decode()
    assert done.returncode == 0, done.stderr.decode()[-2000:]
