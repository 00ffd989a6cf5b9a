"""`SimDrive`: a simulated HA-655 / HA-675 driver with an FHA-C actuator that can be commissioned.

The drive keeps its tune / parameter / test items in an EEPROM file, switches the servo, jogs
(under the 100 ms communication watchdog), moves by an angle, supervises the axis (alarms 10, 20,
41, 60, encoder alarms on demand), reads its I/O (inhibits, option-L sensors, brake coil) and
captures traces. The axis itself is :mod:`fha_studio.physics`, stepped at the servo rate.

Time: in *stepped* mode nothing moves until :meth:`SimDrive.advance` is called (deterministic,
for tests); :meth:`SimDrive.start` runs a thread that advances in real time until :meth:`close`.

Signs: the drive's command sense is FWD positive (JOG, MOV, monitors 100-104, 108). The physical
sense is CW seen from the output flange positive (FHA-C manual 1-10): with rotary direction 0
(system item 8) FWD = CW, with 1 FWD = CCW. The encoder's own counts (``DGR``) and the external
load encoder (monitor 107) are physical: they do not follow the rotary-direction setting.

Everything is reachable through :meth:`SimDrive.execute` (a CN3 command name and its integer
value -> :class:`Reply`), which is what :class:`SimProtocolServer` calls after decoding bytes.
"""

from __future__ import annotations

import math
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from fha_studio import __version__ as _version
from fha_studio.hardware.parameters import (
    Mode,
    ParameterValueError,
    load_alarm_table,
    load_parameter_model,
    split_low_high,
)
from fha_studio.hardware.protocol import EXTENSION_COMMANDS, Command
from fha_studio.hardware.sim.axis import (
    DEFAULT_SERVO_RATE_HZ,
    build_axis,
    build_model,
    resolve_actuator,
    servo_settings,
)
from fha_studio.hardware.sim.constants import SimConstants, load_sim_constants
from fha_studio.hardware.sim.eeprom import EepromError, EepromFile, default_eeprom_dir
from fha_studio.hardware.sim.options import SimConfig, SimConfigError
from fha_studio.hardware.sim.trace import TraceCapture, TraceError
from fha_studio.physics import ServoAxis, ServoSettings

TWO_PI = 2.0 * math.pi
RPM = TWO_PI / 60.0  # rad/s per r/min
ABS_COUNTS_PER_MOTOR_REV = 8192  # 13-bit single-turn (FHA-C manual 1-8, HA-655 p.20)
ABS_MULTI_TURN_RANGE = (-4096, 4095)  # HA-655 manual (relianca p.5): alarm 54 outside it

# I/O bits (docs/protocol.md, I/O table)
BIT_SERVO_ON = 0
BIT_READY = 1
BIT_ALARM = 2
BIT_IN_POSITION = 3
BIT_FWD_INHIBIT = 4
BIT_REV_INHIBIT = 5
BIT_ORIGIN = 6
BIT_LIMIT_1 = 7
BIT_LIMIT_2 = 8
BIT_BRAKE_RELEASED = 9
BIT_ERROR_CLEAR = 10
BIT_ALM_A = 11
BIT_MOVING = 15
INPUT_MASK = sum(1 << b for b in (4, 5, 6, 7, 8, 9, 10))
SENSOR_MASK = sum(1 << b for b in (BIT_ORIGIN, BIT_LIMIT_1, BIT_LIMIT_2))

SUPERVISION_PERIOD_S = 0.001  # alarms, watchdog, sensors and inhibits are checked every 1 ms


class SimRefused(Exception):
    """The command is refused: ``terminal`` is ``"s"`` (servo on) or ``"x"`` (not allowed / bad)."""

    def __init__(self, terminal: str, reason: str):
        super().__init__(reason)
        self.terminal = terminal
        self.reason = reason


def _x(reason: str) -> SimRefused:
    return SimRefused("x", reason)


@dataclass(frozen=True)
class Reply:
    """What the drive answers one command: data lines and the terminal ``q``, ``s`` or ``x``.

    ``reason`` says why a command was refused (for logs and messages; not on the wire).
    """

    terminal: str = "q"
    lines: tuple[str, ...] = ()
    reason: str = ""


@dataclass
class AlarmRecord:
    """One entry of the alarm history."""

    code: int
    seconds_since_power_on: float
    time_utc: str


class SimDrive:
    """A simulated HA-655/HA-675 with an FHA-C actuator (see the module docstring).

    Build with keywords (``SimDrive("FHA-25C-50-US250", load_inertia_kgm2=1.5)``), a
    :class:`SimConfig` (``SimDrive(config=cfg)``) or ``SimDrive.from_url("sim://...")``.
    Raises SimConfigError for a bad option, EepromError for an unreadable EEPROM file.
    """

    def __init__(
        self,
        actuator: str | None = None,
        *,
        config: SimConfig | None = None,
        constants: SimConstants | None = None,
        servo_rate_hz: float = DEFAULT_SERVO_RATE_HZ,
        **options: Any,
    ):
        if config is None:
            config = SimConfig(actuator=actuator or SimConfig.actuator, **options)
        elif actuator is not None or options:
            config = config.replace(**({"actuator": actuator} if actuator else {}), **options)
        self.config = config
        self.constants = constants or load_sim_constants()
        self.servo_rate_hz = float(servo_rate_hz)
        self._lock = threading.RLock()
        self._thread: threading.Thread | None = None
        self._stop_event = threading.Event()
        self._closed = False
        self._tempdir: tempfile.TemporaryDirectory[str] | None = None

        resolved = resolve_actuator(config)
        self.resolved = resolved
        self.actuator = resolved.actuator
        self.actuator_code: str = resolved.code
        self.driver: str = resolved.driver
        self.absolute_encoder: bool = resolved.absolute_encoder
        self.brake_holding_torque_nm = resolved.brake_holding_torque_nm
        self.has_brake: bool = self.brake_holding_torque_nm is not None
        self.has_sensors: bool = resolved.has_sensors
        self.model = build_model(resolved, config)
        family = "HA-675" if self.driver.startswith("HA-675") else "HA-655"
        self.parameters = load_parameter_model(family)
        self.alarm_table = load_alarm_table(family)

        c = self.constants
        self.origin_deg = config.origin_deg if config.origin_deg is not None else c.origin_angle_deg
        self.ls1_deg = config.ls1_deg if config.ls1_deg is not None else c.limit_switch_1_angle_deg
        self.ls2_deg = config.ls2_deg if config.ls2_deg is not None else c.limit_switch_2_angle_deg
        self.oww_clear_s = config.oww_clear_s if config.oww_clear_s is not None else c.oww_clear_s

        # EEPROM: stored values; the active ones are copied at power-on
        self.eeprom = EepromFile(self._eeprom_path(config.eeprom))
        self._stored: dict[tuple[Mode, int], int] = {}
        self._active: dict[tuple[Mode, int], int] = {}
        self.alarm_history: list[AlarmRecord] = []
        # the shaft does not move while the drive is off: a restarted sim finds it where it was
        self._initial_angle_rad = 0.0
        self._absolute_zero_rad = 0.0  # physical angle where the absolute count is 0
        self.axis: ServoAxis | None = None
        self._load_eeprom()
        self.axis = build_axis(self.model, self._settings(self._stored), self._initial_angle_rad)

        self._selected: tuple[Mode, int] | None = None
        self._inputs = 0  # INP bits
        self.trace = TraceCapture()
        self._deferred: list[Reply] = []
        self.clock_s = 0.0  # simulated time since the drive was built (not reset by PWC)
        self._recorder: Any = None
        self._power_on()

    # ------------------------------------------------------------------ construction helpers
    @classmethod
    def from_url(cls, url: str, **kwargs: Any) -> SimDrive:
        from fha_studio.hardware.sim.options import config_from_url

        return cls(config=config_from_url(url), **kwargs)

    def _eeprom_path(self, option: str | None) -> Path:
        if option is None or option == "":
            self._tempdir = tempfile.TemporaryDirectory(prefix="fha-sim-")
            return Path(self._tempdir.name) / "eeprom.json"
        if option == "user":
            return default_eeprom_dir() / f"{self.driver}_{self.actuator_code}.json"
        return Path(option).expanduser()

    def _item_defaults(self) -> dict[tuple[Mode, int], int]:
        return {
            (item.mode, item.number): item.default
            for item in self.parameters
            if item.mode is not Mode.MONITOR and item.default is not None
        }

    def _load_eeprom(self) -> None:
        stored = self._item_defaults()
        doc = self.eeprom.load()
        path = self.eeprom.path
        if doc is None:
            self._stored = stored
            self._save_eeprom()
            return
        if doc.get("actuator") not in (None, self.actuator_code):
            raise EepromError(
                f"simulated drive EEPROM {path} was adjusted for {doc.get('actuator')}, not "
                f"{self.actuator_code}; use another file (or delete it)"
            )
        params = doc.get("parameters", {})
        if not isinstance(params, dict):
            raise EepromError(f"simulated drive EEPROM {path}: 'parameters' is not a table")
        for mode_name, values in params.items():
            try:
                mode = Mode(mode_name)
            except ValueError:
                raise EepromError(f"simulated drive EEPROM {path}: unknown mode {mode_name!r}") from None
            if not isinstance(values, dict):
                raise EepromError(f"simulated drive EEPROM {path}: parameters.{mode_name} is not a table")
            for key, value in values.items():
                try:
                    item = self.parameters.by_key(key)
                except KeyError:
                    continue  # an item this version no longer has
                if item.mode is not mode:
                    raise EepromError(f"simulated drive EEPROM {path}: {key} is a {item.mode.value} item")
                try:
                    item.check(value)
                except ParameterValueError as exc:
                    raise EepromError(f"simulated drive EEPROM {path}: {exc}") from None
                stored[(mode, item.number)] = value
        try:
            history = [AlarmRecord(int(a["code"]), float(a["seconds"]), str(a["time_utc"]))
                       for a in doc.get("alarm_history", [])]
            encoder = doc.get("encoder", {})
            mechanical = float(encoder.get("mechanical_angle_rad", 0.0))
            absolute_zero = float(encoder.get("absolute_zero_rad", 0.0))
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise EepromError(
                f"simulated drive EEPROM {path}: bad alarm history or encoder data ({exc})"
            ) from None
        if not (math.isfinite(mechanical) and math.isfinite(absolute_zero)):
            raise EepromError(f"simulated drive EEPROM {path}: encoder data is not finite")
        self._stored = stored
        self.alarm_history = history
        self._initial_angle_rad = mechanical
        self._absolute_zero_rad = absolute_zero

    def _save_eeprom(self) -> None:
        angle = self._initial_angle_rad if self.axis is None else self.axis.output_pos_rad
        by_mode: dict[str, dict[str, int]] = {}
        for (mode, number), value in sorted(self._stored.items()):
            by_mode.setdefault(mode.value, {})[self.parameters.item(mode, number).key] = value
        self.eeprom.save({
            "driver": self.driver,
            "actuator": self.actuator_code,
            "parameters": by_mode,
            "alarm_history": [
                {"code": a.code, "seconds": round(a.seconds_since_power_on, 3), "time_utc": a.time_utc}
                for a in self.alarm_history
            ],
            "encoder": {
                "mechanical_angle_rad": angle,
                "absolute_zero_rad": self._absolute_zero_rad,
            },
        })

    # ------------------------------------------------------------------ power
    def _settings(self, values: dict[tuple[Mode, int], int]) -> ServoSettings:
        by_key = {self.parameters.item(mode, number).key: v for (mode, number), v in values.items()}
        return servo_settings(self.model, by_key, self.servo_rate_hz, self.config.quantised)

    def _power_on(self) -> None:
        """Control power on: active items from the EEPROM, counters from zero, no alarm."""
        axis = self._axis
        self._active = dict(self._stored)
        self.time_s = 0.0
        self.servo_on = False
        self.alarm = 0
        self._motion = "idle"  # idle | jog | move | stop
        self._motion_sign = 0.0  # direction of the commanded motion, command frame
        self._jog_speed_rad_s = 0.0
        self._jog_deadline = 0.0
        self._oww_done_at: float | None = None
        self._overload_a2s = 0.0  # I^2 t above the continuous current, A^2 s
        self._regen_j = 0.0  # regenerated energy not yet dissipated by the resistor, J
        self._move_speed_rad_s = self._param("jog_speed") * 0.01 * RPM
        self._step_debt = 0.0
        self._steps_to_supervision = 0
        self.trace = TraceCapture()
        axis.servo_off()
        axis.set_settings(self._settings(self._active))
        self._direction = axis.settings.direction_sign
        # the feedback counter (monitor 100) starts at 0 at power-on with an incremental encoder
        # and reads the absolute position with an absolute one
        absolute = self.absolute_encoder
        self._feedback_zero_rad = self._absolute_zero_rad if absolute else axis.output_pos_rad
        self._command_zero_rad = axis.command_pos_rad - self._feedback_zero_rad
        self._last_i2_a2s = axis.current_squared_integral_a2s
        self._last_regen_j = axis.regenerated_energy_j
        axis.reset_peaks()
        self._update_brake()

    @property
    def _axis(self) -> ServoAxis:
        assert self.axis is not None
        return self.axis

    def power_cycle(self) -> None:
        """Simulated control-power cycle (PWC): restart-required items take effect, alarms clear,
        an incremental position is lost. Refused (``s``) while the servo is on."""
        with self._lock:
            if self.servo_on:
                raise SimRefused("s", "servo on: switch it off before a power cycle")
            self._save_eeprom()
            self._power_on()

    # ------------------------------------------------------------------ parameters
    def _param(self, key: str) -> int:
        item = self.parameters.by_key(key)
        return self._active[(item.mode, item.number)]

    def _accel_rad_s2(self) -> float:
        return self._param("jog_acceleration") * RPM

    def read_parameter(self, mode: Mode | str, number: int) -> int:
        """The stored (EEPROM) value of an item; for restart-required items it may differ from
        the active one until the next power cycle."""
        with self._lock:
            item = self.parameters.item(mode, number)
            return self._stored[(item.mode, item.number)]

    def active_parameter(self, key: str) -> int:
        """The value in effect now (restart-required items: as of the last power-on)."""
        with self._lock:
            return self._param(key)

    def write_parameter(self, mode: Mode | str, number: int, value: int) -> None:
        """Store a tune / parameter / test item in the EEPROM. Raises SimRefused: ``x`` for an
        unknown, read-only or out-of-range value, ``s`` for a parameter-mode item with servo on."""
        with self._lock:
            try:
                item = self.parameters.item(mode, number)
            except (KeyError, ValueError) as exc:
                raise _x(str(exc.args[0])) from None
            if not item.writable or item.mode is Mode.MONITOR:
                raise _x(f"{item.label} is read-only")
            if item.mode is Mode.SYSTEM and self.servo_on:
                raise SimRefused("s", f"{item.label}: parameter-mode items are written with the servo off")
            try:
                item.check(value)
            except ParameterValueError as exc:
                raise _x(str(exc)) from None
            self._stored[(item.mode, item.number)] = value
            self._save_eeprom()
            if not item.restart_required:
                self._active[(item.mode, item.number)] = value
                self._axis.set_settings(self._settings(self._active))

    # ------------------------------------------------------------------ positions
    @property
    def physical_angle_rad(self) -> float:
        """Output angle from the motor encoder, CW positive seen from the flange (the sensor disk
        turns with it)."""
        return self._axis.output_pos_rad

    @property
    def load_angle_rad(self) -> float:
        """Load-side angle (after the gear's compliance, kinematic error, lost motion)."""
        return self._axis.load_pos_rad

    @property
    def output_ppr(self) -> int:
        return self.model.output_resolution_ppr

    def _pulses(self, angle_rad: float) -> int:
        return math.floor(angle_rad / TWO_PI * self.output_ppr + 0.5)

    @property
    def feedback_pulses(self) -> int:
        """Monitor 100: feedback position in output pulses, command sense, 0 at power-on with an
        incremental encoder."""
        return self._pulses(self._direction * (self._axis.output_pos_rad - self._feedback_zero_rad))

    @property
    def speed_mode(self) -> bool:
        """Control mode (system 0) is speed: no position loop, the error counter stays at zero."""
        return self._axis.settings.control_mode == "speed"

    @property
    def command_pulses(self) -> int:
        """Monitor 101: command position in output pulses, command sense."""
        if self.speed_mode:
            return self.feedback_pulses
        return self._pulses(self._direction * (self._axis.command_pos_rad - self._feedback_zero_rad))

    @property
    def error_pulses(self) -> int:
        """Monitor 102: the error counter, command - feedback."""
        return self.command_pulses - self.feedback_pulses

    @property
    def absolute_counts(self) -> int:
        """Multi-turn x 8192 + single-turn of the absolute motor encoder (DGR), physical sense."""
        turns = (self._axis.output_pos_rad - self._absolute_zero_rad) / TWO_PI * self.model.ratio
        return math.floor(turns * ABS_COUNTS_PER_MOTOR_REV + 0.5)

    # ------------------------------------------------------------------ I/O
    def set_inputs(self, mask: int) -> None:
        """Set the simulated CN2 inputs (INP): bits 4, 5, 9, 10. Bits 6-8 (origin, limit switches)
        set sensor signals of an actuator without option L; with option L the sensors drive them
        and INP's bits 6-8 are ignored (so a client's read-modify-write of IOS latches nothing)."""
        with self._lock:
            if mask < 0 or mask & ~INPUT_MASK:
                raise _x(f"INP {mask}: only input bits 4-10 can be set (mask {INPUT_MASK})")
            if self.has_sensors:
                mask &= ~SENSOR_MASK
            was_clear = self._inputs >> BIT_ERROR_CLEAR & 1
            self._inputs = mask
            if mask >> BIT_ERROR_CLEAR & 1 and not was_clear:
                self._clear_error_counter()
            self._update_brake()

    def _clear_error_counter(self) -> None:
        # CN2-2 CLEAR: the error counter is cleared (command := feedback), and with it alarm 60
        self._axis.clear_error()
        self._motion = "idle"
        if self.alarm == 60:
            self.alarm = 0

    @property
    def brake_holding(self) -> bool:
        """True while the brake holds: fitted and its 24 V coil unpowered (non-excitation brake)."""
        return self.has_brake and not self._inputs >> BIT_BRAKE_RELEASED & 1

    def _update_brake(self) -> None:
        self._axis.set_brake(self.brake_holding, self.brake_holding_torque_nm or 0.0)

    def _sensor_bits(self) -> int:
        bits = 0
        if not self.has_sensors:
            return bits
        angle = math.degrees(self.physical_angle_rad)

        def wrap(a: float) -> float:
            return (a + 180.0) % 360.0 - 180.0

        c = self.constants
        if abs(wrap(angle - self.origin_deg)) <= c.origin_slit_width_deg / 2:
            bits |= 1 << BIT_ORIGIN
        # a dog holds its switch from its edge on, over its arc, towards its stroke end
        if 0.0 <= wrap(self.ls1_deg - angle) <= c.limit_dog_arc_deg:
            bits |= 1 << BIT_LIMIT_1
        if 0.0 <= wrap(angle - self.ls2_deg) <= c.limit_dog_arc_deg:
            bits |= 1 << BIT_LIMIT_2
        return bits

    @property
    def moving(self) -> bool:
        """The command is moving (a jog, a move, or a stop ramp in progress)."""
        return self._motion != "idle"

    def io_bits(self) -> int:
        """The I/O bit mask of IOS / monitor 106 (docs/protocol.md, I/O table)."""
        with self._lock:
            bits = self._inputs | self._sensor_bits()
            if self.servo_on:
                bits |= 1 << BIT_SERVO_ON
            if not self.alarm:
                bits |= 1 << BIT_READY
            else:
                bits |= 1 << BIT_ALARM
                alarm = self.alarm_table.get(self.alarm)
                if alarm is not None:
                    bits |= alarm.alm_bits << BIT_ALM_A
            if self.servo_on and abs(self.error_pulses) <= self._param("in_position_range") \
                    and not self.moving:
                bits |= 1 << BIT_IN_POSITION
            if self.moving:
                bits |= 1 << BIT_MOVING
            return bits

    # ------------------------------------------------------------------ sensors (sim only)
    def set_sensor_angle(self, which: str, angle_deg: float) -> None:
        """Move the origin slit (``"origin"``) or a limit-switch dog (``"ls1"``, ``"ls2"``), as in
        the sensor adjustment procedure of FHA-C manual 4-7-2."""
        with self._lock:
            if which not in ("origin", "ls1", "ls2"):
                raise ValueError(f"sensor {which!r}: origin, ls1 or ls2")
            if not self.has_sensors:
                raise _x("this actuator has no option-L sensor set")
            if not math.isfinite(angle_deg):
                raise _x("sensor angle must be finite")
            setattr(self, f"{which}_deg", float(angle_deg))

    # ------------------------------------------------------------------ servo and motion
    def set_servo(self, on: bool) -> None:
        """Servo on / off. On is refused (``x``) while an alarm is active; a holding brake is not
        an error (the motor then works against it)."""
        with self._lock:
            if on:
                if self.alarm:
                    raise _x(f"alarm {self.alarm_table.describe(self.alarm)} is active: clear it first")
                if not self.servo_on:
                    self._axis.servo_on()  # the error counter starts empty: command := feedback
                    self._motion = "idle"
                self.servo_on = True
            else:
                self._servo_off()

    def _servo_off(self) -> None:
        self.servo_on = False
        self._motion = "idle"
        self._axis.servo_off()

    def _check_can_move(self, what: str) -> None:
        if self.alarm:
            raise _x(f"{what}: alarm {self.alarm_table.describe(self.alarm)} is active")
        if not self.servo_on:
            raise _x(f"{what}: the servo is off")

    def jog(self, speed_rpm: float) -> None:
        """Jog at ``speed_rpm`` (output, command sense) for 100 ms; repeat to keep jogging."""
        with self._lock:
            self._check_can_move("JOG")
            max_rpm = self.model.max_speed_rpm or 0.0
            if abs(speed_rpm) > max_rpm + 1e-9:
                raise _x(f"JOG {speed_rpm:g} r/min is above the maximum speed {max_rpm:g} r/min")
            if self._motion == "move":
                raise _x("JOG: a move is running (STP first)")
            speed = speed_rpm * RPM
            if self._motion != "jog" or speed != self._jog_speed_rad_s:
                self._axis.jog(speed, self._accel_rad_s2())
            self._jog_speed_rad_s = speed
            self._motion = "jog"
            if speed:
                self._motion_sign = 1.0 if speed > 0 else -1.0
            self._jog_deadline = self.time_s + self.constants.jog_watchdog_s

    def set_move_speed(self, speed_rpm: float) -> None:
        """The speed of the next MOV (SPD), output r/min."""
        with self._lock:
            max_rpm = self.model.max_speed_rpm or 0.0
            if not 0 < speed_rpm <= max_rpm + 1e-9:
                raise _x(f"SPD {speed_rpm:g} r/min outside 0 ... {max_rpm:g}")
            self._move_speed_rad_s = speed_rpm * RPM

    def move_by(self, angle_deg: float) -> None:
        """Move by ``angle_deg`` (output, command sense) at the SPD speed."""
        with self._lock:
            self._check_can_move("MOV")
            if self.moving:
                raise _x("MOV: the axis is moving")
            if angle_deg == 0:
                return
            self._axis.move_by(math.radians(angle_deg), self._move_speed_rad_s, self._accel_rad_s2())
            self._motion = "move"
            self._motion_sign = 1.0 if angle_deg > 0 else -1.0

    def stop(self) -> None:
        """Decelerate to standstill and hold (servo stays on)."""
        with self._lock:
            if self.moving and self.servo_on:
                self._axis.stop(self._accel_rad_s2())
                self._motion = "stop"

    def _halt(self) -> None:
        """Stop the command at once (an inhibit input or a limit switch)."""
        self._axis.stop(math.inf)
        self._motion = "idle"

    # ------------------------------------------------------------------ alarms
    def raise_alarm(self, code: int) -> None:
        """Raise an alarm (as the drive's supervision does, or injected for training: FLT)."""
        with self._lock:
            alarm = self.alarm_table.get(code)
            if alarm is None:
                raise _x(f"alarm {code} is not in the {self.alarm_table.driver} alarm table")
            if alarm.absolute_only and not self.absolute_encoder:
                raise _x(f"alarm {code} ({alarm.name}) exists only with an absolute encoder")
            if self.alarm:
                return  # the first alarm stays on the display
            self.alarm = code
            stamp = datetime.now(UTC).isoformat(timespec="seconds")
            self.alarm_history.insert(0, AlarmRecord(code, self.time_s, stamp))
            del self.alarm_history[self.constants.alarm_history_length:]
            # on an alarm the motor is de-energised and coasts (HA-655 manual p.10)
            self._servo_off()
            self._save_eeprom()

    def clear_alarm(self) -> None:
        """ACL: clears alarms 20 and 60 (as the real driver); others need a power cycle (``x``)."""
        with self._lock:
            if not self.alarm:
                return
            alarm = self.alarm_table.get(self.alarm)
            if alarm is None or not alarm.clearable:
                raise _x(f"alarm {self.alarm_table.describe(self.alarm)} is cleared only by a power cycle")
            if self.alarm == 20:
                self._overload_a2s = 0.0
            if self.alarm == 60:
                self._axis.clear_error()
            self.alarm = 0

    @property
    def overload_threshold_a2s(self) -> float:
        """I^2 t above the continuous current at which alarm 20 trips, A^2 s."""
        i_max = self.model.max_current_a
        i_cont = self.resolved.continuous_current_a
        return (i_max**2 - i_cont**2) * self.constants.overload_time_at_max_current_s

    @property
    def overload_rate(self) -> float:
        """Monitor 105 as a fraction: 1.0 = alarm 20."""
        return self._overload_a2s / self.overload_threshold_a2s

    # ------------------------------------------------------------------ absolute encoder
    def clear_multi_turn(self) -> None:
        """OWW: starts clearing the multi-turn data; the ``q`` comes ``oww_clear_s`` later."""
        with self._lock:
            if self.servo_on:
                raise _x("OWW: the servo is on")
            if not self.absolute_encoder:
                raise _x("OWW: the encoder is incremental")
            if self._oww_done_at is not None:
                raise _x("OWW: repeated before the first acknowledge")
            self._oww_done_at = self.time_s + self.oww_clear_s

    def _finish_oww(self) -> None:
        multi = math.floor(self.absolute_counts / ABS_COUNTS_PER_MOTOR_REV)
        delta = multi * TWO_PI / self.model.ratio  # output angle of the cleared motor turns
        self._absolute_zero_rad += delta
        self._feedback_zero_rad = self._absolute_zero_rad
        self._oww_done_at = None
        self._save_eeprom()
        self._deferred.append(Reply("q"))

    def take_deferred_replies(self) -> list[Reply]:
        """Replies that came later than their command (OWW's ``q``), oldest first."""
        with self._lock:
            replies, self._deferred = self._deferred, []
            return replies

    # ------------------------------------------------------------------ time
    def advance(self, seconds: float) -> None:
        """Advance the simulation by ``seconds`` of drive time (stepped mode)."""
        if self._thread is not None and threading.current_thread() is not self._thread:
            raise RuntimeError("SimDrive.advance() is for stepped mode; this drive runs in real time")
        with self._lock:
            self._advance(seconds)

    def _advance(self, seconds: float) -> None:
        rate = self.servo_rate_hz
        exact = self._step_debt + seconds * rate
        steps = int(exact)
        self._step_debt = exact - steps
        per_tick = max(1, round(SUPERVISION_PERIOD_S * rate))
        dt = 1.0 / rate
        axis = self._axis
        while steps > 0:
            if self._steps_to_supervision <= 0:
                self._supervise()
                self._steps_to_supervision = per_tick
            chunk = min(steps, self._steps_to_supervision)
            tracing = self.trace.active
            if tracing:
                chunk = min(chunk, self.trace.steps_until_sample())
            axis.step(chunk)
            steps -= chunk
            self._steps_to_supervision -= chunk
            self.time_s += chunk * dt
            self.clock_s += chunk * dt
            if tracing and self.trace.after_steps(chunk):
                self.trace.sample(self._trace_value, self.alarm)

    def _trace_value(self, item: int) -> int:
        try:
            return self.monitor(item)
        except SimRefused:
            return 0

    def _supervise(self) -> None:
        """Every 1 ms: OWW, watchdog, inhibits and limit switches, alarms."""
        t = self.time_s
        axis = self._axis
        if self._oww_done_at is not None and t >= self._oww_done_at:
            self._finish_oww()
        if self._motion == "jog" and t >= self._jog_deadline:
            # the watchdog: no JOG for 100 ms -> the command ramps down fast enough for the axis to
            # stand still within the next 100 ms
            decel = max(self._accel_rad_s2(), abs(self._jog_speed_rad_s) / self.constants.jog_watchdog_stop_s)
            axis.stop(decel)
            self._motion = "stop"
        elif self._motion in ("move", "stop") and axis.motion_done:
            self._motion = "idle"
        if self.servo_on and self._motion != "idle":
            inputs = self._inputs | self._sensor_bits()
            forward = self._motion_sign > 0
            physical_cw = self._motion_sign * self._direction > 0
            if (
                (forward and inputs >> BIT_FWD_INHIBIT & 1)
                or (not forward and inputs >> BIT_REV_INHIBIT & 1)
                or (physical_cw and inputs >> BIT_LIMIT_2 & 1)
                or (not physical_cw and inputs >> BIT_LIMIT_1 & 1)
            ):
                self._halt()
        self._supervise_alarms()
        if self._recorder is not None:
            self._recorder.tick(self)

    def _supervise_alarms(self) -> None:
        axis = self._axis
        c = self.constants
        dt = SUPERVISION_PERIOD_S
        # 10 over speed (the peak since the last look, so no excursion slips between two)
        max_speed = (self.model.max_speed_rpm or math.inf) * RPM
        if axis.peak_speed_rad_s > c.over_speed_factor * max_speed:
            self.raise_alarm(10)
        # 20 overload: I^2 t above the continuous current
        i2 = axis.current_squared_integral_a2s
        heat = i2 - self._last_i2_a2s - self.resolved.continuous_current_a**2 * dt
        self._last_i2_a2s = i2
        self._overload_a2s = max(0.0, self._overload_a2s + heat)
        if self._overload_a2s >= self.overload_threshold_a2s:
            self.raise_alarm(20)
        # 41 abnormal regeneration: energy fed back beyond what the 40 W resistor dissipates
        regen = axis.regenerated_energy_j
        self._regen_j = max(0.0, self._regen_j + regen - self._last_regen_j - c.regeneration_resistor_w * dt)
        self._last_regen_j = regen
        if self._regen_j > c.regeneration_energy_capacity_j:
            self.raise_alarm(41)
        # 60 error counter overflow against parameter 6
        if self.servo_on and not self.speed_mode:
            item = self.parameters.by_key("position_error_allowance")
            allowance_pulses = self._param("position_error_allowance") * item.scale
            if axis.peak_error_pulses > allowance_pulses:
                self.raise_alarm(60)
        axis.reset_peaks()
        # 54 multi-turn overflow of the absolute encoder
        if self.absolute_encoder:
            multi = math.floor(self.absolute_counts / ABS_COUNTS_PER_MOTOR_REV)
            if not ABS_MULTI_TURN_RANGE[0] <= multi <= ABS_MULTI_TURN_RANGE[1]:
                self.raise_alarm(54)

    def start(self) -> None:
        """Run in real time in a thread (``sim-drive``) until :meth:`close`."""
        with self._lock:
            if self._thread is not None or self._closed:
                return
            self._stop_event.clear()
            self._thread = threading.Thread(target=self._run, name="sim-drive", daemon=True)
            self._thread.start()

    def _run(self) -> None:
        last = time.monotonic()
        while not self._stop_event.wait(0.002):
            now = time.monotonic()
            # a stalled machine makes the simulation lag instead of jumping
            elapsed = min(now - last, 0.05)
            last = now
            with self._lock:
                self._advance(elapsed)

    @property
    def running(self) -> bool:
        return self._thread is not None

    def close(self) -> None:
        """Stop the real-time thread, save the EEPROM (shaft position, absolute data), remove a
        temporary EEPROM. Safe to call twice."""
        thread = self._thread
        if thread is not None:
            self._stop_event.set()
            thread.join(timeout=5.0)
            self._thread = None
        with self._lock:
            if self._closed:
                return
            self._closed = True
            try:
                self.stop_recording()
                self._save_eeprom()
            finally:
                if self._tempdir is not None:
                    self._tempdir.cleanup()

    def __enter__(self) -> SimDrive:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------------ recording
    def start_recording(self, path: str | Path, sample_rate_hz: float = 1000.0) -> None:
        """Write what the axis does to an ``fha-recording/1`` CSV (t, pos, current, cmd_pos,
        load_pos, vel; physical frame, CW positive) until :meth:`stop_recording` or :meth:`close`."""
        with self._lock:
            self.stop_recording()
            self._recorder = _Recorder(self, Path(path), sample_rate_hz)

    def stop_recording(self) -> None:
        with self._lock:
            recorder, self._recorder = self._recorder, None
            if recorder is not None:
                recorder.close()

    # ------------------------------------------------------------------ monitors
    def monitor(self, item: int) -> int:
        """Wire value of monitor item ``item`` (docs/protocol.md, monitor table); SimRefused
        (``x``) for an item the drive does not have."""
        with self._lock:
            return self._monitor(item)

    def _monitor(self, item: int) -> int:
        axis = self._axis
        d = self._direction
        if item == 100:
            return self.feedback_pulses
        if item == 101:
            return self.command_pulses
        if item == 102:
            return self.error_pulses
        if item == 103:
            return round(d * axis.output_speed_rad_s / RPM * 100)
        if item == 104:
            return round(d * axis.current_a * 1000)
        if item == 105:
            return round(self.overload_rate * 1000)
        if item == 106:
            return self.io_bits()
        if item == 107:
            return self._pulses(self.load_angle_rad)
        if item == 108:
            return round(d * axis.torque_nm * 100)
        if item == 0:
            return round(d * axis.output_speed_rad_s / RPM * self.model.ratio)
        if item == 1:
            return round(100 * d * axis.current_a / self.model.max_current_a)
        if item in (3, 4, 7, 8, 9, 10):
            if item in (3, 4):
                count = self.error_pulses
            elif item in (7, 8):
                count = self.feedback_pulses
            else:  # command pulses counted at the input since power-on: through the electronic gear
                s = axis.settings
                pulses = self.command_pulses - self._pulses(self._direction * self._command_zero_rad)
                count = round(pulses * s.electronic_gear_denominator / s.electronic_gear_numerator)
            low, high = split_low_high(count)
            return low if item in (3, 7, 9) else high
        raise _x(f"no monitor item {item}")

    # ------------------------------------------------------------------ the protocol
    def execute(self, command: str, value: int) -> Reply | None:
        """Do one CN3 command. Returns its reply, or None when the reply comes later
        (OWW: see :meth:`take_deferred_replies`)."""
        with self._lock:
            handler = _HANDLERS.get(command)
            if handler is None:
                return Reply("x", reason=f"unknown command {command}")
            try:
                result = handler(self, value)
            except SimRefused as exc:
                return Reply(exc.terminal, reason=exc.reason)
            except (TraceError, SimConfigError) as exc:
                return Reply("x", reason=str(exc))
            if result is _DEFERRED:
                return None
            if result is None:
                return Reply("q")
            if isinstance(result, str):
                return Reply("q", (result,))
            return Reply("q", tuple(result))

    def capabilities(self) -> list[str]:
        """The extension commands this drive answers (CAP), in the codec's order."""
        return [c.value for c in Command if c in EXTENSION_COMMANDS and c.value in _HANDLERS]


class _Recorder:
    """Rows for an fha-recording/1 file, taken at the supervision ticks, written in blocks."""

    COLUMNS = ("t", "pos", "current", "cmd_pos", "load_pos", "vel")

    def __init__(self, drive: SimDrive, path: Path, sample_rate_hz: float):
        from fha_studio.recording import RecordingMetadata, RecordingWriter

        if not 0 < sample_rate_hz <= 1.0 / SUPERVISION_PERIOD_S:
            raise ValueError(f"recording rate {sample_rate_hz:g} Hz: 0 ... {1 / SUPERVISION_PERIOD_S:g}")
        self.every = max(1, round(1.0 / (sample_rate_hz * SUPERVISION_PERIOD_S)))
        metadata = RecordingMetadata(
            actuator=drive.actuator_code,
            load_inertia_kgm2=drive.config.load_inertia_kgm2,
            supply_voltage=drive.actuator.supply_voltage,
            sample_rate_hz=1.0 / (self.every * SUPERVISION_PERIOD_S),
            extra={"recorded_by": f"FHA Studio simulated drive {_version} ({drive.driver})"},
        )
        self.writer = RecordingWriter(path, metadata, self.COLUMNS)
        self.rows: list[tuple[float, ...]] = []
        self.count = 0

    def tick(self, drive: SimDrive) -> None:
        self.count += 1
        if self.count < self.every:
            return
        self.count = 0
        axis = drive._axis
        self.rows.append((
            drive.clock_s, math.degrees(axis.output_pos_rad), axis.current_a,
            math.degrees(axis.command_pos_rad), math.degrees(axis.load_pos_rad), axis.output_speed_rpm,
        ))
        if len(self.rows) >= 200:
            self.flush()

    def flush(self) -> None:
        if self.rows:
            self.writer.append_rows(self.rows)
            self.rows = []

    def close(self) -> None:
        try:
            self.flush()
        finally:
            self.writer.close()


_DEFERRED = object()


def _cmd_dgr(d: SimDrive, value: int) -> str:
    if d.servo_on:
        raise SimRefused("s", "DGR: the servo is on")
    if not d.absolute_encoder:
        raise _x("DGR: the encoder is incremental")
    return str(d.absolute_counts)


def _cmd_oww(d: SimDrive, value: int) -> object:
    d.clear_multi_turn()
    return _DEFERRED


def _cmd_idn(d: SimDrive, value: int) -> list[str]:
    return [d.driver, d.actuator_code, f"FHA Studio simulated drive {_version}"]


def _cmd_select(mode: Mode) -> Callable[[SimDrive, int], None]:
    def select(d: SimDrive, value: int) -> None:
        try:
            item = d.parameters.item(mode, value)
        except KeyError as exc:
            raise _x(str(exc.args[0])) from None
        d._selected = (item.mode, item.number)

    return select


def _cmd_prd(d: SimDrive, value: int) -> str:
    if d._selected is None:
        raise _x("PRD: no item selected (PSL/TSL first)")
    return str(d.read_parameter(*d._selected))


def _cmd_pwr(d: SimDrive, value: int) -> None:
    if d._selected is None:
        raise _x("PWR: no item selected (PSL/TSL first)")
    d.write_parameter(*d._selected, value)


def _cmd_mon(d: SimDrive, value: int) -> str:
    return str(d.monitor(value))


def _cmd_mmr(d: SimDrive, value: int) -> str:
    if value <= 0 or value >= 1 << 16:
        raise _x(f"MMR: mask {value} selects no monitor item 100-115")
    items = [100 + k for k in range(16) if value >> k & 1]
    return ",".join(str(d.monitor(i)) for i in items)


def _cmd_svo(d: SimDrive, value: int) -> None:
    if value not in (0, 1):
        raise _x(f"SVO {value}: 1 on, 0 off")
    d.set_servo(bool(value))


def _cmd_ahs(d: SimDrive, value: int) -> list[str]:
    return [f"{a.code},{round(a.seconds_since_power_on)}" for a in d.alarm_history]


def _cmd_pwc(d: SimDrive, value: int) -> None:
    d.power_cycle()


def _cmd_trace(setter: str) -> Callable[[SimDrive, int], None]:
    def run(d: SimDrive, value: int) -> None:
        getattr(d.trace, setter)(value)

    return run


def _cmd_tst(d: SimDrive, value: int) -> str:
    state, count = d.trace.status()
    return f"{state},{count}"


def _cmd_trb(d: SimDrive, value: int) -> list[str]:
    return [",".join(str(v) for v in row) for row in d.trace.block(value)]


def _cmd_sensor(which: str) -> Callable[[SimDrive, int], None]:
    def run(d: SimDrive, value: int) -> None:
        d.set_sensor_angle(which, value / 100.0)

    return run


def _cmd_snq(d: SimDrive, value: int) -> str:
    return ",".join(str(round(a * 100)) for a in (d.origin_deg, d.ls1_deg, d.ls2_deg))


_HANDLERS: dict[str, Callable[[SimDrive, int], Any]] = {
    "DGR": _cmd_dgr,
    "OWW": _cmd_oww,
    "IDN": _cmd_idn,
    "CAP": lambda d, v: " ".join(d.capabilities()),
    "PSL": _cmd_select(Mode.SYSTEM),
    "TSL": _cmd_select(Mode.TUNE),
    "JSL": _cmd_select(Mode.TEST),
    "PRD": _cmd_prd,
    "PWR": _cmd_pwr,
    "MON": _cmd_mon,
    "MMR": _cmd_mmr,
    "SVO": _cmd_svo,
    "JOG": lambda d, v: d.jog(v / 100.0),
    "SPD": lambda d, v: d.set_move_speed(v / 100.0),
    "MOV": lambda d, v: d.move_by(v / 100.0),
    "STP": lambda d, v: d.stop(),
    "ALM": lambda d, v: str(d.alarm),
    "AHS": _cmd_ahs,
    "ACL": lambda d, v: d.clear_alarm(),
    "IOS": lambda d, v: str(d.io_bits()),
    "INP": lambda d, v: d.set_inputs(v),
    "PWC": _cmd_pwc,
    "TCH": _cmd_trace("set_channels"),
    "TDV": _cmd_trace("set_divider"),
    "TTG": _cmd_trace("set_trigger"),
    "TTC": _cmd_trace("set_trigger_channel"),
    "TTL": _cmd_trace("set_trigger_level"),
    "TPR": _cmd_trace("set_pretrigger"),
    "TAR": _cmd_trace("arm"),
    "TST": _cmd_tst,
    "TRB": _cmd_trb,
    "FLT": lambda d, v: d.raise_alarm(v),
    "SNO": _cmd_sensor("origin"),
    "SNA": _cmd_sensor("ls1"),
    "SNB": _cmd_sensor("ls2"),
    "SNQ": _cmd_snq,
}

__all__ = ["AlarmRecord", "Reply", "SimDrive", "SimRefused"]
