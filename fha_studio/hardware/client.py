"""DriveClient: the user's API to an HA-655 / HA-675 over CN3 (docs/protocol.md).

Three layers, as in pymodbus: the transport moves bytes (``transport``), ``DriveClient._transact``
is the transaction layer (lock, stale-input flush, timeouts, the one retry policy, resync, link
health), and the public methods are the client. One ``DriveClient`` owns its port; every public
method may be called from any thread (an RLock serialises them, and multi-command operations such
as select-then-read hold it throughout). Calls block for at most a few hundred milliseconds
(``clear_multiturn`` ~6 s), so a GUI runs them in its link worker thread, never in its GUI
thread.

Retry policy (the only one): an attempt fails when no byte arrives for
``settings.response_timeout_s`` (counted from the end of the request, restarted at every byte
received), when the reply is marked corrupt by the codec, or when its lines do not have the form
the command defines. A failed attempt is retried ``settings.retries`` times, after waiting until
the line has been quiet for ``settings.response_timeout_s`` (so a late reply is dropped, not
taken for the next request's). Commands whose repetition could act twice (MOV, OWW, PWC) are
never retried. ``s`` and ``x`` are answers, not failures: raised at once as ``ServoOnRefused`` /
``CommandRejected``, never retried. After ``settings.max_consecutive_failures`` failed
transactions in a row the link is marked lost (``LinkLost``); one success resets the count.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from enum import Enum
from typing import TypeVar

from fha_studio.hardware import protocol as p
from fha_studio.hardware.errors import (
    CommandNotSupported,
    CommandRejected,
    DriveRefused,
    LinkError,
    LinkFailure,
    LinkLost,
    LinkTimeout,
    ReadAborted,
    ServoOnRefused,
)
from fha_studio.hardware.parameters import (
    Mode,
    ParameterItem,
    ParameterModel,
    ParameterValueError,
    load_parameter_model,
)
from fha_studio.hardware.protocol import Command, Garbage, Reply, Request, Status
from fha_studio.hardware.transport import GuardedTransport, Transport, open_transport

__all__ = [
    "AlarmRecord",
    "Capabilities",
    "CapabilityLevel",
    "CommandNotSupported",
    "CommandRejected",
    "DriveClient",
    "DriveRefused",
    "Identity",
    "IoState",
    "LinkError",
    "LinkFailure",
    "LinkLost",
    "LinkSettings",
    "LinkTimeout",
    "ReadAborted",
    "ServoOnRefused",
    "TraceCapture",
    "TraceStatus",
    "WriteResult",
]

log = logging.getLogger(__name__)
T = TypeVar("T")


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
    #: first-byte timeouts of the slow commands
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

    def first_byte_timeout_s(self, command: Command) -> float:
        """How long an attempt of ``command`` waits for the first byte of the reply."""
        slow = {
            Command.OWW: self.oww_timeout_s,
            Command.PWC: self.power_cycle_timeout_s,
            Command.PWR: self.eeprom_write_timeout_s,
        }
        wait = max(self.response_timeout_s, slow.get(command, 0.0))
        return self.transfer_time_s(p.FRAME_LENGTH) + wait


#: Commands whose repetition could act twice; sent once, never retried.
NOT_RETRIED = frozenset({Command.MOV, Command.OWW, Command.PWC})

_SELECT = {Mode.TUNE: Command.TSL, Mode.SYSTEM: Command.PSL, Mode.TEST: Command.JSL}
_TRACE_COMMANDS = frozenset(
    {
        Command.TCH,
        Command.TDV,
        Command.TTG,
        Command.TTC,
        Command.TTL,
        Command.TPR,
        Command.TAR,
        Command.TST,
        Command.TRB,
    }
)


class CapabilityLevel(Enum):
    """What a drive can give, best first (the degrade chain of docs/protocol.md)."""

    TRACE = "trace"  # trace capture at the servo rate
    POLLING = "polling"  # monitor items, polled
    ABSOLUTE_POSITION = "absolute_position"  # DGR only, with the servo off
    NOTHING = "nothing"


_LEVEL_SENTENCES = {
    CapabilityLevel.TRACE: (
        "This drive records traces itself: up to 4 signals at the servo rate, captured in the drive "
        "and read out afterwards."
    ),
    CapabilityLevel.POLLING: (
        "This drive cannot record traces, so FHA Studio polls its monitor items instead: plots show "
        "a few dozen samples per second, not servo-rate detail."
    ),
    CapabilityLevel.ABSOLUTE_POSITION: (
        "This drive speaks only the commands of its manual: FHA Studio can read the absolute "
        "position (DGR), and only while the servo is off. No live signals and no parameter access: "
        "use the drive's front panel for those."
    ),
    CapabilityLevel.NOTHING: (
        "This drive answers on CN3 but offers nothing FHA Studio can read: no extension commands and "
        "no absolute position (DGR is refused, e.g. an incremental encoder). Use the drive's front panel."
    ),
}


@dataclass(frozen=True)
class Capabilities:
    """What the connected drive supports, from its CAP reply and a DGR probe.

    ``absolute_position``: True = DGR answered a position, False = DGR refused (``x``:
    incremental encoder), None = not known (the servo was on: ``s``).
    """

    commands: frozenset[Command]
    absolute_position: bool | None
    answered_cap: bool
    notes: tuple[str, ...] = ()

    @property
    def level(self) -> CapabilityLevel:
        if self.commands >= _TRACE_COMMANDS:
            return CapabilityLevel.TRACE
        if Command.MON in self.commands or Command.MMR in self.commands:
            return CapabilityLevel.POLLING
        if self.absolute_position is not False:
            return CapabilityLevel.ABSOLUTE_POSITION
        return CapabilityLevel.NOTHING

    @property
    def simulated(self) -> bool:
        """True when the drive has the sim-only commands (INP, PWC)."""
        return self.commands >= p.SIM_ONLY_COMMANDS

    @property
    def parameters(self) -> bool:
        """True when parameters can be read and written over the link."""
        return {Command.PRD, Command.PWR, Command.PSL, Command.TSL} <= self.commands

    def supports(self, command: Command) -> bool:
        return command in self.commands

    def describe(self) -> str:
        """Plain-language sentences for the user: what this drive gives and what it does not."""
        parts = [_LEVEL_SENTENCES[self.level]]
        if self.level is not CapabilityLevel.NOTHING:
            if self.absolute_position is None:
                parts.append("Whether it has an absolute encoder is not known yet (the servo was on).")
            elif self.absolute_position is False and Command.DGR in self.commands:
                parts.append("It has no absolute position (DGR refused): the encoder is incremental.")
        parts.extend(self.notes)
        return " ".join(parts)


@dataclass(frozen=True)
class Identity:
    """IDN's reply: driver model, the actuator it is adjusted for, firmware text."""

    driver_model: str
    adjusted_for: str
    firmware: str


@dataclass(frozen=True)
class IoState:
    """The I/O bits of IOS (docs/protocol.md, I/O bits). ``raw`` is the whole mask."""

    raw: int

    def bit(self, bit: p.IoBit) -> bool:
        return bool(self.raw >> bit & 1)

    servo_on = property(lambda self: self.bit(p.IoBit.SERVO_ON))
    ready = property(lambda self: self.bit(p.IoBit.READY))
    alarm = property(lambda self: self.bit(p.IoBit.ALARM))
    in_position = property(lambda self: self.bit(p.IoBit.IN_POSITION))
    fwd_inhibit = property(lambda self: self.bit(p.IoBit.FWD_INHIBIT))
    rev_inhibit = property(lambda self: self.bit(p.IoBit.REV_INHIBIT))
    origin_sensor = property(lambda self: self.bit(p.IoBit.ORIGIN_SENSOR))
    limit_switch_1 = property(lambda self: self.bit(p.IoBit.LIMIT_SWITCH_1))
    limit_switch_2 = property(lambda self: self.bit(p.IoBit.LIMIT_SWITCH_2))
    brake_released = property(lambda self: self.bit(p.IoBit.BRAKE_RELEASED))
    error_counter_clear = property(lambda self: self.bit(p.IoBit.ERROR_COUNTER_CLEAR))
    moving = property(lambda self: self.bit(p.IoBit.MOVING))

    @property
    def alm_bits(self) -> int:
        """The 4-bit alarm output, bit 0 = ALM-A ... bit 3 = ALM-D (compare Alarm.alm_bits)."""
        return p.alm_bits_from_io(self.raw)

    def as_dict(self) -> dict[str, bool]:
        """Every named bit: {"servo_on": True, ...}."""
        return {bit.name.lower(): self.bit(bit) for bit in p.IoBit}


#: Names accepted by DriveClient.set_inputs.
INPUT_NAMES = {bit.name.lower(): bit for bit in p.INPUT_BITS}


@dataclass(frozen=True)
class AlarmRecord:
    """One AHS line: alarm code and when it happened."""

    code: int
    seconds_since_power_on: int


@dataclass(frozen=True)
class TraceStatus:
    state: p.TraceState
    count: int


@dataclass(frozen=True)
class TraceCapture:
    """A read-out capture: ``samples[i][j]`` is channel ``channels[j]`` (monitor item) at sample i,
    in the channel's wire unit (scale it with the parameter model's monitor item)."""

    channels: tuple[int, ...]
    samples: tuple[tuple[int, ...], ...]

    def column(self, item: int) -> list[int]:
        j = self.channels.index(item)
        return [row[j] for row in self.samples]


@dataclass(frozen=True)
class WriteResult:
    """Outcome of a verified write. ``holds`` is "new", "old" or "neither" (read back)."""

    item: ParameterItem
    requested: int
    previous: int | None
    value: int
    holds: str
    message: str = ""

    @property
    def verified(self) -> bool:
        return self.holds == "new"

    @property
    def needs_restart(self) -> bool:
        """True when the new value takes effect only after a power cycle."""
        return self.verified and self.item.restart_required and self.previous != self.requested


class _ReplyShapeError(ValueError):
    """A reply with the wrong number or form of lines for its command (treated as corrupt)."""


def _one_int(reply: Reply) -> int:
    if len(reply.lines) != 1:
        raise _ReplyShapeError(f"expected one value line, got {len(reply.lines)}")
    return p.parse_int(reply.lines[0])


def _no_data(reply: Reply) -> None:
    if reply.lines:
        raise _ReplyShapeError(f"expected no data, got {len(reply.lines)} lines")


@dataclass
class _LinkHealth:
    consecutive_failures: int = 0
    lost: LinkLost | None = None
    transactions: int = 0
    failed_attempts: int = 0
    garbage_bytes: int = 0


class DriveClient:
    """An HA-655 / HA-675 on one port. Build with ``DriveClient.open(url)`` or ``attach(transport)``.

    ``trace_packet``: optional ``callable(sending: bool, data: bytes)`` called with every block
    written (True) and read (False): a bus monitor. It runs in the caller's thread, under the lock;
    it must be quick and must not call the client.
    """

    def __init__(self, transport: Transport, settings: LinkSettings | None = None, *, driver: str = "HA-655"):
        """Wrap an open transport without talking to it (``attach`` also detects capabilities)."""
        self.settings = settings or LinkSettings()
        self._transport = (
            transport if isinstance(transport, GuardedTransport) else GuardedTransport(transport)
        )
        self._transport.timeout = self.settings.poll_s
        self._lock = threading.RLock()
        self._decoder = p.StreamDecoder(p.decode_reply)
        self._health = _LinkHealth()
        self._closed = False
        self.model: ParameterModel = load_parameter_model(driver)
        self._capabilities = Capabilities(
            frozenset(p.DOCUMENTED_COMMANDS), None, False, ("Not detected yet.",)
        )
        self._trace_channels: tuple[int, ...] = ()
        self.trace_packet: Callable[[bool, bytes], None] | None = None

    # --- opening and closing ------------------------------------------------------------------

    @classmethod
    def open(cls, url: str, settings: LinkSettings | None = None, *, driver: str = "HA-655") -> DriveClient:
        """Open ``url`` (see ``transport.open_transport``), detect what the drive supports.

        Raises ``LinkLost`` when the port cannot be opened and ``LinkTimeout`` when no drive
        answers; the port is closed again in both cases.
        """
        settings = settings or LinkSettings()
        transport = open_transport(url, baudrate=settings.baudrate, timeout=settings.poll_s)
        return cls.attach(transport, settings, driver=driver)

    @classmethod
    def attach(
        cls, transport: Transport, settings: LinkSettings | None = None, *, driver: str = "HA-655"
    ) -> DriveClient:
        """Use an already open transport (a pipe end, a port) and detect capabilities."""
        client = cls(transport, settings, driver=driver)
        try:
            client.detect_capabilities()
        except BaseException:
            client.close()
            raise
        return client

    def close(self) -> None:
        """Close the port (idempotent). The client cannot be used afterwards."""
        with self._lock:
            if not self._closed:
                self._closed = True
                self._transport.close()

    def __enter__(self) -> DriveClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def port(self) -> str:
        return self._transport.name

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

    # --- the transaction layer (the one retry policy) -------------------------------------------

    def _trace(self, sending: bool, data: bytes) -> None:
        if self.trace_packet is not None and data:
            try:
                self.trace_packet(sending, data)
            except Exception:  # a monitor must never break the link
                log.exception("trace_packet callback failed")

    def _read_some(self) -> bytes:
        waiting = self._transport.in_waiting
        data = self._transport.read(max(1, waiting))
        self._trace(False, data)
        return data

    def _drain_until_quiet(self) -> None:
        """Drop input until the line has been quiet for response_timeout_s: a reply that comes
        late (after its attempt timed out) is dropped here, not taken for the next request's."""
        quiet_until = time.monotonic() + self.settings.response_timeout_s
        give_up = time.monotonic() + self.settings.max_reply_s
        while time.monotonic() < min(quiet_until, give_up):
            if self._read_some():
                quiet_until = time.monotonic() + self.settings.response_timeout_s
        self._transport.reset_input_buffer()
        self._decoder.clear()

    def _attempt(self, request: Request) -> tuple[Reply | None, str]:
        """Send once and wait for one reply: (reply, "") or (None, why it failed)."""
        self._transport.reset_input_buffer()  # stale input from before this request
        stale = self._decoder.clear()
        if stale:
            self._health.garbage_bytes += len(stale)
        data = request.encode()
        self._transport.write(data)
        self._trace(True, data)
        start = time.monotonic()
        deadline = start + self.settings.first_byte_timeout_s(request.command)
        cap = deadline + self.settings.max_reply_s
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
                if message.corrupt or tainted:
                    return None, "corrupt reply (noise inside it)"
                return message, ""

    def _transact(
        self,
        command: Command,
        value: int = 0,
        parse: Callable[[Reply], T] = _no_data,
        *,
        retry: bool | None = None,
    ) -> T:
        """Send ``command`` and return ``parse(reply)``; the one place of the retry policy."""
        request = Request(command, value)
        with self._lock:
            if self._closed:
                raise LinkLost(f"{self.port}: the client is closed", port=self.port)
            if self._health.lost is not None:
                raise LinkLost(str(self._health.lost), port=self.port)
            attempts = 1 if (retry is False or command in NOT_RETRIED) else 1 + self.settings.retries
            why = ""
            try:
                for attempt in range(attempts):
                    if attempt:
                        self._health.failed_attempts += 1
                        log.info("%s: %s failed (%s), retry %d", self.port, command, why, attempt)
                        self._drain_until_quiet()
                    reply, why = self._attempt(request)
                    if reply is None:
                        continue
                    if reply.status is Status.SERVO_ON:
                        self._succeeded()
                        raise ServoOnRefused(f"{command}: refused, the servo is on (not processed)")
                    if reply.status is Status.REJECTED:
                        self._succeeded()
                        raise CommandRejected(f"{command}{value:+06d}: rejected by the drive (x)")
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
            self._drain_quietly()
            unknown = " (not repeated: unknown whether the drive acted on it)" if attempts == 1 else ""
            text = f"{command} on {self.port}: {why} after {attempts} attempt(s){unknown}"
            if self._health.consecutive_failures >= self.settings.max_consecutive_failures:
                lost = LinkLost(
                    f"{text}; {self._health.consecutive_failures} failed transactions in a row: "
                    "link marked lost (check the cable and the drive's power, then reconnect)",
                    port=self.port,
                )
                self._health.lost = lost
                raise lost
            raise LinkTimeout(text)

    def _drain_quietly(self) -> None:
        try:
            self._drain_until_quiet()
        except LinkLost as exc:
            self._health.lost = exc
            raise

    def _succeeded(self) -> None:
        self._health.transactions += 1
        self._health.consecutive_failures = 0

    def _require(self, *commands: Command) -> None:
        missing = [c for c in commands if c not in self._capabilities.commands]
        if missing:
            names = ", ".join(c.value for c in missing)
            raise CommandNotSupported(f"this drive does not have {names}. {self._capabilities.describe()}")

    # --- capabilities and identity ----------------------------------------------------------------

    @property
    def capabilities(self) -> Capabilities:
        return self._capabilities

    def detect_capabilities(self) -> Capabilities:
        """Ask CAP, probe DGR; set and return ``capabilities``. Never hangs on a silent drive:
        raises ``LinkTimeout`` when neither CAP nor DGR gets any answer."""
        notes: list[str] = []
        answered_cap = False
        commands: set[Command] = set(p.DOCUMENTED_COMMANDS)
        with self._lock:
            try:
                names = self._transact(Command.CAP, parse=_cap_names)
                answered_cap = True
                known = {c.value: c for c in Command}
                commands |= {known[n] for n in names if n in known}
                unknown = sorted(n for n in names if n not in known)
                if unknown:
                    notes.append(f"It also lists commands FHA Studio does not know: {' '.join(unknown)}.")
            except DriveRefused:
                answered_cap = True  # x or s: a drive of the manual's command set
            except LinkTimeout:
                notes.append("It did not answer CAP at all.")
            try:
                self._transact(Command.DGR, parse=_one_int)
                absolute: bool | None = True
            except ServoOnRefused:
                absolute = None
            except CommandRejected:
                absolute = False
            except LinkTimeout:
                if not answered_cap:
                    raise LinkTimeout(
                        f"no drive answers on {self.port} (neither CAP nor DGR got a reply): check the "
                        "cable, the port and the drive's power"
                    ) from None
                absolute = None
                notes.append("DGR got no answer.")
            self._capabilities = Capabilities(frozenset(commands), absolute, answered_cap, tuple(notes))
            return self._capabilities

    def identify(self) -> Identity | None:
        """Driver model, adjusted-for actuator, firmware; None on a drive without IDN.

        An HA-675 switches ``model`` to the HA-675 parameter model (same items, all uncertain).
        """
        if Command.IDN not in self._capabilities.commands:
            return None
        identity = self._transact(Command.IDN, parse=_identity)
        driver = "HA-675" if identity.driver_model.upper().startswith("HA-675") else "HA-655"
        if driver != self.model.driver:
            self.model = load_parameter_model(driver)
        return identity

    # --- parameters -------------------------------------------------------------------------------

    def _item(self, mode: Mode | str, number: int) -> ParameterItem:
        try:
            return self.model.item(mode, number)
        except (KeyError, ValueError) as exc:
            raise ParameterValueError(str(exc).strip("'\"")) from None

    def read_parameter(self, mode: Mode | str, number: int) -> int:
        """The wire value of item ``number`` of ``mode`` (scale with ``model.item(...).to_unit``).

        ``mode`` "monitor" reads a monitor item (MON). Raises ``CommandRejected`` when the drive
        has no such item.
        """
        mode = Mode(mode)
        if mode is Mode.MONITOR:
            return self.read_monitor(number)
        select = _SELECT[mode]
        self._require(select, Command.PRD)
        with self._lock:
            self._transact(select, number)
            return self._transact(Command.PRD, parse=_one_int)

    def read_all_parameters(self, mode: Mode | str) -> dict[int, int | None]:
        """Every item of ``mode`` in the parameter model: {number: wire value, None = the drive
        rejected the item}."""
        values: dict[int, int | None] = {}
        with self._lock:
            for item in self.model.in_mode(mode):
                try:
                    values[item.number] = self.read_parameter(item.mode, item.number)
                except CommandRejected:
                    values[item.number] = None
        return values

    def write_parameter(self, mode: Mode | str, number: int, value: int) -> WriteResult:
        """Write and verify by reading back. Checks ``value`` against the model first (nothing is
        sent for a bad value: ``ParameterValueError``).

        Returns a ``WriteResult`` whose ``holds`` says what the drive holds afterwards ("new",
        "old" or "neither"). ``ServoOnRefused`` (parameter-mode item with the servo on) and
        ``CommandRejected`` are raised with the value the drive still holds in the message.
        ``LinkTimeout`` is raised only when even the read-back failed (then it is unknown).
        """
        item = self._item(mode, number)
        if not item.writable:
            raise ParameterValueError(f"{item.label} is read-only")
        item.check(value)
        select = _SELECT[item.mode]
        self._require(select, Command.PRD, Command.PWR)
        with self._lock:
            self._transact(select, number)
            previous = self._transact(Command.PRD, parse=_one_int)
            try:
                self._transact(Command.PWR, value)
            except DriveRefused as exc:
                now = self._transact(Command.PRD, parse=_one_int)
                held = "the old value" if now == previous else "neither the old nor the new value"
                raise type(exc)(f"{item.label}: not written ({exc}); the drive holds {now}, {held}") from None
            except LinkTimeout as exc:
                failure = str(exc)
            else:
                failure = ""
            try:
                self._transact(select, number)
                now = self._transact(Command.PRD, parse=_one_int)
            except LinkTimeout:
                raise LinkTimeout(
                    f"{item.label}: the write of {value} and its read-back failed: unknown whether the "
                    f"drive holds the old ({previous}) or the new value"
                ) from None
        if now == value:
            holds, message = "new", f"{item.label} = {item.format(value)}"
            if item.restart_required and previous != value:
                message += " (takes effect after a power cycle)"
        elif now == previous:
            holds = "old"
            message = f"{item.label}: write of {value} did not take; the drive still holds {now}"
        else:
            holds = "neither"
            message = f"{item.label}: wrote {value} but the drive holds {now} (was {previous})"
        if failure and holds != "new":
            message += f" [{failure}]"
        return WriteResult(item, value, previous, now, holds, message)

    # --- monitors --------------------------------------------------------------------------------

    def read_monitor(self, item: int) -> int:
        """Monitor item ``item`` (MON), wire value."""
        self._require(Command.MON)
        return self._transact(Command.MON, item, parse=_one_int)

    def read_monitors(self, items: Iterable[int]) -> dict[int, int]:
        """Several monitor items at once: MMR for items 100-115 when the drive has it, else one MON
        each. Returns {item: wire value}."""
        items = sorted(set(items))
        if not items:
            return {}
        if Command.MMR in self._capabilities.commands and all(
            p.MONITOR_MASK_BASE <= i < p.MONITOR_MASK_BASE + p.MONITOR_MASK_ITEMS for i in items
        ):
            values = self._transact(Command.MMR, p.monitor_mask(items), parse=_values(len(items)))
            return dict(zip(items, values, strict=True))
        self._require(Command.MON)
        with self._lock:
            return {i: self.read_monitor(i) for i in items}

    # --- motion ----------------------------------------------------------------------------------

    def servo(self, on: bool) -> None:
        """Servo on (True) or off (SVO). A real drive takes servo-on from CN2 only."""
        self._require(Command.SVO)
        self._transact(Command.SVO, 1 if on else 0)

    def jog(self, speed_rpm: float) -> None:
        """Jog the output at ``speed_rpm`` (signed). Holds 100 ms: repeat while the button is held."""
        self._require(Command.JOG)
        self._transact(Command.JOG, _steps(speed_rpm, p.SPEED_STEP_RPM, "jog speed", "r/min"))

    def set_move_speed(self, speed_rpm: float) -> None:
        """Output speed of the following ``move_by`` moves (SPD), > 0."""
        if speed_rpm <= 0:
            raise ValueError(f"move speed must be positive, got {speed_rpm} r/min")
        self._require(Command.SPD)
        self._transact(Command.SPD, _steps(speed_rpm, p.SPEED_STEP_RPM, "move speed", "r/min"))

    def move_by(self, angle_deg: float) -> None:
        """Start a relative move of the output by ``angle_deg`` (MOV; sent once, never repeated)."""
        self._require(Command.MOV)
        self._transact(Command.MOV, _steps(angle_deg, p.ANGLE_STEP_DEG, "move angle", "deg"))

    def stop(self) -> None:
        """Decelerate to standstill and hold (STP)."""
        self._require(Command.STP)
        self._transact(Command.STP)

    # --- alarms and I/O --------------------------------------------------------------------------

    def alarm(self) -> int:
        """The current alarm code, 0 = none (ALM)."""
        self._require(Command.ALM)
        return self._transact(Command.ALM, parse=_one_int)

    def alarm_history(self) -> list[AlarmRecord]:
        """Alarms, newest first (AHS)."""
        self._require(Command.AHS)
        return self._transact(Command.AHS, parse=_alarm_history)

    def clear_alarm(self) -> None:
        """Clear the alarm (ACL); ``CommandRejected`` when it needs a power cycle."""
        self._require(Command.ACL)
        self._transact(Command.ACL)

    def io_state(self) -> IoState:
        """The I/O bits (IOS)."""
        self._require(Command.IOS)
        return IoState(self._transact(Command.IOS, parse=_one_int))

    def set_inputs(self, **inputs: bool) -> IoState:
        """Set simulated CN2 inputs by name (INP, simulated drive only); the others keep their
        state. Names: fwd_inhibit, rev_inhibit, origin_sensor, limit_switch_1, limit_switch_2,
        brake_released, error_counter_clear. Returns the I/O state afterwards."""
        unknown = sorted(set(inputs) - set(INPUT_NAMES))
        if unknown:
            raise ValueError(f"unknown inputs {unknown}; known: {', '.join(sorted(INPUT_NAMES))}")
        self._require(Command.INP, Command.IOS)
        with self._lock:
            mask = self._transact(Command.IOS, parse=_one_int) & p.INPUT_MASK
            for name, on in inputs.items():
                bit = 1 << INPUT_NAMES[name]
                mask = (mask | bit) if on else (mask & ~bit)
            self._transact(Command.INP, mask)
            return IoState(self._transact(Command.IOS, parse=_one_int))

    def power_cycle(self) -> None:
        """Simulated power cycle (PWC, simulated drive only; sent once)."""
        self._require(Command.PWC)
        self._transact(Command.PWC)

    def inject_alarm(self, code: int) -> None:
        """Raise alarm ``code`` as the drive's supervision would (FLT, simulated drive only)."""
        self._require(Command.FLT)
        self._transact(Command.FLT, code)

    def set_sensor_angle(self, which: str, angle_deg: float) -> None:
        """Move the origin slit (``"origin"``) or the dog of limit switch 1 / 2 (``"ls1"``, ``"ls2"``)
        to ``angle_deg`` (output flange, CW positive): SNO / SNA / SNB, simulated drive only."""
        command = {"origin": Command.SNO, "ls1": Command.SNA, "ls2": Command.SNB}.get(which)
        if command is None:
            raise ValueError(f"sensor {which!r}: origin, ls1 or ls2")
        self._require(command)
        self._transact(command, _steps(angle_deg, p.ANGLE_STEP_DEG, "sensor angle", "deg"))

    def sensor_angles(self) -> dict[str, float]:
        """Where the origin slit and the two dogs are (SNQ, simulated drive only), deg:
        ``{"origin": ..., "ls1": ..., "ls2": ...}``."""
        self._require(Command.SNQ)
        values = self._transact(Command.SNQ, parse=_values(3))
        return {k: v * p.ANGLE_STEP_DEG for k, v in zip(("origin", "ls1", "ls2"), values, strict=True)}

    # --- the documented commands -----------------------------------------------------------------

    def absolute_position(self) -> int:
        """DGR: multi-turn x 8192 + single-turn count (``protocol.split_absolute_position``).
        ``ServoOnRefused`` with the servo on, ``CommandRejected`` with an incremental encoder."""
        return self._transact(Command.DGR, parse=_one_int)

    def clear_multiturn(self) -> None:
        """OWW: clear the multi-turn data; waits for the drive's acknowledgement (~5 s)."""
        self._transact(Command.OWW)

    # --- trace capture ---------------------------------------------------------------------------

    def configure_trace(
        self,
        channels: Iterable[int],
        *,
        divider: int = 1,
        trigger: p.TriggerKind = p.TriggerKind.IMMEDIATE,
        trigger_channel: int = 0,
        trigger_level: int = 0,
        pre_trigger: int = 0,
    ) -> tuple[int, ...]:
        """Set up a capture of monitor items 100-115 (at most 4). Returns the channels in the
        order their values come back."""
        mask = p.monitor_mask(channels)
        ordered = tuple(p.mask_items(mask))
        if not 1 <= len(ordered) <= p.TRACE_MAX_CHANNELS:
            raise ValueError(f"a trace has 1 ... {p.TRACE_MAX_CHANNELS} channels, got {len(ordered)}")
        self._require(*_TRACE_COMMANDS)
        with self._lock:
            self._transact(Command.TCH, mask)
            self._transact(Command.TDV, divider)
            self._transact(Command.TTG, int(trigger))
            self._transact(Command.TTC, trigger_channel)
            self._transact(Command.TTL, trigger_level)
            self._transact(Command.TPR, pre_trigger)
            self._trace_channels = ordered
        return ordered

    def arm_trace(self, samples: int) -> None:
        """Arm a capture of ``samples`` (1 ... 4096) samples."""
        if not 1 <= samples <= p.TRACE_MAX_SAMPLES:
            raise ValueError(f"trace samples must be 1 ... {p.TRACE_MAX_SAMPLES}, got {samples}")
        self._require(Command.TAR)
        self._transact(Command.TAR, samples)

    def trace_status(self) -> TraceStatus:
        self._require(Command.TST)
        return self._transact(Command.TST, parse=_trace_status)

    def read_trace_block(self, block: int, count: int) -> list[tuple[int, ...]]:
        """TRB: block ``block`` (64 samples) of a finished capture of ``count`` samples, one row of
        wire values per sample in the order ``configure_trace`` returned. One exchange (~1 s for
        4 channels at 19200 bit/s)."""
        self._require(Command.TRB)
        channels = self._trace_channels
        if not channels:
            raise ValueError("read_trace_block: configure_trace first (the channels are not known)")
        expect = min(p.TRACE_BLOCK_SAMPLES, count - block * p.TRACE_BLOCK_SAMPLES)
        if block < 0 or expect <= 0:
            raise ValueError(f"read_trace_block: block {block} is outside a capture of {count} samples")
        return self._transact(Command.TRB, block, parse=_trace_block(expect, len(channels)))

    def read_trace(self, should_abort: Callable[[], bool] | None = None) -> TraceCapture:
        """Read out the finished capture, block by block (TRB).

        ``should_abort`` is asked before every block (e.g. a STOP's ``threading.Event.is_set``);
        when it says True the read-out gives up there with ``ReadAborted`` (``done`` / ``total``
        samples), so it keeps the link at most one block (~1 s) after being asked.
        """
        self._require(Command.TST, Command.TRB)
        with self._lock:
            channels = self._trace_channels
            if not channels:
                raise ValueError("read_trace: configure_trace first (the channels are not known)")
            status = self.trace_status()
            if status.state is not p.TraceState.DONE:
                raise CommandRejected(f"no finished capture (state {status.state.name.lower()})")
            rows: list[tuple[int, ...]] = []
            for block in range(math.ceil(status.count / p.TRACE_BLOCK_SAMPLES)):
                if should_abort is not None and should_abort():
                    raise ReadAborted(f"trace read-out stopped after {len(rows)} of {status.count} samples",
                                      len(rows), status.count)
                rows += self.read_trace_block(block, status.count)
        return TraceCapture(channels, tuple(rows))


# --- reply parsers (ValueError = malformed: the attempt is retried) ---------------------------------


def _cap_names(reply: Reply) -> list[str]:
    if len(reply.lines) != 1:
        raise _ReplyShapeError("CAP: expected one line")
    names = reply.lines[0].split()
    if not all(len(n) == 3 and n.isalpha() and n.isupper() for n in names):
        raise _ReplyShapeError("CAP: expected three-letter command names")
    return names


def _identity(reply: Reply) -> Identity:
    if len(reply.lines) != 3:
        raise _ReplyShapeError("IDN: expected three lines")
    return Identity(*reply.lines)


def _values(count: int) -> Callable[[Reply], list[int]]:
    def parse(reply: Reply) -> list[int]:
        if len(reply.lines) != 1:
            raise _ReplyShapeError("expected one line of values")
        values = p.parse_values(reply.lines[0])
        if len(values) != count:
            raise _ReplyShapeError(f"expected {count} values, got {len(values)}")
        return values

    return parse


def _alarm_history(reply: Reply) -> list[AlarmRecord]:
    records = []
    for line in reply.lines:
        values = p.parse_values(line)
        if len(values) != 2:
            raise _ReplyShapeError(f"AHS: expected code,seconds, got {line!r}")
        records.append(AlarmRecord(*values))
    return records


def _trace_status(reply: Reply) -> TraceStatus:
    state, count = _values(2)(reply)
    return TraceStatus(p.TraceState(state), count)


def _trace_block(samples: int, channels: int) -> Callable[[Reply], list[tuple[int, ...]]]:
    def parse(reply: Reply) -> list[tuple[int, ...]]:
        if len(reply.lines) != samples:
            raise _ReplyShapeError(f"TRB: expected {samples} lines, got {len(reply.lines)}")
        rows = [tuple(p.parse_values(line)) for line in reply.lines]
        if any(len(row) != channels for row in rows):
            raise _ReplyShapeError(f"TRB: expected {channels} values per line")
        return rows

    return parse


def _steps(value: float, step: float, what: str, unit: str) -> int:
    steps = round(value / step)
    if not p.VALUE_MINIMUM <= steps <= p.VALUE_MAXIMUM:
        limit = p.VALUE_MAXIMUM * step
        raise ValueError(f"{what} {value} {unit} is outside -{limit:g} ... {limit:g} {unit}")
    return steps
