"""What the register's worker threads share about their connection to a server (no window of
its own): how long they wait for it, its socket (shut from another thread, so that a server that
hangs cannot hold a thread), and a server's error as a window says it."""

from __future__ import annotations

import contextlib
import os
import re
import socket

from fha_studio.logic.register import Register

#: Closing waits at most this long [ms] for each thread (the facts are in the file by then).
CLOSE_WAIT_MS = 10000
#: A connection to the server waits at most this long [s] for the server's first answer.
CONNECT_TIMEOUT_S = 5.0


def server_socket(register: Register) -> int:
    """The socket of a register's connection to its server (-1 when there is none)."""
    connection = getattr(getattr(register, "_db", None), "_conn", None)  # psycopg's Connection
    try:
        return int(connection.pgconn.socket) if connection is not None else -1
    except Exception:
        return -1


def shut_socket(fd: int) -> None:
    """From any thread: the connection on socket ``fd`` (-1: none) is shut, so that whatever waits
    on it in another thread gives up at once (a server that hangs, or a network gone without a
    word, cannot hold that thread)."""
    if fd >= 0:
        with contextlib.suppress(OSError), socket.socket(fileno=os.dup(fd)) as shared:
            shared.shutdown(socket.SHUT_RDWR)


def without_nothing_changed(problem: str) -> str:
    """A register's error without what it adds for a command ("nothing was changed; try again
    when it is back"), which a window that keeps its facts and asks again does not need."""
    return re.sub(r": nothing was changed(; try again when it is back)?$", "", problem)
