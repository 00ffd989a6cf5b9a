"""The transaction layer of the CN3 link: one request, one reply, the one retry policy.

As pymodbus separates its transaction manager from its client, this module knows frames, time and
the line, and nothing of what a command means: ``DriveClient`` (``client.py``) builds the API on
``Transaction.transact``. One ``Transaction`` owns its port; ``transact`` may be called from any
thread (an RLock serialises it; ``lock`` lets the client hold it across a select-then-read).

Retry policy (the only one): an attempt fails when no byte arrives for
``settings.response_timeout_s`` (counted from the end of the request, restarted at every byte
received), when the reply is marked corrupt by the codec, or when its lines do not have the form
the command defines (the parser raises ``ValueError``). A failed attempt is retried
``settings.retries`` times, after waiting until the line has been quiet for
``settings.response_timeout_s`` (so a late reply is dropped, not taken for the next request's).
Commands whose repetition could act twice (``protocol.NOT_RETRIED``: MOV, OWW, PWC, from their rows
in ``protocol.COMMAND_FACTS``) are never retried. ``s`` and ``x`` are
answers, not failures: raised at once as ``ServoOnRefused`` / ``CommandRejected``, never retried.
After ``settings.max_consecutive_failures`` failed transactions in a row the link is marked lost
(``LinkLost``); one success resets the count. This is the one rule of when a link counts as lost:
whoever supervises the link (the GUI's link worker) takes ``LinkLost`` as the verdict and sets
how many failures it takes with ``lose_link_after``; nobody counts timeouts a second time.

Wall time: an attempt ends at the latest ``reply_time_limit_s`` after its first-byte timeout,
however the line behaves (silent, trickling, flooding, garbage, NUL), and so does each wait for a
quiet line; so a transaction is bounded (``LinkSettings.transaction_limit_s``). A transaction that
failed says what the line did: ``LinkSilent`` (not a byte arrived), ``LinkGarbled`` (bytes, but
never a complete reply) or ``LinkTimeout`` (replies came, but corrupt or of the wrong form).
``should_abort`` (e.g. a closing window's event) is asked at every read: when it says True the
exchange gives up at once with ``ReadAborted``.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TypeVar

from fha_studio.hardware import protocol as p
from fha_studio.hardware.errors import (
    CommandRejected,
    LinkGarbled,
    LinkLost,
    LinkSilent,
    LinkTimeout,
    ReadAborted,
    ServoOnRefused,
)
from fha_studio.hardware.protocol import (
    NOT_RETRIED,
    Command,
    Garbage,
    Reply,
    Request,
    Status,
    command_words,
    rejected_text,
    servo_on_text,
)
from fha_studio.hardware.transport import GuardedTransport, Transport

__all__ = [
    "NOT_RETRIED",
    "LinkSettings",
    "PacketMonitor",
    "ReplyShapeError",
    "Transaction",
    "no_data",
    "one_int",
]

log = logging.getLogger(__name__)
T = TypeVar("T")

#: A bus monitor: called with every block written (True) and read (False).
PacketMonitor = Callable[[bool, bytes], None]


def _longest_reply_chars(command: Command) -> int:
    return p.COMMAND_FACTS[command].longest_reply_chars


@dataclass(frozen=True)
class LinkSettings:
    """How the client uses the line. Times in seconds.

    ``response_timeout_s`` is the longest silence the client accepts while it waits for (the
    rest of) a reply; the time the request itself takes on the line (10 characters at
    ``baudrate``) is added for the first byte.
    """

    baudrate: int = p.BAUDRATE
    response_timeout_s: float = 0.3
    retries: int = 2
    max_consecutive_failures: int = 3
    #: first-byte timeouts of the slow replies (a command's row in protocol.COMMAND_FACTS says
    #: whether its reply is one and why: slow_reply_timeout_s)
    oww_timeout_s: float = 6.5  # OWW: "q about 5 s later" (HA-655 manual p.21)
    power_cycle_timeout_s: float = 5.0
    eeprom_write_timeout_s: float = 0.5
    #: cap on one attempt however long the drive keeps sending (a babbling line)
    max_reply_s: float = 5.0
    #: read timeout of the port: how often a waiting read wakes up to check its deadline
    poll_s: float = 0.01

    def __post_init__(self) -> None:
        if self.baudrate <= 0 or self.response_timeout_s <= 0 or self.retries < 0:
            raise ValueError("LinkSettings: baudrate and response_timeout_s must be > 0, retries >= 0")
        if self.max_consecutive_failures < 1:
            raise ValueError("LinkSettings: max_consecutive_failures must be >= 1")

    @property
    def character_time_s(self) -> float:
        """Time of one character on the line (8N1: 10 bits)."""
        return p.character_time_s(self.baudrate)

    def transfer_time_s(self, characters: int) -> float:
        """Time ``characters`` take on the line."""
        return characters * self.character_time_s

    def slow_reply_timeout_s(self, slow: p.SlowReply) -> float:
        """How long the first byte of a reply that is ``slow`` may take."""
        return {
            p.SlowReply.MULTI_TURN_CLEAR: self.oww_timeout_s,
            p.SlowReply.POWER_CYCLE: self.power_cycle_timeout_s,
            p.SlowReply.EEPROM_WRITE: self.eeprom_write_timeout_s,
        }[slow]

    def first_byte_timeout_s(self, command: Command) -> float:
        """How long an attempt of ``command`` waits for the first byte of the reply."""
        slow = p.COMMAND_FACTS[command].slow
        wait = max(self.response_timeout_s, self.slow_reply_timeout_s(slow) if slow is not None else 0.0)
        return self.transfer_time_s(p.FRAME_LENGTH) + wait

    def reply_time_limit_s(self, command: Command) -> float:
        """How long an attempt of ``command`` may go on after its first-byte timeout: twice the
        line time of the command's longest reply plus one response timeout, at most
        ``max_reply_s``. A line still sending then is babbling, not replying."""
        chars = _longest_reply_chars(command)
        return min(self.max_reply_s, 2 * self.transfer_time_s(chars) + self.response_timeout_s)

    def transaction_limit_s(self, command: Command) -> float:
        """The longest wall time of one transaction of ``command``, whatever the line does: every
        attempt, the quiet-line waits between and after them (each at most one attempt long)."""
        attempts = 1 if command in NOT_RETRIED else 1 + self.retries
        attempt = self.first_byte_timeout_s(command) + self.reply_time_limit_s(command)
        quiet = self.response_timeout_s + self.reply_time_limit_s(command)
        return attempts * (attempt + quiet)


class ReplyShapeError(ValueError):
    """A reply with the wrong number or form of lines for its command (treated as corrupt)."""


def one_int(reply: Reply) -> int:
    """Parser of a reply with one integer line."""
    if len(reply.lines) != 1:
        raise ReplyShapeError(f"expected one value line, got {len(reply.lines)}")
    return p.parse_int(reply.lines[0])


def no_data(reply: Reply) -> None:
    """Parser of a reply without data lines."""
    if reply.lines:
        raise ReplyShapeError(f"expected no data, got {len(reply.lines)} lines")


@dataclass
class _LinkHealth:
    consecutive_failures: int = 0
    lost: LinkLost | None = None
    transactions: int = 0
    failed_attempts: int = 0
    garbage_bytes: int = 0


class Transaction:
    """Framing, timeouts, retries, resynchronisation and link health over one transport.

    ``packet_monitor``: optional ``callable(sending: bool, data: bytes)`` called with every block
    written (True) and read (False): a bus monitor. It runs in the caller's thread, under the
    lock; it must be quick and must not call the link.
    """

    def __init__(
        self,
        transport: Transport,
        settings: LinkSettings | None = None,
        should_abort: Callable[[], bool] | None = None,
    ):
        self.settings = settings or LinkSettings()
        self.transport = (
            transport if isinstance(transport, GuardedTransport) else GuardedTransport(transport)
        )
        self.transport.timeout = self.settings.poll_s
        self.lock = threading.RLock()
        self._decoder: p.StreamDecoder[Reply | Garbage] = p.StreamDecoder(p.decode_reply)
        self._health = _LinkHealth()
        self._closed = False
        self.packet_monitor: PacketMonitor | None = None
        self.should_abort = should_abort
        self._received = 0  # bytes read during the current transaction
        self._framed = False  # a reply (well-formed or not) was decoded in it

    # --- state ----------------------------------------------------------------------------------

    def close(self) -> None:
        """Close the port (idempotent)."""
        with self.lock:
            if not self._closed:
                self._closed = True
                self.transport.close()

    def lose_link_after(self, failures: int) -> None:
        """From now on the link is marked lost after ``failures`` failed transactions in a row
        (``settings.max_consecutive_failures``). A supervisor that must show a dead link at once
        (the GUI's link worker: 1) sets it once the drive is open, so that opening keeps its
        fallbacks (a drive that ignores CAP)."""
        with self.lock:
            self.settings = replace(self.settings, max_consecutive_failures=failures)

    @property
    def port(self) -> str:
        return self.transport.name

    @property
    def is_open(self) -> bool:
        return not self._closed and self._health.lost is None

    @property
    def link_lost(self) -> bool:
        return self._health.lost is not None

    @property
    def statistics(self) -> dict[str, int]:
        """Transactions, failed attempts, garbage bytes seen, consecutive failures."""
        h = self._health
        return {
            "transactions": h.transactions,
            "failed_attempts": h.failed_attempts,
            "garbage_bytes": h.garbage_bytes,
            "consecutive_failures": h.consecutive_failures,
        }

    # --- one exchange ---------------------------------------------------------------------------

    def transact(
        self,
        command: Command,
        value: int = 0,
        parse: Callable[[Reply], T] = no_data,  # type: ignore[assignment]  # T is None then
        *,
        retry: bool | None = None,
    ) -> T:
        """Send ``command`` and return ``parse(reply)``; the one place of the retry policy.

        ``parse`` raises ``ValueError`` for a reply of the wrong form (the attempt is retried).
        ``retry=False`` sends once whatever the command.
        """
        request = Request(command, value)
        with self.lock:
            if self._closed:
                raise LinkLost(f"{self.port}: the client is closed", port=self.port)
            if self._health.lost is not None:
                raise LinkLost(str(self._health.lost), port=self.port)
            attempts = 1 if (retry is False or command in NOT_RETRIED) else 1 + self.settings.retries
            why = ""
            started = time.monotonic()
            self._received, self._framed = 0, False
            made = 0
            quiet = True
            try:
                for attempt in range(attempts):
                    if attempt:
                        self._health.failed_attempts += 1
                        log.info("%s: %s failed (%s), retry %d", self.port, command, why, attempt)
                        quiet = self._drain_until_quiet(command)
                        if not quiet:  # a line that never pauses carries no reply: do not retry
                            why += "; the line never went quiet"
                            break
                    made += 1
                    reply, why = self._attempt(request)
                    if reply is None:
                        continue
                    if reply.status is Status.SERVO_ON:
                        self._succeeded()
                        raise ServoOnRefused(
                            servo_on_text(command)
                        )
                    if reply.status is Status.REJECTED:
                        self._succeeded()
                        raise CommandRejected(rejected_text(command, value))
                    try:
                        result = parse(reply)
                    except ValueError as exc:
                        why = f"malformed reply {reply.lines!r}: {exc}"
                        continue
                    self._succeeded()
                    return result
            except LinkLost as exc:
                self._health.lost = exc
                raise
            self._health.failed_attempts += 1
            self._health.consecutive_failures += 1
            if quiet:
                self._drain_quietly(command)
            failure = self._failure(command, why, made, attempts == 1, time.monotonic() - started)
            failures = self._health.consecutive_failures
            if failures >= self.settings.max_consecutive_failures:
                in_a_row = f"; {failures} failed transactions in a row" if failures > 1 else ""
                lost = LinkLost(
                    f"{failure}{in_a_row}: link marked lost (check the cable and the drive's power, "
                    "then reconnect)",
                    port=self.port,
                )
                self._health.lost = lost
                raise lost
            raise failure

    def _failure(
        self, command: Command, why: str, attempts: int, once: bool, elapsed_s: float
    ) -> LinkTimeout:
        """The error of a failed transaction, saying what the line did."""
        unknown = " (not repeated: unknown whether the drive acted on it)" if once else ""
        tried = f"to {command_words(command)}: {attempts} attempt(s) in {elapsed_s:.1f} s{unknown}"
        if not self._received:
            return LinkSilent(
                f"nothing arrives on {self.port} ({tried}): check the cable, the port and the "
                "drive's power"
            )
        if not self._framed:
            return LinkGarbled(
                f"bytes arrive on {self.port} but no complete reply ({self._received} bytes; {tried}): "
                "a wrong baud rate, or not an HA-655/HA-675 on this port"
            )
        return LinkTimeout(f"{command} on {self.port}: {why} after {attempts} attempt(s){unknown}")

    # --- the line ---------------------------------------------------------------------------------

    def _monitor(self, sending: bool, data: bytes) -> None:
        if self.packet_monitor is not None and data:
            try:
                self.packet_monitor(sending, data)
            except Exception:  # a monitor must never break the link
                log.exception("packet monitor failed")

    def _read_some(self) -> bytes:
        if self.should_abort is not None and self.should_abort():
            raise ReadAborted(f"{self.port}: the exchange was abandoned (the link is closing)")
        waiting = self.transport.in_waiting
        data = self.transport.read(max(1, waiting))
        self._received += len(data)
        self._monitor(False, data)
        return data

    def _drain_until_quiet(self, command: Command) -> bool:
        """Drop input until the line has been quiet for response_timeout_s: a reply that comes
        late (after its attempt timed out) is dropped here, not taken for the next request's.
        Gives up after the longest reply of ``command`` could have come. False for a flood: it
        gave up having read more than that reply's length (another attempt would fare no better)."""
        quiet_until = time.monotonic() + self.settings.response_timeout_s
        give_up = quiet_until + self.settings.reply_time_limit_s(command)
        drained = 0
        while time.monotonic() < min(quiet_until, give_up):
            data = self._read_some()
            if data:
                drained += len(data)
                quiet_until = time.monotonic() + self.settings.response_timeout_s
                # a late reply is a reply: the line carries frames (only not in time)
                if drained <= _longest_reply_chars(command) and any(
                    not isinstance(m, Garbage) for m in self._decoder.feed(data)
                ):
                    self._framed = True
        self.transport.reset_input_buffer()
        self._decoder.clear()
        flooding = quiet_until > give_up and drained > _longest_reply_chars(command)
        return not flooding

    def _drain_quietly(self, command: Command) -> None:
        try:
            self._drain_until_quiet(command)
        except LinkLost as exc:
            self._health.lost = exc
            raise

    def _attempt(self, request: Request) -> tuple[Reply | None, str]:
        """Send once and wait for one reply: (reply, "") or (None, why it failed)."""
        self.transport.reset_input_buffer()  # stale input from before this request
        stale = self._decoder.clear()
        if stale:
            self._health.garbage_bytes += len(stale)
        data = request.encode()
        self.transport.write(data)
        self._monitor(True, data)
        start = time.monotonic()
        deadline = start + self.settings.first_byte_timeout_s(request.command)
        cap = deadline + self.settings.reply_time_limit_s(request.command)
        tainted = False
        while True:
            now = time.monotonic()
            if now >= min(deadline, cap):
                pending = self._decoder.pending
                return None, ("half a reply, then silence" if pending else "no reply") + (
                    f" within {now - start:.2f} s"
                )
            chunk = self._read_some()
            if not chunk:
                continue
            deadline = time.monotonic() + self.settings.response_timeout_s
            for message in self._decoder.feed(chunk):
                if isinstance(message, Garbage):
                    self._health.garbage_bytes += len(message.data)
                    log.debug("%s: skipped %r (%s)", self.port, message.data, message.reason)
                    tainted = tainted or message.printable
                    continue
                self._framed = True
                if message.corrupt or tainted:
                    return None, "corrupt reply (noise inside it)"
                return message, ""

    def _succeeded(self) -> None:
        self._health.transactions += 1
        self._health.consecutive_failures = 0
