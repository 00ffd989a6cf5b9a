"""DriveClient: the user's API to an HA-655 / HA-675 over CN3 (docs/protocol.md); a ``DriveApi``.

Three layers, as in pymodbus: the transport moves bytes (``transport``), ``transaction`` frames
one request and its reply (lock, stale-input flush, timeouts, the one retry policy, resync, link
health, bus monitor), and this module is the client: what each command means, capability checks,
verified writes. One ``DriveClient`` owns its port; every public method may be called from any
thread (the transaction's RLock serialises them, and multi-command operations such as
select-then-read hold it throughout). Calls block for at most a few hundred milliseconds
(``clear_multiturn`` ~6 s), so a GUI runs them in its link worker thread, never in its GUI
thread.

The result types and errors live in ``api`` and ``errors`` and are re-exported here.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from fha_studio.hardware import protocol as p
from fha_studio.hardware.api import (
    INPUT_NAMES,
    TRACE_COMMANDS,
    AlarmRecord,
    Capabilities,
    CapabilityLevel,
    DriveApi,
    Held,
    Identity,
    IoState,
    SensorName,
    SimPanel,
    TraceCapture,
    TraceStatus,
    WriteResult,
)
from fha_studio.hardware.errors import (
    CommandNotSupported,
    CommandRejected,
    DriveRefused,
    LinkError,
    LinkFailure,
    LinkGarbled,
    LinkLost,
    LinkSilent,
    LinkTimeout,
    ReadAborted,
    ServoOnRefused,
)
from fha_studio.hardware.parameters import (
    Mode,
    ParameterItem,
    ParameterModel,
    ParameterValueError,
    driver_family,
    load_parameter_model,
)
from fha_studio.hardware.protocol import Command, Reply
from fha_studio.hardware.trace_readout import block_samples, read_out
from fha_studio.hardware.transaction import (
    NOT_RETRIED,
    LinkSettings,
    PacketMonitor,
    ReplyShapeError,
    Transaction,
    one_int,
)
from fha_studio.hardware.transport import Transport, open_transport

__all__ = [
    "INPUT_NAMES",
    "NOT_RETRIED",
    "AlarmRecord",
    "Capabilities",
    "CapabilityLevel",
    "CommandNotSupported",
    "CommandRejected",
    "DriveApi",
    "DriveClient",
    "DriveRefused",
    "Held",
    "Identity",
    "IoState",
    "LinkError",
    "LinkFailure",
    "LinkGarbled",
    "LinkLost",
    "LinkSettings",
    "LinkSilent",
    "LinkTimeout",
    "ReadAborted",
    "ServoOnRefused",
    "TraceCapture",
    "TraceStatus",
    "Transaction",
    "WriteResult",
]

#: The command that selects an item of each front-panel mode before PRD/PWR.
SELECT_COMMAND = {Mode.TUNE: Command.TSL, Mode.SYSTEM: Command.PSL, Mode.TEST: Command.JSL}
_SENSOR_COMMANDS = {SensorName.ORIGIN: Command.SNO, SensorName.LS1: Command.SNA, SensorName.LS2: Command.SNB}


class DriveClient:
    """An HA-655 / HA-675 on one port. Build with ``DriveClient.open(url)`` or ``attach(transport)``.

    ``trace_packet``: optional ``callable(sending: bool, data: bytes)`` called with every block
    written (True) and read (False): a bus monitor (the transaction's ``packet_monitor``). It runs
    in the caller's thread, under the lock; it must be quick and must not call the client.
    """

    def __init__(
        self,
        transport: Transport,
        settings: LinkSettings | None = None,
        *,
        driver: str = "HA-655",
        should_abort: Callable[[], bool] | None = None,
    ):
        """Wrap an open transport without talking to it (``attach`` also detects capabilities).
        ``should_abort``: asked at every read; True abandons the exchange (``ReadAborted``)."""
        self.transaction = Transaction(transport, settings, should_abort)
        self.settings = self.transaction.settings
        self._lock = self.transaction.lock
        self._transact = self.transaction.transact
        self.model: ParameterModel = load_parameter_model(driver)
        self._capabilities = Capabilities(
            frozenset(p.DOCUMENTED_COMMANDS), None, False, ("Not detected yet.",)
        )
        self._trace_channels: tuple[int, ...] = ()

    # --- opening and closing ------------------------------------------------------------------

    @classmethod
    def open(
        cls,
        url: str,
        settings: LinkSettings | None = None,
        *,
        driver: str = "HA-655",
        should_abort: Callable[[], bool] | None = None,
    ) -> DriveClient:
        """Open ``url`` (see ``transport.open_transport``), detect what the drive supports.

        Raises ``LinkLost`` when the port cannot be opened, ``LinkSilent`` when nothing arrives,
        ``LinkGarbled`` when bytes arrive but no reply; the port is closed again in each case.
        Whatever the line does, it returns or raises within ``open_limit_s(settings)`` (plus the
        time the port itself takes to open), or at the next read after ``should_abort()``.
        """
        settings = settings or LinkSettings()
        transport = open_transport(url, baudrate=settings.baudrate, timeout=settings.poll_s)
        return cls.attach(transport, settings, driver=driver, should_abort=should_abort)

    @staticmethod
    def open_limit_s(settings: LinkSettings | None = None) -> float:
        """The longest wall time of capability detection (``open`` after the port opened)."""
        settings = settings or LinkSettings()
        return settings.transaction_limit_s(Command.CAP) + settings.transaction_limit_s(Command.DGR)

    @classmethod
    def attach(
        cls,
        transport: Transport,
        settings: LinkSettings | None = None,
        *,
        driver: str = "HA-655",
        should_abort: Callable[[], bool] | None = None,
    ) -> DriveClient:
        """Use an already open transport (a pipe end, a port) and detect capabilities."""
        client = cls(transport, settings, driver=driver, should_abort=should_abort)
        try:
            client.detect_capabilities()
        except BaseException:
            client.close()
            raise
        return client

    def close(self) -> None:
        """Close the port (idempotent). The client cannot be used afterwards."""
        self.transaction.close()

    def __enter__(self) -> DriveClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def port(self) -> str:
        return self.transaction.port

    def lose_link_after(self, failures: int) -> None:
        """The link is marked lost (``LinkLost``) after ``failures`` failed transactions in a row
        from now on (the transaction layer's one rule; ``Transaction.lose_link_after``)."""
        self.transaction.lose_link_after(failures)
        self.settings = self.transaction.settings

    @property
    def is_open(self) -> bool:
        return self.transaction.is_open

    @property
    def link_lost(self) -> bool:
        return self.transaction.link_lost

    @property
    def sim_panel(self) -> SimPanel | None:
        """The panel of the embedded simulated drive behind a ``sim://`` port (its CN2 and the
        technician's hands), None for any other drive. For the thread that uses the link."""
        from fha_studio.hardware.sim.protocol_sim import Serial as SimPort

        port = self.transaction.transport.inner
        return port.sim_responder if isinstance(port, SimPort) else None

    @property
    def statistics(self) -> dict[str, int]:
        """Transactions, failed attempts, garbage bytes seen, consecutive failures."""
        return self.transaction.statistics

    @property
    def trace_packet(self) -> PacketMonitor | None:
        return self.transaction.packet_monitor

    @trace_packet.setter
    def trace_packet(self, monitor: PacketMonitor | None) -> None:
        self.transaction.packet_monitor = monitor

    # --- capabilities and identity ----------------------------------------------------------------

    def _require(self, *commands: Command) -> None:
        missing = [c for c in commands if c not in self._capabilities.commands]
        if missing:
            names = ", ".join(c.value for c in missing)
            raise CommandNotSupported(f"this drive does not have {names}. {self._capabilities.describe()}")

    @property
    def capabilities(self) -> Capabilities:
        return self._capabilities

    def detect_capabilities(self) -> Capabilities:
        """Ask CAP, probe DGR; set and return ``capabilities``. Never hangs, whatever the line
        does: raises ``LinkGarbled`` at once when CAP got bytes but no reply (a wrong baud rate or
        device: DGR would fare no better), ``LinkSilent`` when neither CAP nor DGR got a byte."""
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
            except LinkGarbled as exc:
                raise LinkGarbled(f"no drive answers on {self.port}: {exc}") from None
            except LinkTimeout:
                notes.append("It did not answer CAP at all.")
            try:
                self._transact(Command.DGR, parse=one_int)
                absolute: bool | None = True
            except ServoOnRefused:
                absolute = None
            except CommandRejected:
                absolute = False
            except LinkTimeout as exc:
                if not answered_cap:
                    kind = type(exc) if isinstance(exc, LinkSilent | LinkGarbled) else LinkTimeout
                    raise kind(
                        f"no drive answers on {self.port} (neither CAP nor DGR got a reply): {exc}"
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
        driver = driver_family(identity.driver_model)
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
        select = SELECT_COMMAND[mode]
        self._require(select, Command.PRD)
        with self._lock:
            self._transact(select, number)
            return self._transact(Command.PRD, parse=one_int)

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
        select = SELECT_COMMAND[item.mode]
        self._require(select, Command.PRD, Command.PWR)
        with self._lock:
            self._transact(select, number)
            previous = self._transact(Command.PRD, parse=one_int)
            try:
                self._transact(Command.PWR, value)
            except DriveRefused as exc:
                now = self._transact(Command.PRD, parse=one_int)
                held = "the old value" if now == previous else "neither the old nor the new value"
                raise type(exc)(
                    f"{item.label}: not written ({exc}); the drive holds {item.format(now)}, {held}"
                ) from None
            except LinkTimeout as exc:
                failure = str(exc)
            else:
                failure = ""
            try:
                self._transact(select, number)
                now = self._transact(Command.PRD, parse=one_int)
            except LinkTimeout:
                raise LinkTimeout(
                    f"{item.label}: the write of {item.format(value)} and its read-back failed: unknown "
                    f"whether the drive holds the old ({item.format(previous)}) or the new value"
                ) from None
        if now == value:
            holds, message = Held.NEW, f"{item.label} = {item.format(value)}"
            if item.restart_required and previous != value:
                message += " (takes effect after a power cycle)"
        elif now == previous:
            holds = Held.OLD
            message = (
                f"{item.label}: the write of {item.format(value)} did not take; "
                f"the drive still holds {item.format(now)}"
            )
        else:
            holds = Held.NEITHER
            message = (
                f"{item.label}: wrote {item.format(value)} but the drive holds {item.format(now)} "
                f"(was {item.format(previous)})"
            )
        if failure and holds is not Held.NEW:
            message += f" [{failure}]"
        return WriteResult(item, value, previous, now, holds, message)

    # --- monitors --------------------------------------------------------------------------------

    def read_monitor(self, item: int) -> int:
        """Monitor item ``item`` (MON), wire value."""
        self._require(Command.MON)
        return self._transact(Command.MON, item, parse=one_int)

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

    def set_excitation(self, amplitude_rpm: float, travel_limit_deg: float) -> None:
        """The excitation's amplitude (EXA, output r/min) and the angle it may travel (EXL)."""
        self._require(Command.EXA, Command.EXL)
        amplitude = _steps(amplitude_rpm, p.EXCITATION_STEP_RPM, "excitation amplitude", "r/min")
        self._transact(Command.EXA, amplitude)
        self._transact(Command.EXL, _steps(travel_limit_deg, p.ANGLE_STEP_DEG, "travel limit", "deg"))

    def excite(self, hold_periods: int) -> None:
        """Run the excitation (EXG), bits of ``hold_periods`` servo periods; holds 100 ms as JOG:
        repeat while it is to run. 0 stops it."""
        self._require(Command.EXG)
        self._transact(Command.EXG, hold_periods)

    # --- alarms and I/O --------------------------------------------------------------------------

    def alarm(self) -> int:
        """The current alarm code, 0 = none (ALM)."""
        self._require(Command.ALM)
        return self._transact(Command.ALM, parse=one_int)

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
        return IoState(self._transact(Command.IOS, parse=one_int))

    def set_inputs(self, **inputs: bool) -> IoState:
        """Set simulated CN2 inputs by name (INP, simulated drive only); the others keep their
        state. Names: fwd_inhibit, rev_inhibit, origin_sensor, limit_switch_1, limit_switch_2,
        brake_released, error_counter_clear. Returns the I/O state afterwards."""
        unknown = sorted(set(inputs) - set(INPUT_NAMES))
        if unknown:
            raise ValueError(f"unknown inputs {unknown}; known: {', '.join(sorted(INPUT_NAMES))}")
        self._require(Command.INP, Command.IOS)
        with self._lock:
            mask = self._transact(Command.IOS, parse=one_int) & p.INPUT_MASK
            for name, on in inputs.items():
                bit = 1 << INPUT_NAMES[name]
                mask = (mask | bit) if on else (mask & ~bit)
            self._transact(Command.INP, mask)
            return IoState(self._transact(Command.IOS, parse=one_int))

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
        try:
            command = _SENSOR_COMMANDS[SensorName(which)]
        except ValueError:
            raise ValueError(f"sensor {which!r}: origin, ls1 or ls2") from None
        self._require(command)
        self._transact(command, _steps(angle_deg, p.ANGLE_STEP_DEG, "sensor angle", "deg"))

    def sensor_angles(self) -> dict[str, float]:
        """Where the origin slit and the two dogs are (SNQ, simulated drive only), deg:
        ``{"origin": ..., "ls1": ..., "ls2": ...}``."""
        self._require(Command.SNQ)
        values = self._transact(Command.SNQ, parse=_values(3))
        return {k: v * p.ANGLE_STEP_DEG for k, v in zip(SensorName, values, strict=True)}

    # --- the documented commands -----------------------------------------------------------------

    def absolute_position(self) -> int:
        """DGR: multi-turn x 8192 + single-turn count (``protocol.split_absolute_position``).
        ``ServoOnRefused`` with the servo on, ``CommandRejected`` with an incremental encoder."""
        return self._transact(Command.DGR, parse=one_int)

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
        self._require(*TRACE_COMMANDS)
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
        """Block ``block`` (64 samples) of a finished capture of ``count`` samples, one row of
        wire values per sample in the order ``configure_trace`` returned. One exchange: ``TRP``
        (packed) when the drive has it, else ``TRB`` (~1 s for 4 channels at 19200 bit/s)."""
        self._require(Command.TRB)
        channels = self._trace_channels
        if not channels:
            raise ValueError("read_trace_block: configure_trace first (the channels are not known)")
        expect = block_samples(block, count)
        if self.trace_encoding == "packed":
            return self._transact(Command.TRP, block, parse=_packed_block(expect, len(channels)))
        return self._transact(Command.TRB, block, parse=_trace_block(expect, len(channels)))

    @property
    def trace_encoding(self) -> str:
        """How trace blocks are read: "packed" (TRP, when the drive lists it in CAP: a third
        of the characters or fewer) or "text" (TRB, every drive with a trace)."""
        return "packed" if Command.TRP in self._capabilities.commands else "text"

    def read_trace(
        self,
        should_abort: Callable[[], bool] | None = None,
        progress: Callable[[int, int], None] | None = None,
    ) -> TraceCapture:
        """Read out the finished capture, block by block (``read_trace_block``: TRP or TRB).

        ``should_abort`` is asked before every block (e.g. a STOP's ``threading.Event.is_set``);
        when it says True the read-out gives up there with ``ReadAborted`` (``done`` / ``total``
        samples), so it keeps the link at most one block (~1 s) after being asked.
        ``progress(done, total)`` is called before the first block and after every block (samples
        read, samples in all).
        """
        self._require(Command.TST, Command.TRB)
        with self._lock:
            return read_out(self._trace_channels, self.trace_status, self.read_trace_block, should_abort,
                            progress)


# --- reply parsers (ValueError = malformed: the attempt is retried) ---------------------------------


def _cap_names(reply: Reply) -> list[str]:
    if len(reply.lines) != 1:
        raise ReplyShapeError("CAP: expected one line")
    names = reply.lines[0].split()
    if not all(len(n) == 3 and n.isalpha() and n.isupper() for n in names):
        raise ReplyShapeError("CAP: expected three-letter command names")
    return names


def _identity(reply: Reply) -> Identity:
    if len(reply.lines) != 3:
        raise ReplyShapeError("IDN: expected three lines")
    return Identity(*reply.lines)


def _values(count: int) -> Callable[[Reply], list[int]]:
    def parse(reply: Reply) -> list[int]:
        if len(reply.lines) != 1:
            raise ReplyShapeError("expected one line of values")
        values = p.parse_values(reply.lines[0])
        if len(values) != count:
            raise ReplyShapeError(f"expected {count} values, got {len(values)}")
        return values

    return parse


def _alarm_history(reply: Reply) -> list[AlarmRecord]:
    records = []
    for line in reply.lines:
        values = p.parse_values(line)
        if len(values) != 2:
            raise ReplyShapeError(f"AHS: expected code,seconds, got {line!r}")
        records.append(AlarmRecord(*values))
    return records


def _trace_status(reply: Reply) -> TraceStatus:
    state, count = _values(2)(reply)
    return TraceStatus(p.TraceState(state), count)


def _trace_block(samples: int, channels: int) -> Callable[[Reply], list[tuple[int, ...]]]:
    def parse(reply: Reply) -> list[tuple[int, ...]]:
        if len(reply.lines) != samples:
            raise ReplyShapeError(f"TRB: expected {samples} lines, got {len(reply.lines)}")
        rows = [tuple(p.parse_values(line)) for line in reply.lines]
        if any(len(row) != channels for row in rows):
            raise ReplyShapeError(f"TRB: expected {channels} values per line")
        return rows

    return parse


def _packed_block(samples: int, channels: int) -> Callable[[Reply], list[tuple[int, ...]]]:
    def parse(reply: Reply) -> list[tuple[int, ...]]:
        if not reply.lines:
            raise ReplyShapeError("TRP: expected the lines of a packed block, got none")
        try:
            return p.decode_packed_block(reply.lines, samples, channels)
        except ValueError as exc:
            raise ReplyShapeError(f"TRP: {exc}") from None

    return parse


def _steps(value: float, step: float, what: str, unit: str) -> int:
    steps = round(value / step)
    if not p.VALUE_MINIMUM <= steps <= p.VALUE_MAXIMUM:
        limit = p.VALUE_MAXIMUM * step
        raise ValueError(f"{what} {value} {unit} is outside -{limit:g} ... {limit:g} {unit}")
    return steps
