"""The CN3 codec of the HA-655 / HA-675: bytes <-> messages, both directions, no I/O.

docs/protocol.md is the specification; this module is its executable form.

Client side: ``encode_request(Request)`` -> bytes; ``decode_reply(buffer)`` -> (used, message).
Drive side:  ``decode_request(buffer)`` -> (used, message); ``encode_reply(Reply)`` -> bytes.

Decoders follow the pymodbus framer contract: the caller owns the buffer and calls
``decode(buffer)`` which answers ``(bytes_used, message_or_None)``. ``used == 0`` means "need more
bytes"; otherwise the caller drops ``buffer[:used]`` and, if the message is not None, handles it,
then calls again. Skipped bytes come out as a ``Garbage`` message so that nothing vanishes
silently. The decoders never raise for any input. ``StreamDecoder`` wraps that loop.

Resynchronisation rules (docs/protocol.md, "Resynchronisation"):

- Requests (drive side): a frame is ``[A-Z]{3}[+-][0-9]{5}CR``. The decoder takes the earliest
  complete frame in the buffer and reports everything before it as garbage. Without a complete
  frame it keeps the shortest tail that could still become one and reports the bytes before that
  tail as garbage; so a half frame followed by a good frame loses only the half frame.
- Replies (client side): a line ends in CR. Bytes that are neither printable ASCII (20h-7Eh) nor
  CR are noise. Noise and empty lines before the first printable character are reported as
  garbage. Once a reply has begun, its lines accumulate until a terminal line (``q``, ``s`` or
  ``x``); noise or an empty line inside it is dropped and the reply comes out ``corrupt=True``, so
  the client retries instead of trusting it. A line longer than ``MAX_LINE_CHARS`` ends the reply
  in progress as garbage.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from enum import Enum, IntEnum, StrEnum
from typing import Generic, TypeVar

from fha_studio.hardware import packed as _packed

CR = 0x0D
FRAME_LENGTH = 10
VALUE_MINIMUM = -99999
VALUE_MAXIMUM = 99999
#: Longest data line accepted in a reply (characters, without CR). TRB's widest line is 4 x 12.
MAX_LINE_CHARS = 200

#: Line settings of CN3 (HA-655 manual p.20): 19200 bit/s, 8N1 = 10 bits per character.
BAUDRATE = 19200
#: The baud rates FHA Studio opens a serial link at (the GUI's --baud and connect dialog, the
#: drive command's --baud): CN3 runs at BAUDRATE and at no other rate (HA-655 manual p.20), so
#: this is the one; a drive documented to run at others adds them here, in one place.
BAUD_RATES: tuple[int, ...] = (BAUDRATE,)
BITS_PER_CHARACTER = 10


def character_time_s(baudrate: int = BAUDRATE) -> float:
    """Seconds one character takes on the line at ``baudrate`` (8N1: 10 bits)."""
    return BITS_PER_CHARACTER / baudrate


class Command(StrEnum):
    """Every command of docs/protocol.md; what is known of each is its row in :data:`COMMAND_FACTS`."""

    DGR = "DGR"
    OWW = "OWW"
    IDN = "IDN"
    CAP = "CAP"
    PSL = "PSL"
    TSL = "TSL"
    JSL = "JSL"
    PRD = "PRD"
    PWR = "PWR"
    MON = "MON"
    MMR = "MMR"
    SVO = "SVO"
    JOG = "JOG"
    SPD = "SPD"
    MOV = "MOV"
    STP = "STP"
    ALM = "ALM"
    AHS = "AHS"
    ACL = "ACL"
    IOS = "IOS"
    INP = "INP"
    PWC = "PWC"
    TCH = "TCH"
    TDV = "TDV"
    TTG = "TTG"
    TTC = "TTC"
    TTL = "TTL"
    TPR = "TPR"
    TAR = "TAR"
    TST = "TST"
    TRB = "TRB"
    TRP = "TRP"
    FLT = "FLT"
    SNO = "SNO"
    SNA = "SNA"
    SNB = "SNB"
    SNQ = "SNQ"
    EXA = "EXA"
    EXL = "EXL"
    EXG = "EXG"


class Status(StrEnum):
    """Terminal line of a reply."""

    DONE = "q"
    SERVO_ON = "s"  # refused: the servo is on, the command was not processed
    REJECTED = "x"  # bad command: unknown, malformed, not allowed now, out of range


_TERMINALS = {s.value.encode(): s for s in Status}


@dataclass(frozen=True)
class Request:
    """A command frame, host -> drive. ``value`` is the signed five-digit field."""

    command: Command
    value: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.command, Command):
            raise ValueError(f"not a CN3 command: {self.command!r}")
        if isinstance(self.value, bool) or not isinstance(self.value, int):
            raise ValueError(f"{self.command}: value must be an integer, got {self.value!r}")
        if not VALUE_MINIMUM <= self.value <= VALUE_MAXIMUM:
            raise ValueError(
                f"{self.command}: value {self.value} outside {VALUE_MINIMUM} ... {VALUE_MAXIMUM}"
            )

    def encode(self) -> bytes:
        return encode_request(self)


@dataclass(frozen=True)
class UnknownRequest:
    """A well-formed frame whose three letters are no command: the drive answers ``x``."""

    name: str
    value: int


@dataclass(frozen=True)
class Reply:
    """A reply, drive -> host: data lines (without CR) and the terminal status.

    ``corrupt`` is set by the decoder when noise was dropped inside the reply: its data cannot be
    trusted and the client retries.
    """

    lines: tuple[str, ...] = ()
    status: Status = Status.DONE
    corrupt: bool = False

    def encode(self) -> bytes:
        return encode_reply(self)


@dataclass(frozen=True)
class Garbage:
    """Bytes a decoder skipped, and why (for a bus monitor and for the client's retry decision)."""

    data: bytes
    reason: str

    @property
    def printable(self) -> bool:
        """True when any skipped byte was printable: it may have been part of a message."""
        return any(0x20 <= b <= 0x7E for b in self.data)


# ---------------------------------------------------------------------------------------------
# Requests
# ---------------------------------------------------------------------------------------------

_FRAME = re.compile(rb"[A-Z]{3}[+-][0-9]{5}\r")
_COMMANDS_BY_NAME = {c.value: c for c in Command}


def encode_request(request: Request) -> bytes:
    """``Request(DGR, 0)`` -> ``b"DGR+00000\\r"``."""
    sign = "-" if request.value < 0 else "+"
    return f"{request.command.value}{sign}{abs(request.value):05d}\r".encode("ascii")


def _could_start_frame(tail: bytes) -> bool:
    """True when ``tail`` (shorter than a frame) is a prefix of some valid frame."""
    for i, byte in enumerate(tail):
        if i < 3:
            ok = 0x41 <= byte <= 0x5A
        elif i == 3:
            ok = byte in b"+-"
        elif i < 9:
            ok = 0x30 <= byte <= 0x39
        else:  # pragma: no cover - tails are shorter than a frame
            ok = byte == CR
        if not ok:
            return False
    return True


def decode_request(buffer: bytes | bytearray) -> tuple[int, Request | UnknownRequest | Garbage | None]:
    """Drive side: the next request in ``buffer`` (see the module's resynchronisation rule)."""
    data = bytes(buffer)
    match = _FRAME.search(data)
    if match is not None:
        if match.start() > 0:
            return match.start(), Garbage(data[: match.start()], "bytes before a request frame")
        name = data[:3].decode("ascii")
        sign = -1 if data[3:4] == b"-" else 1
        value = sign * int(data[4:9])
        command = _COMMANDS_BY_NAME.get(name)
        if command is None:
            return FRAME_LENGTH, UnknownRequest(name, value)
        return FRAME_LENGTH, Request(command, value)
    # No complete frame: keep the earliest tail that may still grow into one.
    start = max(0, len(data) - (FRAME_LENGTH - 1))
    for i in range(start, len(data)):
        if _could_start_frame(data[i:]):
            break
    else:
        i = len(data)
    if i == 0:
        return 0, None
    return i, Garbage(data[:i], "bytes that cannot start a request frame")


# ---------------------------------------------------------------------------------------------
# Replies
# ---------------------------------------------------------------------------------------------


def _printable(byte: int) -> bool:
    return 0x20 <= byte <= 0x7E


def check_data_line(line: str) -> None:
    """Raise ValueError unless ``line`` may be sent as a data line of a reply."""
    if not line or len(line) > MAX_LINE_CHARS:
        raise ValueError(f"data line must have 1 ... {MAX_LINE_CHARS} characters: {line!r}")
    if any(not 0x20 <= ord(ch) <= 0x7E for ch in line):
        raise ValueError(f"data line must be printable ASCII: {line!r}")
    if line in ("q", "s", "x"):
        raise ValueError(f"a data line cannot be a lone terminal character: {line!r}")


def encode_reply(reply: Reply) -> bytes:
    """``Reply(("123",), DONE)`` -> ``b"123\\rq\\r"``. Raises ValueError for an invalid data line."""
    for line in reply.lines:
        check_data_line(line)
    body = b"".join(line.encode("ascii") + b"\r" for line in reply.lines)
    return body + reply.status.value.encode("ascii") + b"\r"


def decode_reply(buffer: bytes | bytearray) -> tuple[int, Reply | Garbage | None]:
    """Client side: the next reply in ``buffer`` (see the module's resynchronisation rule)."""
    data = bytes(buffer)
    n = len(data)
    lead = 0
    while lead < n and not _printable(data[lead]):
        lead += 1
    if lead:
        return lead, Garbage(data[:lead], "noise or empty line before a reply")
    lines: list[str] = []
    corrupt = False
    pos = 0
    while True:
        end = data.find(b"\r", pos)
        if end < 0:
            if n - pos > MAX_LINE_CHARS:
                return n, Garbage(data, f"a reply line longer than {MAX_LINE_CHARS} characters")
            return 0, None
        raw = data[pos:end]
        if len(raw) > MAX_LINE_CHARS:
            return end + 1, Garbage(data[: end + 1], f"a reply line longer than {MAX_LINE_CHARS} characters")
        pos = end + 1
        clean = bytes(b for b in raw if _printable(b))
        if len(clean) != len(raw) or not clean:
            corrupt = True
        if not clean:
            continue
        status = _TERMINALS.get(clean)
        if status is not None:
            return pos, Reply(tuple(lines), status, corrupt)
        lines.append(clean.decode("ascii"))


# ---------------------------------------------------------------------------------------------
# Stream helper and value formats
# ---------------------------------------------------------------------------------------------

M = TypeVar("M")


class StreamDecoder(Generic[M]):
    """Holds received bytes and yields whole messages: ``feed(data)`` -> list of messages.

    ``StreamDecoder(decode_request)`` on the drive side, ``StreamDecoder(decode_reply)`` on the
    client side. Garbage messages are returned like the others.
    """

    def __init__(self, decode: Callable[[bytes | bytearray], tuple[int, M | None]]):
        self._decode = decode
        self._buffer = bytearray()

    def feed(self, data: bytes | bytearray = b"") -> list[M]:
        self._buffer += data
        messages: list[M] = []
        while self._buffer:
            used, message = self._decode(self._buffer)
            if used == 0:
                break
            del self._buffer[:used]
            if message is not None:
                messages.append(message)
        return messages

    @property
    def pending(self) -> bytes:
        """Bytes received but not yet part of a message."""
        return bytes(self._buffer)

    def clear(self) -> bytes:
        """Drop and return the pending bytes (the client does this before each request)."""
        dropped = bytes(self._buffer)
        self._buffer.clear()
        return dropped


def format_values(values: Iterable[int]) -> str:
    """Comma-separated integers, the format of MMR, TRB, TST and AHS lines: ``"12,-3,0"``."""
    return ",".join(str(int(v)) for v in values)


def parse_values(line: str) -> list[int]:
    """The integers of a comma-separated line; ValueError naming the line when it is not one."""
    try:
        return [int(part) for part in line.split(",")]
    except ValueError:
        raise ValueError(f"expected comma-separated integers, got {line!r}") from None


def parse_int(line: str) -> int:
    """One signed decimal integer (``-`` only when negative, as DGR's reply); ValueError otherwise."""
    if not re.fullmatch(r"[+-]?[0-9]{1,12}", line):
        raise ValueError(f"expected a signed integer, got {line!r}")
    return int(line)


#: Single-turn counts per motor turn of the absolute encoder: DGR = multi-turn x 8192 + single-turn
#: (HA-655 manual p.21). The one constant of the wire format; the catalogue's absolute encoder
#: (resources/catalog/specs.toml, FHA-C manual 1-8: 13 bit) says the same, a test keeps them equal.
ABSOLUTE_COUNTS_PER_TURN = 8192


def split_absolute_position(value: int) -> tuple[int, int]:
    """DGR's value -> (multi-turn, single-turn count 0 ... 8191)."""
    return divmod(value, ABSOLUTE_COUNTS_PER_TURN)


def join_absolute_position(multi_turn: int, single_turn: int) -> int:
    """(multi-turn, single-turn count) -> DGR's value."""
    return multi_turn * ABSOLUTE_COUNTS_PER_TURN + single_turn


# ---------------------------------------------------------------------------------------------
# Numbers the extension commands share (docs/protocol.md)
# ---------------------------------------------------------------------------------------------

#: JOG and SPD values are output speed in 0.01 r/min; MOV values are output angle in 0.01 deg.
SPEED_STEP_RPM = 0.01
ANGLE_STEP_DEG = 0.01
#: A JOG holds this long; without a repeat the axis decelerates to a stop (watchdog).
JOG_HOLD_S = 0.1
#: MMR and TCH masks: bit k selects monitor item MONITOR_MASK_BASE + k.
MONITOR_MASK_BASE = 100
MONITOR_MASK_ITEMS = 16
TRACE_MAX_CHANNELS = 4
TRACE_MAX_SAMPLES = 4096
TRACE_BLOCK_SAMPLES = 64
#: EXA's step (r/min): finer than JOG's, a heavy axis is excited by hundredths of a r/min
EXCITATION_STEP_RPM = 0.0001
#: The excitation (EXG): shortest and longest shift register of its PRBS, in bits
EXCITATION_MIN_BITS = 4
EXCITATION_MAX_BITS = 12


def excitation_register_bits(hold_periods: int) -> int:
    """Length of the excitation's shift register for bits held ``hold_periods`` servo periods:
    the longest whose period, (2^bits - 1) x hold, still fits one trace (TRACE_MAX_SAMPLES), so a
    capture of one period at the servo rate is leakage-free (docs/protocol.md, EXG)."""
    bits = EXCITATION_MAX_BITS
    while bits > EXCITATION_MIN_BITS and ((1 << bits) - 1) * hold_periods > TRACE_MAX_SAMPLES:
        bits -= 1
    return bits


def excitation_period_periods(hold_periods: int) -> int:
    """Servo periods in one period of the excitation's PRBS."""
    return ((1 << excitation_register_bits(hold_periods)) - 1) * hold_periods


class IoBit(IntEnum):
    """Bits of the IOS reply and monitor item 106; INP sets the input bits."""

    SERVO_ON = 0
    READY = 1
    ALARM = 2
    IN_POSITION = 3
    FWD_INHIBIT = 4
    REV_INHIBIT = 5
    ORIGIN_SENSOR = 6
    LIMIT_SWITCH_1 = 7
    LIMIT_SWITCH_2 = 8
    BRAKE_RELEASED = 9
    ERROR_COUNTER_CLEAR = 10
    ALM_A = 11
    ALM_B = 12
    ALM_C = 13
    ALM_D = 14
    MOVING = 15


#: The bits INP may set (the simulated CN2 inputs).
INPUT_BITS = frozenset(
    {
        IoBit.FWD_INHIBIT,
        IoBit.REV_INHIBIT,
        IoBit.ORIGIN_SENSOR,
        IoBit.LIMIT_SWITCH_1,
        IoBit.LIMIT_SWITCH_2,
        IoBit.BRAKE_RELEASED,
        IoBit.ERROR_COUNTER_CLEAR,
    }
)
INPUT_MASK = sum(1 << b for b in INPUT_BITS)


def alm_bits_from_io(mask: int) -> int:
    """The 4-bit alarm code (bit 0 = ALM-A ... bit 3 = ALM-D) from an I/O mask."""
    return (mask >> IoBit.ALM_A) & 0xF


def io_with_alm_bits(mask: int, alm_bits: int) -> int:
    """``mask`` with its ALM-A ... ALM-D bits set to ``alm_bits``."""
    return (mask & ~(0xF << IoBit.ALM_A)) | ((alm_bits & 0xF) << IoBit.ALM_A)


class TriggerKind(IntEnum):
    """TTG values."""

    IMMEDIATE = 0
    RISING_LEVEL = 1
    FALLING_LEVEL = 2
    IO_BIT_RISES = 3
    IO_BIT_FALLS = 4
    ALARM = 5


class TraceState(IntEnum):
    """First value of the TST reply."""

    IDLE = 0
    ARMED = 1
    CAPTURING = 2
    DONE = 3


def monitor_mask(items: Iterable[int]) -> int:
    """MMR/TCH mask for monitor items 100-115; ValueError naming an item outside that range."""
    mask = 0
    for item in items:
        if not MONITOR_MASK_BASE <= item < MONITOR_MASK_BASE + MONITOR_MASK_ITEMS:
            raise ValueError(
                f"monitor item {item} cannot be in a mask (items {MONITOR_MASK_BASE} ... "
                f"{MONITOR_MASK_BASE + MONITOR_MASK_ITEMS - 1})"
            )
        mask |= 1 << (item - MONITOR_MASK_BASE)
    return mask


def mask_items(mask: int) -> list[int]:
    """The monitor items of an MMR/TCH mask, in item order (the order of the reply's values)."""
    return [MONITOR_MASK_BASE + k for k in range(MONITOR_MASK_ITEMS) if mask >> k & 1]


# ---------------------------------------------------------------------------------------------
# Each command's facts: one row per command (docs/protocol.md, the Commands table)
# ---------------------------------------------------------------------------------------------


class SlowReply(Enum):
    """Why a command's reply may take longer than the response timeout; the link's settings say
    how long each may take (``LinkSettings.slow_reply_timeout_s``)."""

    MULTI_TURN_CLEAR = "clearing the multi-turn data"  # OWW: "q about 5 s later" (manual p.21)
    POWER_CYCLE = "a power cycle"
    EEPROM_WRITE = "an EEPROM write"


class TraceRole(Enum):
    """A command's part in a drive-side trace capture."""

    CAPTURE = "capture"  # a drive that lists every one of these records traces
    PACKED_READ = "packed read"  # the packed block read: used when listed, TRB otherwise


#: Longest trace block reply: 64 lines of 4 values of up to 11 characters, commas, CRs, terminal.
TRACE_BLOCK_REPLY_CHARS = TRACE_BLOCK_SAMPLES * (TRACE_MAX_CHANNELS * 12 + 1) + 2
#: Longest reply of the other commands: CAP, IDN, MMR of 16 items and every one-line reply fit.
DEFAULT_REPLY_CHARS = 256


@dataclass(frozen=True)
class CommandFacts:
    """What is known of one CN3 command: its row in :data:`COMMAND_FACTS`."""

    #: what the command asks the drive to do, in words for a person ("the drive refused to ...")
    words: str
    #: the public HA-655 manual documents it (p.21); every other command is an extension (in CAP)
    documented: bool = False
    #: only the simulated drive has it (a real drive answers x)
    sim_only: bool = False
    #: its value names what it acts on (an item or alarm number): said with the words
    numbered: bool = False
    #: False when a repetition could act twice: sent once, never retried
    retried: bool = True
    #: why its reply may come later than the response timeout, None when it does not
    slow: SlowReply | None = None
    #: its part in a drive-side trace capture, None for none
    trace: TraceRole | None = None
    #: the longest reply it may give, in characters
    longest_reply_chars: int = DEFAULT_REPLY_CHARS


_CAPTURE, _BLOCK = TraceRole.CAPTURE, TRACE_BLOCK_REPLY_CHARS

#: One row per command: everything the codec, the client, the transaction layer, the simulated
#: drive and the test fakes need to know of it (docs/protocol.md, the Commands table).
COMMAND_FACTS: dict[Command, CommandFacts] = {
    Command.DGR: CommandFacts("report the absolute position", documented=True),
    Command.OWW: CommandFacts("clear the multi-turn data", documented=True, retried=False,
                              slow=SlowReply.MULTI_TURN_CLEAR),
    Command.IDN: CommandFacts("say what it is"),
    Command.CAP: CommandFacts("list the commands it has"),
    Command.PSL: CommandFacts("select parameter-mode item", numbered=True),
    Command.TSL: CommandFacts("select tune-mode item", numbered=True),
    Command.JSL: CommandFacts("select test-mode item", numbered=True),
    Command.PRD: CommandFacts("read the selected item"),
    Command.PWR: CommandFacts("write the selected item", slow=SlowReply.EEPROM_WRITE),
    Command.MON: CommandFacts("read monitor item", numbered=True),
    Command.MMR: CommandFacts("read the monitor items"),
    Command.SVO: CommandFacts("switch the servo"),
    Command.JOG: CommandFacts("jog"),  # at a speed, held by repetition
    Command.SPD: CommandFacts("set the move speed"),  # for MOV
    Command.MOV: CommandFacts("move by an angle", retried=False),
    Command.STP: CommandFacts("stop"),
    Command.ALM: CommandFacts("report the alarm"),
    Command.AHS: CommandFacts("report the alarm history", longest_reply_chars=1024),  # a line per alarm
    Command.ACL: CommandFacts("clear the alarm"),
    Command.IOS: CommandFacts("report its inputs and outputs"),
    Command.INP: CommandFacts("set the simulated inputs", sim_only=True),
    Command.PWC: CommandFacts("power-cycle", sim_only=True, retried=False, slow=SlowReply.POWER_CYCLE),
    Command.TCH: CommandFacts("set the trace channels", trace=_CAPTURE),
    Command.TDV: CommandFacts("set the trace sample rate", trace=_CAPTURE),
    Command.TTG: CommandFacts("set the trace trigger", trace=_CAPTURE),
    Command.TTC: CommandFacts("set the trace trigger channel", trace=_CAPTURE),
    Command.TTL: CommandFacts("set the trace trigger level", trace=_CAPTURE),
    Command.TPR: CommandFacts("set the trace pre-trigger", trace=_CAPTURE),
    Command.TAR: CommandFacts("arm the trace", trace=_CAPTURE),
    Command.TST: CommandFacts("report the trace state", trace=_CAPTURE),
    Command.TRB: CommandFacts("send a trace block", trace=_CAPTURE, longest_reply_chars=_BLOCK),
    Command.TRP: CommandFacts("send a trace block", trace=TraceRole.PACKED_READ, longest_reply_chars=_BLOCK),
    Command.FLT: CommandFacts("raise alarm", sim_only=True, numbered=True),  # inject one
    Command.SNO: CommandFacts("move the origin slit", sim_only=True),
    Command.SNA: CommandFacts("move the dog of limit switch 1", sim_only=True),
    Command.SNB: CommandFacts("move the dog of limit switch 2", sim_only=True),
    Command.SNQ: CommandFacts("report the sensor angles", sim_only=True),
    Command.EXA: CommandFacts("set the excitation amplitude"),
    Command.EXL: CommandFacts("set the excitation travel limit"),
    Command.EXG: CommandFacts("run the excitation"),  # held by repetition, as JOG
}


def _commands(test: Callable[[CommandFacts], bool]) -> frozenset[Command]:
    return frozenset(c for c, facts in COMMAND_FACTS.items() if test(facts))


#: What each command asks the drive to do, in words for a person.
COMMAND_WORDS: dict[Command, str] = {c: facts.words for c, facts in COMMAND_FACTS.items()}
#: Commands whose value names what they act on (an item or alarm number): said with the words.
NUMBERED_COMMANDS = _commands(lambda f: f.numbered)
#: The commands a real HA-655 is known to answer (its public manual, p.21).
DOCUMENTED_COMMANDS = _commands(lambda f: f.documented)
#: Commands that only the simulated drive has (a real drive answers x).
SIM_ONLY_COMMANDS = _commands(lambda f: f.sim_only)
#: Extension commands a drive lists in its CAP reply.
EXTENSION_COMMANDS = _commands(lambda f: not f.documented)
#: Commands whose repetition could act twice; sent once, never retried.
NOT_RETRIED = _commands(lambda f: not f.retried)
#: The commands of a drive-side trace capture (a drive that lists them all records traces).
TRACE_COMMANDS = _commands(lambda f: f.trace is TraceRole.CAPTURE)


def command_words(command: Command | str, value: int | None = None) -> str:
    """What ``command`` asks the drive to do, in words ("move by an angle", "select
    parameter-mode item 8" with its ``value`` where the value names the item)."""
    try:
        command = Command(command)
        words = COMMAND_WORDS[command]
    except (KeyError, ValueError):
        return f"answer {command}"
    return f"{words} {value}" if value is not None and command in NUMBERED_COMMANDS else words


def servo_on_text(command: Command | str) -> str:
    """What a refusal ``s`` (servo on) says to a person: "the drive does not move by an angle
    while the servo is on"."""
    return f"the drive does not {command_words(command)} while the servo is on"


def rejected_text(command: Command | str, value: int | None = None) -> str:
    """What a refusal ``x`` says to a person: "the drive refused to select parameter-mode item 5"."""
    return f"the drive refused to {command_words(command, value)}"


# ---------------------------------------------------------------------------------------------
# The packed trace block (TRP): packed.py; its names are the protocol's too
# ---------------------------------------------------------------------------------------------

PACKED_ALPHABET = _packed.PACKED_ALPHABET
PACKED_LINE_CHARS = _packed.PACKED_LINE_CHARS
PACKED_CHECK_MODULUS = _packed.PACKED_CHECK_MODULUS
packed_check = _packed.packed_check
encode_packed_block = _packed.encode_packed_block
decode_packed_block = _packed.decode_packed_block
