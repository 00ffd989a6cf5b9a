"""`SimProtocolServer`: bytes in -> codec -> SimDrive -> codec -> bytes out, paced like the line.

A real CN3 line carries 1920 characters/s (19200 bit/s, 8N1 = 10 bits per character). Paced (the
default), each byte the host writes *arrives* one character time after the previous one (a
command is acted on when its 10th character has arrived), and each reply byte becomes readable
one character time after the previous one. Unpaced (``paced=False``) everything happens at once.

The server owns no thread: whoever carries the bytes (the ``sim://`` handler, the pty or TCP
loop of ``fha-studio sim``) calls :meth:`feed` with what the host wrote, and :meth:`read_ready`
for what the host may read now; :meth:`next_event_s` says when to look again.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable

from fha_studio.hardware import protocol
from fha_studio.hardware.protocol import (
    Garbage,
    Request,
    Status,
    UnknownRequest,
    decode_request,
    encode_reply,
)
from fha_studio.hardware.sim.drive import SimDrive
from fha_studio.hardware.sim.reply import SimReply

_STATUS = {"q": Status.DONE, "s": Status.SERVO_ON, "x": Status.REJECTED}


class SimProtocolServer:
    """Speaks CN3 for one :class:`SimDrive`. Thread-safe: feed and read may come from two threads.

    ``on_transaction(request_text, reply)`` is called for every command handled (a bus monitor).
    """

    def __init__(
        self,
        drive: SimDrive,
        *,
        paced: bool = True,
        baudrate: int = protocol.BAUDRATE,
        clock: Callable[[], float] = time.monotonic,
        on_transaction: Callable[[str, SimReply], None] | None = None,
    ):
        self.drive = drive
        self.paced = paced
        self.char_s = protocol.character_time_s(baudrate) if paced else 0.0
        self._clock = clock
        self._lock = threading.Lock()
        self._on_transaction = on_transaction
        self._incoming: deque[tuple[float, bytes]] = deque()  # (arrival time of the last byte, bytes)
        self._in_free_at = 0.0  # when the host -> drive line is free again
        self._rx = bytearray()  # arrived, not yet decoded
        self._out: deque[tuple[float, int]] = deque()  # (time the byte is readable, byte)
        self._out_free_at = 0.0
        self.garbage_bytes = 0
        self.transactions = 0

    # ---- host -> drive --------------------------------------------------------------------
    def feed(self, data: bytes) -> None:
        """Bytes the host wrote. Paced, they arrive one character time apart."""
        if not data:
            return
        with self._lock:
            now = self._clock()
            if self.paced:
                start = max(now, self._in_free_at)
                # each byte is its own arrival, so a frame is handled when its CR has arrived
                for i, byte in enumerate(data):
                    self._incoming.append((start + (i + 1) * self.char_s, bytes((byte,))))
                self._in_free_at = start + len(data) * self.char_s
            else:
                self._incoming.append((now, bytes(data)))
            self._pump(now)

    # ---- drive -> host --------------------------------------------------------------------
    def read_ready(self, size: int | None = None) -> bytes:
        """The reply bytes the host can read now (at most ``size``)."""
        with self._lock:
            now = self._clock()
            self._pump(now)
            out = bytearray()
            while self._out and self._out[0][0] <= now and (size is None or len(out) < size):
                out.append(self._out.popleft()[1])
            return bytes(out)

    def in_waiting(self) -> int:
        """How many reply bytes are readable now."""
        with self._lock:
            now = self._clock()
            self._pump(now)
            return sum(1 for t, _ in self._out if t <= now)

    def next_event_s(self) -> float | None:
        """Seconds until a reply byte may become readable, or None when nothing is pending. While
        a request is still arriving nothing can be read before its last byte is in and one more
        character time has passed (the reply's first byte), so a reader sleeps through the
        request instead of waking for each of its characters. A deferred reply (OWW) is not
        foreseen here: callers poll at least every few ms while they wait."""
        with self._lock:
            if self._out:
                return max(0.0, self._out[0][0] - self._clock())
            if self._incoming:
                return max(0.0, self._incoming[-1][0] + self.char_s - self._clock())
            return None

    def reset_output(self) -> None:
        """Drop reply bytes not yet read (the host flushed its input buffer)."""
        with self._lock:
            self._out.clear()

    # ---- the work ---------------------------------------------------------------------------
    def _pump(self, now: float) -> None:
        while self._incoming and self._incoming[0][0] <= now:
            arrived, data = self._incoming.popleft()
            self._rx += data
            self._decode(arrived)
        for reply in self.drive.take_deferred_replies():
            self._send(reply, now)

    def _decode(self, at: float) -> None:
        while self._rx:
            used, message = decode_request(self._rx)
            if used == 0:
                return
            del self._rx[:used]
            if isinstance(message, Garbage):
                self.garbage_bytes += len(message.data)
                continue
            if isinstance(message, UnknownRequest):
                name, value = message.name, message.value
            elif isinstance(message, Request):
                name, value = message.command.value, message.value
            else:  # pragma: no cover - the codec returns only these
                continue
            reply = self.drive.execute(name, value)
            self.transactions += 1
            if reply is not None:
                self._send(reply, at)
            if self._on_transaction is not None:
                self._on_transaction(f"{name}{'-' if value < 0 else '+'}{abs(value):05d}",
                                     reply or SimReply("q", reason="deferred"))

    def _send(self, reply: SimReply, at: float) -> None:
        data = encode_reply(protocol.Reply(tuple(reply.lines), _STATUS[reply.terminal]))
        start = max(at, self._out_free_at)
        for i, byte in enumerate(data):
            self._out.append((start + (i + 1) * self.char_s, byte))
        self._out_free_at = start + len(data) * self.char_s
