"""`SimProtocolServer`: bytes in -> codec -> SimResponder -> codec -> bytes out, paced like the line.

A real CN3 line carries 1920 characters/s (19200 bit/s, 8N1 = 10 bits per character). Paced (the
default), each byte the host writes *arrives* one character time after the previous one (a
command is acted on when its 10th character has arrived), and each reply byte becomes readable
one character time after the previous one. Unpaced (``paced=False``) everything happens at once.

The server owns no thread: whoever carries the bytes (the ``sim://`` handler, the pty or TCP
loop of ``fha-studio sim``) calls :meth:`feed` with what the host wrote, and :meth:`read_ready`
for what the host may read now; :meth:`next_event_s` says when to look again.

Both directions are bounded, as a serial adapter's buffers are: bytes the host writes faster than
the line carries wait at most ``INPUT_BACKLOG_BYTES`` (about half a second of line time at 19200
baud); what comes beyond is dropped and counted in ``overrun_bytes``, so a flood can neither grow
the process's memory nor keep the drive busy for long after the sender has gone. Replies the host
does not read wait up to ``OUTPUT_BACKLOG_BYTES``; later ones are dropped (``dropped_reply_bytes``).
:meth:`reset` starts a new connection on a clean line: nothing of the previous host's bytes or
replies reaches the next host.
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
    UnknownRequest,
    decode_request,
    encode_reply,
)
from fha_studio.hardware.sim.drive import SimDrive
from fha_studio.hardware.sim.reply import SimReply
from fha_studio.hardware.sim.responder import SimResponder

#: Bytes written by the host that may wait for the line (1024 characters: 0.53 s at 19200 baud).
INPUT_BACKLOG_BYTES = 1024
#: Reply bytes that may wait for the host to read them.
OUTPUT_BACKLOG_BYTES = 64 * 1024


class SimProtocolServer:
    """Speaks CN3 for one :class:`SimDrive`, through its :class:`SimResponder` (``responder``).
    Thread-safe: feed and read may come from two threads.

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
        self.responder = SimResponder(drive)
        self.paced = paced
        self.char_s = protocol.character_time_s(baudrate) if paced else 0.0
        self._clock = clock
        self._lock = threading.Lock()
        self._on_transaction = on_transaction
        # written by the host, not yet arrived: _incoming[i] is byte number _in_done + i since the
        # line started at _in_start, and byte k arrives at _in_start + (k + 1) * char_s
        self._incoming = bytearray()
        self._in_start = 0.0
        self._in_done = 0
        self._rx = bytearray()  # arrived, not yet decoded (at most an unfinished frame)
        self._out: deque[tuple[float, int]] = deque()  # (time the byte is readable, byte)
        self._out_free_at = 0.0
        self.garbage_bytes = 0
        self.overrun_bytes = 0
        self.dropped_reply_bytes = 0
        self.transactions = 0

    # ---- host -> drive --------------------------------------------------------------------
    def feed(self, data: bytes) -> None:
        """Bytes the host wrote. Paced, they arrive one character time apart."""
        if not data:
            return
        with self._lock:
            now = self._clock()
            self._pump(now)
            view = memoryview(data)
            while view:
                room = INPUT_BACKLOG_BYTES - len(self._incoming)
                if room <= 0:
                    break
                if not self._incoming:
                    line_free_at = self._in_start + self._in_done * self.char_s
                    self._in_start, self._in_done = max(now, line_free_at), 0
                self._incoming += view[:room]
                view = view[room:]
                self._pump(now)  # unpaced, everything is handled at once: room again
            if view:
                self.overrun_bytes += len(view)

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
                last = self._in_start + (self._in_done + len(self._incoming)) * self.char_s
                return max(0.0, last + self.char_s - self._clock())
            return None

    def reset_output(self) -> None:
        """Drop reply bytes not yet read (the host flushed its input buffer)."""
        with self._lock:
            self._out.clear()

    def reset(self) -> None:
        """A new connection on a clean line: the previous host's unsent bytes, its unfinished
        frame and the replies it did not read are dropped. The drive itself keeps its state
        (like a drive whose cable is unplugged and plugged again)."""
        with self._lock:
            self._incoming.clear()
            self._in_start, self._in_done = 0.0, 0
            self._rx.clear()
            self._out.clear()
            self._out_free_at = 0.0

    # ---- the work ---------------------------------------------------------------------------
    def _pump(self, now: float) -> None:
        # move what has arrived, a frame at a time (up to each CR), so each command is acted on
        # when its CR arrives
        while self._incoming and self._in_start + (self._in_done + 1) * self.char_s <= now:
            arrived = len(self._incoming) if self.char_s == 0 else min(
                len(self._incoming), max(1, int((now - self._in_start) / self.char_s + 1e-9) - self._in_done))
            cr = self._incoming.find(b"\r", 0, arrived)
            count = arrived if cr < 0 else cr + 1
            self._in_done += count
            at = self._in_start + self._in_done * self.char_s
            self._rx += self._incoming[:count]
            del self._incoming[:count]
            self._decode(at)
        for reply in self.responder.take_deferred_replies():
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
            if not isinstance(message, Request | UnknownRequest):  # pragma: no cover - the codec
                continue  # returns only these
            reply = self.responder.respond(message)
            self.transactions += 1
            if reply is not None:
                self._send(reply, at)
            if self._on_transaction is not None:
                name = message.command.value if isinstance(message, Request) else message.name
                value = message.value
                self._on_transaction(f"{name}{'-' if value < 0 else '+'}{abs(value):05d}",
                                     reply or SimReply(reason="deferred"))

    def _send(self, reply: SimReply, at: float) -> None:
        data = encode_reply(reply.on_the_wire())
        if len(self._out) + len(data) > OUTPUT_BACKLOG_BYTES:  # the host does not read: drop
            self.dropped_reply_bytes += len(data)
            return
        start = max(at, self._out_free_at)
        for i, byte in enumerate(data):
            self._out.append((start + (i + 1) * self.char_s, byte))
        self._out_free_at = start + len(data) * self.char_s
