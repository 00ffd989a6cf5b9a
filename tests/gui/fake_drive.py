"""A stand-in drive in memory, for GUI tests that must not depend on the simulated drive's timing.

It implements ``fha_studio.hardware.api.DriveApi`` with the real result types and the real errors
(mypy checks that it does: tests/typecheck_drive_api.py), and follows the protocol's rules:
servo-on refusals, alarms that need a power cycle, a jog that stops 100 ms after the last JOG.
Commands it does not model raise ``CommandNotSupported``, as the client does for a drive without
the extension.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable

from fha_studio.hardware import protocol as p
from fha_studio.hardware.api import (
    INPUT_NAMES,
    AlarmRecord,
    Capabilities,
    CommandNotSupported,
    CommandRejected,
    Held,
    Identity,
    IoState,
    LinkLost,
    ServoOnRefused,
    TraceCapture,
    TraceStatus,
    WriteResult,
)
from fha_studio.hardware.client import SELECT_COMMAND
from fha_studio.hardware.parameters import (
    Mode,
    MonitorItem,
    ParameterModel,
    ParameterValueError,
    load_parameter_model,
)
from fha_studio.hardware.protocol import Command, IoBit, rejected_text, servo_on_text

#: What the fake answers: the manual's commands, parameters, monitors, motion, alarms, I/O and the
#: simulated power cycle; no trace capture and no other sim-only command (inputs, alarms, sensors).
FAKE_COMMANDS = frozenset(
    c for c, facts in p.COMMAND_FACTS.items() if facts.trace is None and not facts.sim_only
) | {Command.PWC}


class FakeDriveClient:
    """An HA-655-2-200 adjusted for an FHA-25C-50-US250, in memory (a ``DriveApi``).

    ``values`` maps ``(mode name, number)`` to the wire value; ``calls`` records jog and stop;
    ``raise_alarm(code)`` plays the drive's supervision. ``commands`` narrows what it supports.
    """

    def __init__(self, model: ParameterModel | None = None, commands: Iterable[Command] = FAKE_COMMANDS):
        self.model = model or load_parameter_model()
        self.values: dict[tuple[str, int], int] = {
            (i.mode.value, i.number): i.default for i in self.model if i.default is not None
        }
        self.effective = dict(self.values)
        self._capabilities = Capabilities(frozenset(commands), True, True)
        self.closed = False
        self.servo_on = False
        self.alarm_code = 0
        self.history: list[AlarmRecord] = []
        self.inputs = 0
        self.position_pulse = 0.0
        self.jog_speed_rpm = 0.0
        self.jog_until = 0.0
        self.move_speed_rpm = 10.0
        self.t = time.monotonic()
        self.calls: list[tuple[object, ...]] = []

    # --- the link ----------------------------------------------------------------------------
    @property
    def port(self) -> str:
        return "fake://"

    @property
    def is_open(self) -> bool:
        return not self.closed

    @property
    def link_lost(self) -> bool:
        return self.closed

    def close(self) -> None:
        self.closed = True

    def _check(self, *commands: Command) -> None:
        if self.closed:
            raise LinkLost("fake:// is closed", port=self.port)
        missing = [c.value for c in commands if c not in self._capabilities.commands]
        if missing:
            raise CommandNotSupported(f"this drive does not have {', '.join(missing)}")
        now = time.monotonic()
        if self.jog_speed_rpm and now < self.jog_until:
            self.position_pulse += self.jog_speed_rpm * (now - self.t) * 1000
        elif now >= self.jog_until:
            self.jog_speed_rpm = 0.0
        self.t = now

    # --- what the drive is -------------------------------------------------------------------
    @property
    def capabilities(self) -> Capabilities:
        return self._capabilities

    @capabilities.setter
    def capabilities(self, capabilities: Capabilities) -> None:
        self._capabilities = capabilities

    def without(self, *commands: Command) -> FakeDriveClient:
        """The same fake lacking ``commands`` (e.g. the parameter commands); returns self."""
        self._capabilities = Capabilities(self._capabilities.commands - set(commands), True, True)
        return self

    def detect_capabilities(self) -> Capabilities:
        self._check()
        return self._capabilities

    def identify(self) -> Identity | None:
        self._check()
        return Identity("HA-655-2-200", "FHA-25C-50-US250", "fake 1.0")

    # --- parameters ----------------------------------------------------------------------------
    def read_parameter(self, mode: Mode | str, number: int) -> int:
        mode = Mode(mode)
        if mode is Mode.MONITOR:
            return self.read_monitor(number)
        self._check(Command.PRD)
        try:
            return self.values[(mode.value, number)]
        except KeyError:
            raise CommandRejected(rejected_text(SELECT_COMMAND[mode], number)) from None

    def read_all_parameters(self, mode: Mode | str) -> dict[int, int | None]:
        values: dict[int, int | None] = {}
        for item in self.model.in_mode(mode):
            try:
                values[item.number] = self.read_parameter(item.mode, item.number)
            except CommandRejected:
                values[item.number] = None
        return values

    def write_parameter(self, mode: Mode | str, number: int, value: int) -> WriteResult:
        mode = Mode(mode)
        self._check(Command.PRD, Command.PWR)
        item = self.model.item(mode, number)
        if not item.writable:
            raise ParameterValueError(f"{item.label} is read-only")
        item.check(value)
        if mode is Mode.SYSTEM and self.servo_on:
            raise ServoOnRefused(servo_on_text(Command.PWR))
        key = (mode.value, number)
        previous = self.values[key]
        self.values[key] = value
        if not item.restart_required:
            self.effective[key] = value
        message = f"{item.label} = {item.format(value)}"
        if item.restart_required and previous != value:
            message += " (takes effect after a power cycle)"
        return WriteResult(item, value, previous, value, Held.NEW, message)

    # --- monitors ------------------------------------------------------------------------------
    def _monitor_wire(self, item: int) -> int:
        if item == MonitorItem.FEEDBACK_POSITION:
            return int(self.position_pulse)
        if item == MonitorItem.OUTPUT_SPEED:
            return round(self.jog_speed_rpm / self.model.item(Mode.MONITOR, item).scale)
        if item == MonitorItem.MOTOR_CURRENT:
            return round((0.5 if self.jog_speed_rpm else 0.0) / self.model.item(Mode.MONITOR, item).scale)
        if item == MonitorItem.IO_STATE:
            return self._io_bits()
        raise CommandRejected(rejected_text(Command.MON, item))

    def read_monitor(self, item: int) -> int:
        self._check(Command.MON)
        return self._monitor_wire(item)

    def read_monitors(self, items: Iterable[int]) -> dict[int, int]:
        self._check(Command.MON)
        return {i: self._monitor_wire(i) for i in sorted(set(items))}

    # --- motion --------------------------------------------------------------------------------
    def servo(self, on: bool) -> None:
        self._check(Command.SVO)
        if on and self.alarm_code:
            raise CommandRejected(rejected_text(Command.SVO))
        self.servo_on = bool(on)

    def jog(self, speed_rpm: float) -> None:
        self._check(Command.JOG)
        if not self.servo_on:
            raise CommandRejected(rejected_text(Command.JOG))
        self.calls.append(("jog", speed_rpm))
        self.jog_speed_rpm = speed_rpm
        self.jog_until = time.monotonic() + p.JOG_HOLD_S

    def set_move_speed(self, speed_rpm: float) -> None:
        if speed_rpm <= 0:
            raise ValueError(f"move speed must be positive, got {speed_rpm} r/min")
        self._check(Command.SPD)
        self.move_speed_rpm = speed_rpm

    def move_by(self, angle_deg: float) -> None:
        self._check(Command.MOV)
        if not self.servo_on:
            raise CommandRejected(rejected_text(Command.MOV))
        self.position_pulse += angle_deg / 360 * 1_000_000

    def stop(self) -> None:
        self._check(Command.STP)
        self.calls.append(("stop",))
        self.jog_speed_rpm = 0.0

    # --- alarms and I/O ------------------------------------------------------------------------
    def alarm(self) -> int:
        self._check(Command.ALM)
        return self.alarm_code

    def alarm_history(self) -> list[AlarmRecord]:
        self._check(Command.AHS)
        return list(self.history)

    def raise_alarm(self, code: int) -> None:
        """The drive's supervision raises alarm ``code`` (servo off, history entry)."""
        self.alarm_code = code
        self.servo_on = False
        self.history.insert(0, AlarmRecord(code, 123))

    def clear_alarm(self) -> None:
        self._check(Command.ACL)
        if self.alarm_code not in (0, 20, 60):
            raise CommandRejected(f"{rejected_text(Command.ACL)}: it needs a power cycle")
        self.alarm_code = 0

    def _io_bits(self) -> int:
        bits = self.inputs | 1 << IoBit.READY
        bits |= int(self.servo_on) << IoBit.SERVO_ON | int(bool(self.alarm_code)) << IoBit.ALARM
        if self.jog_speed_rpm:
            bits |= 1 << IoBit.MOVING
        return bits

    def io_state(self) -> IoState:
        self._check(Command.IOS)
        return IoState(self._io_bits())

    def set_inputs(self, **inputs: bool) -> IoState:
        unknown = sorted(set(inputs) - set(INPUT_NAMES))
        if unknown:
            raise ValueError(f"unknown inputs {unknown}")
        self._check(Command.INP, Command.IOS)
        for name, on in inputs.items():
            bit = 1 << INPUT_NAMES[name]
            self.inputs = (self.inputs | bit) if on else (self.inputs & ~bit)
        return IoState(self._io_bits())

    def power_cycle(self) -> None:
        self._check(Command.PWC)
        if self.servo_on:
            raise ServoOnRefused(servo_on_text(Command.PWC))
        self.effective = dict(self.values)
        self.alarm_code = 0

    def inject_alarm(self, code: int) -> None:
        self._check(Command.FLT)
        self.raise_alarm(code)

    def set_sensor_angle(self, which: str, angle_deg: float) -> None:
        self._check(Command.SNO, Command.SNA, Command.SNB)

    def sensor_angles(self) -> dict[str, float]:
        self._check(Command.SNQ)
        return {}

    # --- the documented commands ------------------------------------------------------------
    def absolute_position(self) -> int:
        self._check(Command.DGR)
        if self.servo_on:
            raise ServoOnRefused(servo_on_text(Command.DGR))
        return int(self.position_pulse)

    def clear_multiturn(self) -> None:
        self._check(Command.OWW)
        if self.servo_on:
            raise CommandRejected(rejected_text(Command.OWW))

    # --- trace capture (not modelled: a drive without the extension) --------------------------
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
        self._check(Command.TCH)
        return ()

    def arm_trace(self, samples: int) -> None:
        self._check(Command.TAR)

    def trace_status(self) -> TraceStatus:
        self._check(Command.TST)
        return TraceStatus(p.TraceState.IDLE, 0)

    def read_trace_block(self, block: int, count: int) -> list[tuple[int, ...]]:
        self._check(Command.TRB)
        return []

    def read_trace(
        self,
        should_abort: Callable[[], bool] | None = None,
        progress: Callable[[int, int], None] | None = None,
    ) -> TraceCapture:
        self._check(Command.TRB)
        return TraceCapture((), ())
