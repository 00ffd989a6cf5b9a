"""Byte transports to a drive: pyserial URLs, and an in-process pipe pair for tests and the sim.

``open_transport(url)`` opens anything ``serial.serial_for_url`` knows: a device (``/dev/ttyUSB0``,
``COM3``), a pty path, ``socket://host:port``, ``loop://``, and ``sim://ACTUATOR-CODE?...`` (the
embedded simulated drive; the handler module is ``fha_studio.hardware.sim.protocol_sim`` by
pyserial's naming rule). What it returns is a ``GuardedTransport``: the same calls as a pyserial
port, but a vanished port (unplugged adapter, closed pty or socket peer) raises ``LinkLost``
naming the port instead of a bare ``SerialException`` / ``OSError``.

``pipe_pair()`` gives two connected in-process ends with the same calls (the pymodbus NullModem
idea): what one end writes the other reads. Writes can be split, delayed or corrupted on purpose
through ``write_filter``, and ``unplug()`` makes both ends fail like a pulled cable.
"""

from __future__ import annotations

import contextlib
import errno
import socket
import threading
import time
from collections.abc import Callable, Iterable
from typing import Any, Protocol

import serial
from serial.urlhandler import protocol_socket

from fha_studio.hardware.errors import LinkLost
from fha_studio.hardware.protocol import BAUDRATE

try:  # pyserial's POSIX port lets termios.error (not an OSError) out of tcflush on a closed pty
    import termios

    _PORT_ERRORS: tuple[type[BaseException], ...] = (serial.SerialException, OSError, termios.error)
except ImportError:  # pragma: no cover - Windows
    _PORT_ERRORS = (serial.SerialException, OSError)

#: Why a port did not open, in a technician's words, by the error number pyserial passes on (it
#: repeats the port and the number: "[Errno 2] could not open port X: [Errno 2] No such file or
#: directory: 'X'").
_OPEN_FAILURES = {
    errno.ENOENT: "no such port (is the USB-serial adapter plugged in, and is this its name?)",
    errno.EACCES: "permission denied (on Linux: add the user to the dialout group and log in again)",
    errno.EBUSY: "the port is in use by another program",
    errno.ENXIO: "no device behind this port (an adapter unplugged, or a pty whose other side is gone)",
    errno.ECONNREFUSED: "nothing accepts connections there (connection refused: is the server running, "
                        "and is this its port?)",
    errno.EHOSTUNREACH: "the host cannot be reached (check the network and the address)",
    errno.ENETUNREACH: "the network cannot be reached (check the network and the address)",
}
#: The same from pyserial's Windows port, which gives the error's repr, not its number.
_WINDOWS_OPEN_FAILURES = {
    "FileNotFoundError": _OPEN_FAILURES[errno.ENOENT],
    "PermissionError": "access denied: the port is in use by another program",
}


def port_failure_words(exc: BaseException) -> str:
    """Why a port did not open, in a technician's words where the error is one of
    :data:`_OPEN_FAILURES`, else pyserial's own text."""
    # pyserial's socket port gives the socket's error as the cause, not as its own number
    number = getattr(exc, "errno", None) or getattr(exc.__context__, "errno", None) or 0
    words = _OPEN_FAILURES.get(number)
    if words:
        return words
    text = str(exc)
    return next((w for name, w in _WINDOWS_OPEN_FAILURES.items() if name in text), text)


#: The package that holds ``protocol_sim`` for ``sim://`` URLs.
SIM_HANDLER_PACKAGE = "fha_studio.hardware.sim"


class Transport(Protocol):
    """What the client needs of a port: the subset of pyserial's ``Serial`` it uses."""

    timeout: float | None

    @property
    def port(self) -> str | None: ...

    def write(self, data: bytes) -> int | None: ...
    def read(self, size: int = 1) -> bytes: ...
    @property
    def in_waiting(self) -> int: ...
    def reset_input_buffer(self) -> None: ...
    def close(self) -> None: ...
    @property
    def is_open(self) -> bool: ...


def register_url_handlers() -> None:
    """Let ``serial_for_url`` find ``sim://`` (idempotent)."""
    if SIM_HANDLER_PACKAGE not in serial.protocol_handler_packages:
        serial.protocol_handler_packages.append(SIM_HANDLER_PACKAGE)


class GuardedTransport:
    """A pyserial-like port whose failures come out as ``LinkLost`` naming the port.

    Attributes not listed here are passed through to the wrapped port (``baudrate``, ...).
    """

    def __init__(self, inner: Any, name: str | None = None):
        self.inner = inner
        self.name = name or str(getattr(inner, "port", None) or "port")

    def _lost(self, exc: BaseException) -> LinkLost:
        return LinkLost(f"lost the link on {self.name}: {exc or type(exc).__name__}", port=self.name)

    def write(self, data: bytes) -> int | None:
        try:
            written: int | None = self.inner.write(data)
            return written
        except _PORT_ERRORS as exc:
            raise self._lost(exc) from exc

    def read(self, size: int = 1) -> bytes:
        try:
            data: bytes = self.inner.read(size)
            return data
        except _PORT_ERRORS as exc:
            raise self._lost(exc) from exc

    @property
    def in_waiting(self) -> int:
        try:
            waiting: int = self.inner.in_waiting
            return waiting
        except _PORT_ERRORS as exc:
            raise self._lost(exc) from exc

    def reset_input_buffer(self) -> None:
        try:
            self.inner.reset_input_buffer()
        except _PORT_ERRORS as exc:
            raise self._lost(exc) from exc

    @property
    def timeout(self) -> float | None:
        timeout: float | None = self.inner.timeout
        return timeout

    @timeout.setter
    def timeout(self, value: float | None) -> None:
        try:
            self.inner.timeout = value
        except _PORT_ERRORS as exc:
            raise self._lost(exc) from exc

    @property
    def port(self) -> str:
        return self.name

    @property
    def is_open(self) -> bool:
        return bool(self.inner.is_open)

    def close(self) -> None:
        # closing a port that is already gone must not raise
        with contextlib.suppress(*_PORT_ERRORS):
            self.inner.close()

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)


#: The longest URL or device path taken (a sim:// URL with several effects is some 300 characters).
MAX_URL_LENGTH = 2000


def check_url(url: str) -> None:
    """Refuse (ValueError, one line saying what is allowed) a URL that cannot name a drive:
    empty, too long, with control characters, or a ``socket://`` without a host or with a port
    outside 1 ... 65535. Whether the drive is there is for opening it to find out."""
    if not isinstance(url, str) or not url.strip():
        raise ValueError("no drive URL given (a device or pty path, socket://host:port or sim://ACTUATOR-CODE)")
    if len(url) > MAX_URL_LENGTH:
        raise ValueError(f"the drive URL is {len(url)} characters long; at most {MAX_URL_LENGTH}")
    if any(ord(c) < 32 or ord(c) == 127 for c in url):
        raise ValueError("the drive URL holds control characters (line breaks, tabs)")
    if url.lower().startswith("socket://"):
        from urllib.parse import urlsplit

        parts = urlsplit(url)
        try:
            port = parts.port
        except ValueError:
            port = None
        if not parts.hostname or port is None or not 1 <= port <= 65535:
            raise ValueError(f"{url[:80]}: expected socket://HOST:PORT with a port 1 ... 65535")


class _BoundedSocket(protocol_socket.Serial):
    """pyserial's ``socket://`` port with the TCP connect bounded by ``connect_timeout_s`` (its
    own is a fixed 5 s, longer than a caller with a deadline has) and no pause on closing (its
    0.3 s "in case of quick reconnects" is for a caller that reconnects, not one that exits)."""

    connect_timeout_s: float = protocol_socket.POLL_TIMEOUT

    def open(self) -> None:
        self.logger = None
        if self._port is None or self._opened():
            raise serial.SerialException("the socket port is not configured or already open")
        try:
            connected = socket.create_connection(self.from_url(self.portstr),
                                                 timeout=max(0.001, self.connect_timeout_s))
        except TimeoutError:
            raise serial.SerialException(
                f"nothing accepted the connection in {self.connect_timeout_s:.1f} s") from None
        except OSError as exc:
            raise serial.SerialException(str(exc.strerror or exc).lower()) from None
        connected.setblocking(False)
        self._socket = connected
        self.is_open = True
        self.reset_input_buffer()
        self.reset_output_buffer()

    def _opened(self) -> bool:
        return bool(getattr(self, "is_open", False))

    def close(self) -> None:
        connected = getattr(self, "_socket", None)
        if self._opened() and connected is not None:
            with contextlib.suppress(OSError):
                connected.shutdown(socket.SHUT_RDWR)
            connected.close()
        self._socket = None  # type: ignore[assignment]  # pyserial's own close does the same
        self.is_open = False


def open_transport(
    url: str, baudrate: int = BAUDRATE, timeout: float | None = 0.05, *,
    open_timeout_s: float | None = None, **kwargs: Any
) -> GuardedTransport:
    """Open ``url`` at ``baudrate`` 8N1 (CN3's line) and return it guarded.

    ``timeout`` is the read timeout of the port in seconds (the client sets its own per read).
    ``open_timeout_s`` bounds the opening itself where it can wait (a ``socket://`` connect to a
    listener that never accepts; devices and ptys open at once): a caller with one deadline for
    the whole exchange passes what is left of it.
    Raises ``LinkLost`` naming the port when it cannot be opened (absent, busy, no permission,
    no connection in time), ``ValueError`` for a URL scheme nobody handles.
    """
    check_url(url)
    register_url_handlers()
    settings = dict(baudrate=baudrate, bytesize=serial.EIGHTBITS, parity=serial.PARITY_NONE,
                    stopbits=serial.STOPBITS_ONE, timeout=timeout, **kwargs)
    try:
        if open_timeout_s is not None and url.lower().startswith("socket://"):
            bounded = _BoundedSocket(None, **settings)
            bounded.connect_timeout_s = open_timeout_s
            bounded.port = url
            bounded.open()
            port = bounded
        else:
            port = serial.serial_for_url(url, **settings)
    except ValueError as exc:
        if "not known" in str(exc):
            scheme = url.split("://", 1)[0]
            raise ValueError(
                f"cannot open {url!r}: unknown URL scheme {scheme!r} (use a device or pty path, "
                "socket://host:port, loop:// or sim://ACTUATOR-CODE)"
            ) from None
        raise ValueError(f"cannot open {url!r}: {exc}") from None
    except _PORT_ERRORS as exc:
        raise LinkLost(f"cannot open {url}: {port_failure_words(exc)}", port=url) from exc
    return GuardedTransport(port, name=url)


# ---------------------------------------------------------------------------------------------
# In-process pipe pair
# ---------------------------------------------------------------------------------------------

WriteFilter = Callable[[bytes], Iterable[bytes]]


class PipeEnd:
    """One end of an in-process byte pipe with pyserial's calls (``read`` honours ``timeout``).

    ``write_filter`` (optional) turns each written block into the chunks the peer receives: it
    can split, drop or corrupt them on purpose. A chunk of type ``float`` is a pause in seconds
    before the next chunk (to make a reply arrive in pieces over time).
    """

    def __init__(self, name: str):
        self.port = name
        self.timeout: float | None = None
        self.write_filter: WriteFilter | None = None
        self.peer: PipeEnd | None = None
        self.written = bytearray()  # everything this end wrote, for tests
        self._inbox = bytearray()
        self._cond = threading.Condition()
        self._open = True
        self._unplugged = False
        self._cancel = False

    # pyserial-like API -------------------------------------------------------------------------

    @property
    def is_open(self) -> bool:
        return self._open

    @property
    def in_waiting(self) -> int:
        self._check()
        with self._cond:
            return len(self._inbox)

    def write(self, data: bytes) -> int:
        self._check()
        peer = self.peer
        if peer is None or not peer._open:
            raise serial.SerialException(f"{self.port}: the other end is closed")
        self.written += data
        chunks = self.write_filter(bytes(data)) if self.write_filter else [bytes(data)]
        for chunk in chunks:
            if isinstance(chunk, float):
                time.sleep(chunk)
            else:
                peer.inject(chunk)
        return len(data)

    def read(self, size: int = 1) -> bytes:
        """Up to ``size`` bytes; fewer (maybe none) when ``timeout`` passes first."""
        self._check()
        deadline = None if self.timeout is None else time.monotonic() + self.timeout
        with self._cond:
            while len(self._inbox) < size and not self._cancel:
                if self._unplugged:
                    raise serial.SerialException(f"{self.port}: device disconnected")
                if self.peer is not None and not self.peer._open:
                    if self._inbox:
                        break  # what the peer sent before closing
                    raise serial.SerialException(f"{self.port}: the other end closed")
                remaining = None if deadline is None else deadline - time.monotonic()
                if remaining is not None and remaining <= 0:
                    break
                self._cond.wait(remaining)
            self._cancel = False
            data = bytes(self._inbox[:size])
            del self._inbox[:size]
            return data

    def reset_input_buffer(self) -> None:
        self._check()
        with self._cond:
            self._inbox.clear()

    def reset_output_buffer(self) -> None:
        self._check()

    def flush(self) -> None:
        self._check()

    def cancel_read(self) -> None:
        """Wake a blocked ``read`` (it returns what it has)."""
        with self._cond:
            self._cancel = True
            self._cond.notify_all()

    def close(self) -> None:
        self._open = False
        self._wake()
        if self.peer is not None:
            self.peer._wake()

    # test controls -----------------------------------------------------------------------------

    def inject(self, data: bytes) -> None:
        """Make ``data`` arrive at this end as if the peer had sent it (garbage, half frames)."""
        with self._cond:
            self._inbox += data
            self._cond.notify_all()

    def unplug(self) -> None:
        """Fail both ends from now on, like a pulled USB adapter."""
        for end in (self, self.peer):
            if end is not None:
                end._unplugged = True
                end._wake()

    def _wake(self) -> None:
        with self._cond:
            self._cond.notify_all()

    def _check(self) -> None:
        if self._unplugged:
            raise serial.SerialException(f"{self.port}: device disconnected")
        if not self._open:
            raise serial.PortNotOpenError()


def pipe_pair(name: str = "pipe") -> tuple[PipeEnd, PipeEnd]:
    """Two connected ends: ``(host_end, drive_end)``, named ``name:host`` and ``name:drive``."""
    host, drive = PipeEnd(f"{name}:host"), PipeEnd(f"{name}:drive")
    host.peer, drive.peer = drive, host
    return host, drive


def split_every(n: int) -> WriteFilter:
    """A write filter that delivers writes in chunks of ``n`` bytes."""

    def split(data: bytes) -> list[bytes]:
        return [data[i : i + n] for i in range(0, len(data), n)]

    return split


def corrupt_at(index: int, byte: int) -> WriteFilter:
    """A write filter that replaces byte ``index`` of every write (when it has one) by ``byte``."""

    def corrupt(data: bytes) -> list[bytes]:
        if index < len(data):
            data = data[:index] + bytes([byte]) + data[index + 1 :]
        return [data]

    return corrupt
