"""The one drive interface: ``DriveApi``, its result types and its errors.

Everything above the hardware layer (the GUI's link worker, the scope, procedures, the CLI) talks
to a drive through ``DriveApi``. ``DriveClient`` implements it over CN3 (any transport: a real
port, a pty, TCP, the embedded ``sim://`` drive); test fakes implement it in memory. They return
the types below and raise the errors of ``fha_studio.hardware.errors`` (re-exported here), so a
caller never has to guess a result's shape or an exception's meaning.

Every method blocks until the drive answered (or the link layer gave up), so callers run them in
a worker thread, never in a GUI thread.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from enum import Enum, StrEnum
from typing import Protocol, runtime_checkable

from fha_studio.hardware import protocol as p
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
from fha_studio.hardware.parameters import Mode, ParameterItem, ParameterModel
from fha_studio.hardware.protocol import TRACE_COMMANDS, Command

__all__ = [
    "INPUT_NAMES",
    "TRACE_COMMANDS",
    "AlarmRecord",
    "Capabilities",
    "CapabilityLevel",
    "CommandNotSupported",
    "CommandRejected",
    "DriveApi",
    "DriveLink",
    "DriveRefused",
    "ExtensionCommands",
    "Held",
    "Identity",
    "IoState",
    "LinkError",
    "LinkFailure",
    "LinkGarbled",
    "LinkLost",
    "LinkSilent",
    "LinkTimeout",
    "ManualCommands",
    "ReadAborted",
    "SensorName",
    "ServoOnRefused",
    "SimPanel",
    "SimulatedDriveControls",
    "TraceCapture",
    "TraceCommands",
    "TraceStatus",
    "WriteResult",
]

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
#: The same in a few words, for the window's status bar (the sentences above in its tooltip).
_LEVEL_SUMMARIES = {
    CapabilityLevel.TRACE: "traces at the servo rate",
    CapabilityLevel.POLLING: "signals polled, no traces",
    CapabilityLevel.ABSOLUTE_POSITION: "the manual's commands only (DGR, OWW)",
    CapabilityLevel.NOTHING: "nothing to read over CN3: use the front panel",
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
        if self.commands >= TRACE_COMMANDS:
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

    @property
    def can_move(self) -> bool:
        """True when servo on/off and jog go over the link."""
        return {Command.SVO, Command.JOG} <= self.commands

    @property
    def can_monitor(self) -> bool:
        """True when monitor items can be read (MON or MMR)."""
        return Command.MON in self.commands or Command.MMR in self.commands

    def supports(self, command: Command) -> bool:
        return command in self.commands

    def summary(self) -> str:
        """What the drive gives, in a few words (``describe`` says it whole)."""
        return _LEVEL_SUMMARIES[self.level]

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

    @property
    def servo_on(self) -> bool:
        return self.bit(p.IoBit.SERVO_ON)

    @property
    def ready(self) -> bool:
        return self.bit(p.IoBit.READY)

    @property
    def alarm(self) -> bool:
        return self.bit(p.IoBit.ALARM)

    @property
    def in_position(self) -> bool:
        return self.bit(p.IoBit.IN_POSITION)

    @property
    def fwd_inhibit(self) -> bool:
        return self.bit(p.IoBit.FWD_INHIBIT)

    @property
    def rev_inhibit(self) -> bool:
        return self.bit(p.IoBit.REV_INHIBIT)

    @property
    def origin_sensor(self) -> bool:
        return self.bit(p.IoBit.ORIGIN_SENSOR)

    @property
    def limit_switch_1(self) -> bool:
        return self.bit(p.IoBit.LIMIT_SWITCH_1)

    @property
    def limit_switch_2(self) -> bool:
        return self.bit(p.IoBit.LIMIT_SWITCH_2)

    @property
    def brake_released(self) -> bool:
        return self.bit(p.IoBit.BRAKE_RELEASED)

    @property
    def error_counter_clear(self) -> bool:
        return self.bit(p.IoBit.ERROR_COUNTER_CLEAR)

    @property
    def moving(self) -> bool:
        return self.bit(p.IoBit.MOVING)

    @property
    def alm_bits(self) -> int:
        """The 4-bit alarm output, bit 0 = ALM-A ... bit 3 = ALM-D (compare Alarm.alm_bits)."""
        return p.alm_bits_from_io(self.raw)

    def as_dict(self) -> dict[str, bool]:
        """Every named bit: {"servo_on": True, ...}."""
        return {bit.name.lower(): self.bit(bit) for bit in p.IoBit}


#: Names accepted by ``DriveApi.set_inputs``.
INPUT_NAMES = {bit.name.lower(): bit for bit in p.INPUT_BITS}


class SensorName(StrEnum):
    """The movable sensors of the simulated drive (``set_sensor_angle``)."""

    ORIGIN = "origin"  # the origin slit
    LS1 = "ls1"  # the dog of limit switch 1
    LS2 = "ls2"  # the dog of limit switch 2


@dataclass(frozen=True)
class AlarmRecord:
    """One AHS line: alarm code and when it happened (seconds after power-on)."""

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


class Held(StrEnum):
    """What the drive holds after a verified write (read back)."""

    NEW = "new"
    OLD = "old"
    NEITHER = "neither"


@dataclass(frozen=True)
class WriteResult:
    """Outcome of a verified write: ``previous`` value, ``value`` read back, what it ``holds``."""

    item: ParameterItem
    requested: int
    previous: int | None
    value: int
    holds: Held
    message: str = ""

    @property
    def verified(self) -> bool:
        return self.holds is Held.NEW

    @property
    def needs_restart(self) -> bool:
        """True when the new value takes effect only after a power cycle."""
        return self.verified and self.item.restart_required and self.previous != self.requested


@runtime_checkable
class DriveLink(Protocol):
    """The link to one drive and what the drive is (asked once, kept)."""

    #: The driver's parameter model (items, units, ranges, monitor items).
    model: ParameterModel

    @property
    def port(self) -> str: ...
    @property
    def is_open(self) -> bool: ...
    @property
    def link_lost(self) -> bool: ...
    def close(self) -> None: ...
    @property
    def capabilities(self) -> Capabilities: ...
    def detect_capabilities(self) -> Capabilities: ...


@runtime_checkable
class ManualCommands(Protocol):
    """What the public HA-655 manual documents (``protocol.DOCUMENTED_COMMANDS``): every drive."""

    def absolute_position(self) -> int: ...
    def clear_multiturn(self) -> None: ...


@runtime_checkable
class ExtensionCommands(Protocol):
    """The extensions a drive lists in CAP: identity, parameters, monitors, motion, alarms, I/O."""

    def identify(self) -> Identity | None: ...

    # --- parameters ----------------------------------------------------------------------------
    def read_parameter(self, mode: Mode | str, number: int) -> int: ...
    def read_all_parameters(self, mode: Mode | str) -> dict[int, int | None]: ...
    def write_parameter(self, mode: Mode | str, number: int, value: int) -> WriteResult: ...

    # --- monitors ------------------------------------------------------------------------------
    def read_monitor(self, item: int) -> int: ...
    def read_monitors(self, items: Iterable[int]) -> dict[int, int]: ...

    # --- motion --------------------------------------------------------------------------------
    def servo(self, on: bool) -> None: ...
    def jog(self, speed_rpm: float) -> None: ...
    def set_move_speed(self, speed_rpm: float) -> None: ...
    def move_by(self, angle_deg: float) -> None: ...
    def stop(self) -> None: ...

    # --- alarms and I/O ------------------------------------------------------------------------
    def alarm(self) -> int: ...
    def alarm_history(self) -> list[AlarmRecord]: ...
    def clear_alarm(self) -> None: ...
    def io_state(self) -> IoState: ...


@runtime_checkable
class TraceCommands(Protocol):
    """A drive-side trace capture (``protocol.TRACE_COMMANDS``, read in packed blocks when listed)."""

    def configure_trace(
        self,
        channels: Iterable[int],
        *,
        divider: int = 1,
        trigger: p.TriggerKind = p.TriggerKind.IMMEDIATE,
        trigger_channel: int = 0,
        trigger_level: int = 0,
        pre_trigger: int = 0,
    ) -> tuple[int, ...]: ...
    def arm_trace(self, samples: int) -> None: ...
    def trace_status(self) -> TraceStatus: ...
    def read_trace_block(self, block: int, count: int) -> list[tuple[int, ...]]: ...
    def read_trace(
        self,
        should_abort: Callable[[], bool] | None = None,
        progress: Callable[[int, int], None] | None = None,
    ) -> TraceCapture: ...


@runtime_checkable
class SimulatedDriveControls(Protocol):
    """The simulated drive's own commands (``protocol.SIM_ONLY_COMMANDS``): what a test or a
    training plays on CN2, the supervision and the sensors."""

    def set_inputs(self, **inputs: bool) -> IoState: ...
    def power_cycle(self) -> None: ...
    def inject_alarm(self, code: int) -> None: ...
    def set_sensor_angle(self, which: str, angle_deg: float) -> None: ...
    def sensor_angles(self) -> dict[str, float]: ...


@runtime_checkable
class DriveApi(DriveLink, ManualCommands, ExtensionCommands, TraceCommands, SimulatedDriveControls, Protocol):
    """One drive, whatever carries it: every part above. Methods raise the ``LinkError`` family
    only (plus ``ValueError`` / ``ParameterValueError`` for an argument refused before anything
    is sent).

    ``CommandNotSupported`` means the drive lacks the extension (nothing was sent);
    ``ServoOnRefused`` / ``CommandRejected`` that it answered ``s`` / ``x``; ``LinkTimeout`` /
    ``LinkLost`` that the link failed.
    """


@runtime_checkable
class SimPanel(Protocol):
    """An embedded simulated drive's panel: what a real drive gets from outside CN3, the
    controller's CN2 and the technician's hands (``DriveClient.sim_panel``). Raises the sim's
    ``SimRefused`` when the drive does not allow it now."""

    @property
    def has_sensors(self) -> bool: ...
    def set_servo(self, on: bool) -> None: ...
    def controller_command(self, angle_deg: float) -> None: ...
    def turn_by_hand(self, angle_deg: float) -> None: ...
    def release_brake(self, released: bool) -> None: ...
    def io_state(self) -> IoState: ...
