"""A stand-in drive in memory, for GUI tests that must not depend on the simulated drive's timing.

It implements ``fha_studio.hardware.api.DriveApi`` with the real result types and the real errors
(mypy checks that it does: tests/test_drive_api.py) and behaves as ``DriveClient`` does on the
simulated drive: the same arguments refused before anything is sent (same ``ValueError`` text),
the same refusals in the same words (``protocol.servo_on_text`` / ``rejected_text``, the
client's wording of a refused write), ``CommandNotSupported`` for a command it lacks. The shared
client suite (tests/hardware/test_client_buses.py) runs over it beside ``sim://``, TCP and a pty.

Its time is its own: the jog stops 100 ms after the last JOG, a trace is captured at once from
what the monitors show over the capture's time. A drive that answers only the manual's DGR and
OWW is not this fake: it is ``tests.support.documented.DocumentedDrive`` behind a real client.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable

from fha_studio.catalog.actuator import get_actuator
from fha_studio.catalog.model_code import parse_model_code
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
    SensorName,
    ServoOnRefused,
    TraceCapture,
    TraceStatus,
    WriteResult,
)
from fha_studio.hardware.client import SELECT_COMMAND, _steps
from fha_studio.hardware.parameters import (
    Mode,
    MonitorItem,
    ParameterItem,
    ParameterModel,
    ParameterValueError,
    load_alarm_table,
    load_parameter_model,
)
from fha_studio.hardware.protocol import Command, IoBit, rejected_text, servo_on_text
from fha_studio.hardware.sim.constants import load_sim_constants
from fha_studio.hardware.trace_readout import block_samples, read_out

#: Every row of the protocol's table: what the simulated drive's full profile answers (the fake
#: in the shared client suite).
SIMULATED_COMMANDS = frozenset(p.COMMAND_FACTS)
#: The GUI tests' fake: the manual's commands and the extensions without a trace capture, and of
#: the simulated drive's own commands only the power cycle (the pages poll; no sim panel, no
#: training controls).
FAKE_COMMANDS = frozenset(
    c for c, facts in p.COMMAND_FACTS.items() if facts.trace is None and not facts.sim_only
) | {Command.PWC}
#: Output pulses a turn of the fake's output (its feedback position's unit), and what a jog
#: adds a second for each r/min.
PULSES_PER_TURN = 1_000_000
JOG_PULSES_PER_RPM_S = 1000
_SENSOR_COMMANDS = {SensorName.ORIGIN: Command.SNO, SensorName.LS1: Command.SNA, SensorName.LS2: Command.SNB}


class FakeDriveClient:
    """An HA-655 adjusted for ``actuator`` (FHA-25C-50-US250: an HA-655-2-200), in memory.

    ``values`` maps ``(mode name, number)`` to the wire value; ``calls`` records jog and stop;
    ``raise_alarm(code)`` plays the drive's supervision. ``commands`` narrows what it supports
    (``without`` takes some away). DGR answers a position unless ``absolute_encoder`` is False.
    """

    def __init__(
        self,
        model: ParameterModel | None = None,
        commands: Iterable[Command] = FAKE_COMMANDS,
        *,
        actuator: str = "FHA-25C-50-US250",
        absolute_encoder: bool = True,
    ):
        self.model = model or load_parameter_model()
        self.alarm_table = load_alarm_table(self.model.driver)
        code = parse_model_code(actuator)
        self.actuator = actuator
        drivers = get_actuator(actuator).compatible_drivers
        self.driver_model = next(d for d in drivers if d.startswith(self.model.driver))
        self.absolute_encoder = absolute_encoder
        self.has_sensors = "L" in code.options
        self.values: dict[tuple[str, int], int] = {
            (i.mode.value, i.number): i.default for i in self.model if i.default is not None
        }
        self.effective = dict(self.values)
        commands = frozenset(commands)
        if not commands - p.DOCUMENTED_COMMANDS:
            raise ValueError("a drive of only the manual's commands is tests.support.documented's")
        self._capabilities = Capabilities(commands, absolute_encoder, True)
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
        constants = load_sim_constants()
        self.sensors = {
            SensorName.ORIGIN.value: constants.origin_angle_deg,
            SensorName.LS1.value: constants.limit_switch_1_angle_deg,
            SensorName.LS2.value: constants.limit_switch_2_angle_deg,
        }
        self._trace_channels: tuple[int, ...] = ()
        self._trace_divider = 1
        self._trace_rows: list[tuple[int, ...]] = []
        self._trace_state = p.TraceState.IDLE

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
        """As the client's ``_require`` and then its transaction: the link, the commands."""
        if self.closed:
            raise LinkLost("fake:// is closed", port=self.port)
        missing = [c.value for c in commands if c not in self._capabilities.commands]
        if missing:
            raise CommandNotSupported(
                f"this drive does not have {', '.join(missing)}. {self._capabilities.describe()}"
            )
        now = time.monotonic()
        self.position_pulse = self._position_at(now)
        if now >= self.jog_until:
            self.jog_speed_rpm = 0.0
        self.t = now

    def _position_at(self, when: float) -> float:
        """Where the output is at ``when`` (no earlier than the last look), jogging until the
        jog's 100 ms run out."""
        moving_until = min(when, self.jog_until)
        if not self.jog_speed_rpm or moving_until <= self.t:
            return self.position_pulse
        return self.position_pulse + self.jog_speed_rpm * (moving_until - self.t) * JOG_PULSES_PER_RPM_S

    # --- what the drive is -------------------------------------------------------------------
    @property
    def capabilities(self) -> Capabilities:
        return self._capabilities

    @capabilities.setter
    def capabilities(self, capabilities: Capabilities) -> None:
        self._capabilities = capabilities

    def without(self, *commands: Command) -> FakeDriveClient:
        """The same fake lacking ``commands`` (e.g. the parameter commands); returns self."""
        self._capabilities = Capabilities(
            self._capabilities.commands - set(commands), self.absolute_encoder, True
        )
        return self

    def detect_capabilities(self) -> Capabilities:
        self._check()
        return self._capabilities

    def identify(self) -> Identity | None:
        if Command.IDN not in self._capabilities.commands:
            return None
        self._check(Command.IDN)
        return Identity(self.driver_model, self.actuator, "fake 1.0")

    # --- parameters ----------------------------------------------------------------------------
    def _item(self, mode: Mode | str, number: int) -> ParameterItem:
        try:
            return self.model.item(mode, number)
        except (KeyError, ValueError) as exc:
            raise ParameterValueError(str(exc).strip("'\"")) from None

    def read_parameter(self, mode: Mode | str, number: int) -> int:
        mode = Mode(mode)
        if mode is Mode.MONITOR:
            return self.read_monitor(number)
        self._check(SELECT_COMMAND[mode], Command.PRD)
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
        item = self._item(mode, number)
        if not item.writable:
            raise ParameterValueError(f"{item.label} is read-only")
        item.check(value)
        self._check(SELECT_COMMAND[item.mode], Command.PRD, Command.PWR)
        key = (item.mode.value, number)
        previous = self.values[key]
        if item.mode is Mode.SYSTEM and self.servo_on:
            raise ServoOnRefused(
                f"{item.label}: not written ({servo_on_text(Command.PWR)}); "
                f"the drive holds {item.format(previous)}, the old value"
            )
        self.values[key] = value
        if not item.restart_required:
            self.effective[key] = value
        message = f"{item.label} = {item.format(value)}"
        if item.restart_required and previous != value:
            message += " (takes effect after a power cycle)"
        return WriteResult(item, value, previous, value, Held.NEW, message)

    # --- monitors ------------------------------------------------------------------------------
    def _monitor_wire(self, item: int, when: float | None = None) -> int:
        position = self.position_pulse if when is None else self._position_at(when)
        speed_rpm = self.jog_speed_rpm if when is None or when < self.jog_until else 0.0
        if item in (MonitorItem.FEEDBACK_POSITION, MonitorItem.COMMAND_POSITION, MonitorItem.LOAD_POSITION):
            return int(position)
        if item == MonitorItem.OUTPUT_SPEED:
            return round(speed_rpm / self.model.item(Mode.MONITOR, item).scale)
        if item in (MonitorItem.MOTOR_CURRENT, MonitorItem.MOTOR_CURRENT_MEAN):
            return round((0.5 if speed_rpm else 0.0) / self.model.item(Mode.MONITOR, item).scale)
        if item == MonitorItem.IO_STATE:
            return self._io_bits(moving=bool(speed_rpm))
        if (Mode.MONITOR, item) in {(i.mode, i.number) for i in self.model.in_mode(Mode.MONITOR)}:
            return 0  # an item the fake does not model: the axis at rest, no load
        raise CommandRejected(rejected_text(Command.MON, item))

    def read_monitor(self, item: int) -> int:
        self._check(Command.MON)
        return self._monitor_wire(item)

    def read_monitors(self, items: Iterable[int]) -> dict[int, int]:
        items = sorted(set(items))
        if not items:
            return {}
        self._check(Command.MON)
        return {i: self._monitor_wire(i) for i in items}

    # --- motion --------------------------------------------------------------------------------
    def servo(self, on: bool) -> None:
        self._check(Command.SVO)
        if on and self.alarm_code:
            raise CommandRejected(rejected_text(Command.SVO))
        self.servo_on = bool(on)
        if not on:
            self.jog_speed_rpm = 0.0

    def jog(self, speed_rpm: float) -> None:
        self._check(Command.JOG)
        _steps(speed_rpm, p.SPEED_STEP_RPM, "jog speed", "r/min")
        if not self.servo_on:
            raise CommandRejected(rejected_text(Command.JOG))
        self.calls.append(("jog", speed_rpm))
        self.jog_speed_rpm = speed_rpm
        self.jog_until = time.monotonic() + p.JOG_HOLD_S

    def set_move_speed(self, speed_rpm: float) -> None:
        if speed_rpm <= 0:
            raise ValueError(f"move speed must be positive, got {speed_rpm} r/min")
        self._check(Command.SPD)
        _steps(speed_rpm, p.SPEED_STEP_RPM, "move speed", "r/min")
        self.move_speed_rpm = speed_rpm

    def move_by(self, angle_deg: float) -> None:
        self._check(Command.MOV)
        _steps(angle_deg, p.ANGLE_STEP_DEG, "move angle", "deg")
        if not self.servo_on:
            raise CommandRejected(rejected_text(Command.MOV))
        self.position_pulse += angle_deg / 360 * PULSES_PER_TURN

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
        self.jog_speed_rpm = 0.0
        self.history.insert(0, AlarmRecord(code, 123))

    def clear_alarm(self) -> None:
        self._check(Command.ACL)
        alarm = self.alarm_table.get(self.alarm_code)
        if alarm is not None and not alarm.clearable:
            raise CommandRejected(rejected_text(Command.ACL))  # it needs a power cycle
        self.alarm_code = 0

    def _io_bits(self, moving: bool | None = None) -> int:
        bits = self.inputs | 1 << IoBit.READY
        bits |= int(self.servo_on) << IoBit.SERVO_ON | int(bool(self.alarm_code)) << IoBit.ALARM
        if self.jog_speed_rpm if moving is None else moving:
            bits |= 1 << IoBit.MOVING
        return bits

    def io_state(self) -> IoState:
        self._check(Command.IOS)
        return IoState(self._io_bits())

    def set_inputs(self, **inputs: bool) -> IoState:
        unknown = sorted(set(inputs) - set(INPUT_NAMES))
        if unknown:
            raise ValueError(f"unknown inputs {unknown}; known: {', '.join(sorted(INPUT_NAMES))}")
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
        if self.alarm_table.get(code) is None:
            raise CommandRejected(rejected_text(Command.FLT, code))
        self.raise_alarm(code)

    def set_sensor_angle(self, which: str, angle_deg: float) -> None:
        try:
            command = _SENSOR_COMMANDS[SensorName(which)]
        except ValueError:
            raise ValueError(f"sensor {which!r}: origin, ls1 or ls2") from None
        self._check(command)
        _steps(angle_deg, p.ANGLE_STEP_DEG, "sensor angle", "deg")
        if not self.has_sensors:
            raise CommandRejected(rejected_text(command))  # no option L: nothing to move
        self.sensors[which] = round(angle_deg / p.ANGLE_STEP_DEG) * p.ANGLE_STEP_DEG

    def sensor_angles(self) -> dict[str, float]:
        self._check(Command.SNQ)
        return dict(self.sensors)

    # --- the documented commands ------------------------------------------------------------
    def absolute_position(self) -> int:
        self._check(Command.DGR)
        if self.servo_on:
            raise ServoOnRefused(servo_on_text(Command.DGR))
        if not self.absolute_encoder:
            raise CommandRejected(rejected_text(Command.DGR))
        return int(self.position_pulse)

    def clear_multiturn(self) -> None:
        self._check(Command.OWW)
        if self.servo_on or not self.absolute_encoder:
            raise CommandRejected(rejected_text(Command.OWW))

    # --- trace capture: taken at once, from what the monitors show over the capture's time ----
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
        ordered = tuple(p.mask_items(p.monitor_mask(channels)))
        if not 1 <= len(ordered) <= p.TRACE_MAX_CHANNELS:
            raise ValueError(f"a trace has 1 ... {p.TRACE_MAX_CHANNELS} channels, got {len(ordered)}")
        self._check(*p.TRACE_COMMANDS)
        if not 1 <= divider <= 99999:
            raise CommandRejected(rejected_text(Command.TDV))
        if not 0 <= pre_trigger < p.TRACE_MAX_SAMPLES:
            raise CommandRejected(rejected_text(Command.TPR))
        self._trace_channels, self._trace_divider = ordered, divider
        return ordered

    def arm_trace(self, samples: int) -> None:
        if not 1 <= samples <= p.TRACE_MAX_SAMPLES:
            raise ValueError(f"trace samples must be 1 ... {p.TRACE_MAX_SAMPLES}, got {samples}")
        self._check(Command.TAR)
        if not self._trace_channels:
            raise CommandRejected(rejected_text(Command.TAR))
        start, step_s = time.monotonic(), self._trace_divider / 1000
        self._trace_rows = [
            tuple(self._monitor_wire(c, start + k * step_s) for c in self._trace_channels)
            for k in range(samples)
        ]
        self._trace_state = p.TraceState.DONE

    def trace_status(self) -> TraceStatus:
        self._check(Command.TST)
        done = self._trace_state is p.TraceState.DONE
        return TraceStatus(self._trace_state, len(self._trace_rows) if done else 0)

    def read_trace_block(self, block: int, count: int) -> list[tuple[int, ...]]:
        self._check(Command.TRB)
        if not self._trace_channels:
            raise ValueError("read_trace_block: configure_trace first (the channels are not known)")
        expect = block_samples(block, count)
        first = block * p.TRACE_BLOCK_SAMPLES
        rows = self._trace_rows[first:first + expect] if self._trace_state is p.TraceState.DONE else []
        if not rows:
            raise CommandRejected(rejected_text(Command.TRB))
        return rows

    def read_trace(
        self,
        should_abort: Callable[[], bool] | None = None,
        progress: Callable[[int, int], None] | None = None,
    ) -> TraceCapture:
        self._check(Command.TST, Command.TRB)
        return read_out(self._trace_channels, self.trace_status, self.read_trace_block, should_abort,
                        progress)
