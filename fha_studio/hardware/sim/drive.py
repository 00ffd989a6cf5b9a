"""`SimDrive`: a simulated HA-655 / HA-675 driver with an FHA-C actuator that can be commissioned.

The drive keeps its tune / parameter / test items in an EEPROM file, switches the servo, jogs
(under the 100 ms communication watchdog), moves by an angle, supervises the axis (alarms 10, 20,
41, 60, encoder alarms on demand), reads its I/O (inhibits, option-L sensors, brake coil) and
captures traces. The axis itself is :mod:`fha_studio.physics`, stepped at the servo rate.

This module holds the servo, positions and time; the other jobs have their own modules:
:mod:`.memory` (items and EEPROM), :mod:`.motion` (jog, move, stop, the watchdog), :mod:`.io`
(inputs, sensors, brake, I/O bits), :mod:`.supervision` (alarms and their checks), :mod:`.trace`
(trace capture), :mod:`.monitors` (the monitor items' wire values) and :mod:`.recorder`
(``fha-recording/1`` output). The drive's methods speak units (r/min, degrees,
item values); its CN3 face is :class:`fha_studio.hardware.sim.responder.SimResponder`.

Time: in *stepped* mode nothing moves until :meth:`SimDrive.advance` is called (deterministic,
for tests); :meth:`SimDrive.start` runs a thread that advances in real time until :meth:`close`.

Signs: the drive's command sense is FWD positive (JOG, MOV, monitors 100-104, 108). The physical
sense is CW seen from the output flange positive (FHA-C manual 1-10): with rotary direction 0
(system item 8) FWD = CW, with 1 FWD = CCW. The encoder's own counts (``DGR``) and the external
load encoder (monitor 107) are physical: they do not follow the rotary-direction setting.

Every CN3 command reaches the drive through :class:`SimResponder` (a decoded request ->
:class:`SimReply`), which is what :class:`SimProtocolServer` calls after decoding bytes.
"""

from __future__ import annotations

import math
import tempfile
import threading
from collections import deque
from pathlib import Path
from typing import Any

from fha_studio import __version__ as _version
from fha_studio.hardware.api import SensorName
from fha_studio.hardware.parameters import Mode, driver_family, load_alarm_table, load_parameter_model
from fha_studio.hardware.protocol import ABSOLUTE_COUNTS_PER_TURN
from fha_studio.hardware.sim.axis import (
    DEFAULT_SERVO_RATE_HZ,
    build_axis,
    build_model,
    resolve_actuator,
)
from fha_studio.hardware.sim.constants import SimConstants, load_sim_constants
from fha_studio.hardware.sim.eeprom import EepromFile, eeprom_path
from fha_studio.hardware.sim.excitation import SimExcitation, excitation_offset_rad
from fha_studio.hardware.sim.io import SimIo
from fha_studio.hardware.sim.memory import ItemId, ParameterMemory, PersistentState
from fha_studio.hardware.sim.monitors import monitor_wire
from fha_studio.hardware.sim.motion import RPM, MotionKind, SimMotion
from fha_studio.hardware.sim.options import Battery, SimConfig, SimConfigError, Wiring
from fha_studio.hardware.sim.realtime import RealTime
from fha_studio.hardware.sim.recorder import SimRecorder
from fha_studio.hardware.sim.reply import SimRefused, SimReply, rejected, servo_is_on
from fha_studio.hardware.sim.spd_cmd import SpeedCommandInput, spd_cmd_speeds
from fha_studio.hardware.sim.supervision import (
    MOTION_WIRING_FAULTS,
    SUPERVISION_PERIOD_S,
    AlarmSupervisor,
    SimAlarmRecord,
    WiringFaultTrip,
)
from fha_studio.hardware.sim.trace import SimTrace
from fha_studio.physics import ServoAxis, ServoSettings, servo_settings

TWO_PI = 2.0 * math.pi
#: Monitor 112 and the status read-outs give the motor current as its mean over this window: with
#: quantised feedback the instantaneous current (monitor 104) dithers by tenths of an ampere around
#: its mean (the pulse-difference speed steps by one pulse per servo period), so one sample per
#: status poll reads as a standing current that is not there. 10 ms spans many dither periods and
#: is still short against a move.
CURRENT_MEAN_WINDOW_S = 0.01


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
        #: held by every method; hold it to make several calls one step (the responder does, for
        #: each command and what its journal writes of it)
        self.lock = threading.RLock()
        self._realtime = RealTime(self.lock, self._advance, "sim-drive")
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
        # a catalogue actuator always has its ratio (only a custom axis model lacks one)
        self.ratio: float = float(resolved.actuator.ratio)
        family = driver_family(self.driver)
        self.parameters = load_parameter_model(family)
        self.alarm_table = load_alarm_table(family)

        c = self.constants
        self.io = SimIo(
            c,
            has_sensors=self.has_sensors,
            has_brake=self.has_brake,
            origin_deg=config.origin_deg if config.origin_deg is not None else c.origin_angle_deg,
            ls1_deg=config.ls1_deg if config.ls1_deg is not None else c.limit_switch_1_angle_deg,
            ls2_deg=config.ls2_deg if config.ls2_deg is not None else c.limit_switch_2_angle_deg,
            brake_supply=config.brake_supply,
        )
        if config.battery is not Battery.OK and not self.absolute_encoder:
            raise SimConfigError(f"simulated drive option battery={config.battery}: {self.actuator_code} "
                                 "has an incremental encoder (no backup battery)")
        # the encoder's A/B leads swapped: it counts the other way (docs/sim.md, wiring faults)
        self._encoder_sign = -1.0 if config.wiring is Wiring.ENCODER_SWAPPED else 1.0
        self.oww_clear_s = config.oww_clear_s if config.oww_clear_s is not None else c.oww_clear_s
        self.supervisor = AlarmSupervisor(
            self.alarm_table,
            c,
            max_speed_rad_s=(self.model.max_speed_rpm or math.inf) * RPM,
            max_current_a=self.model.max_current_a,
            continuous_current_a=resolved.continuous_current_a,
            absolute_encoder=self.absolute_encoder,
        )

        # EEPROM: stored values; the active ones are copied at power-on
        if not config.eeprom:  # a temporary EEPROM, gone with the drive
            self._tempdir = tempfile.TemporaryDirectory(prefix="fha-sim-")
        self.memory = ParameterMemory(
            self.parameters,
            EepromFile(eeprom_path(config.eeprom, self.driver, self.actuator_code, self._tempdir)),
            driver=self.driver,
            actuator_code=self.actuator_code,
        )
        self.eeprom = self.memory.eeprom
        persistent = self.memory.load()
        if persistent is None:
            persistent = PersistentState()
            try:
                self._store_as_delivered(persistent)
            except SimConfigError:
                if self._tempdir is not None:  # no drive: nothing will close it
                    self._tempdir.cleanup()
                raise
            self.memory.save(persistent)
        self.supervisor.history = persistent.alarm_history
        self._absolute_zero_rad = persistent.absolute_zero_rad  # physical angle where the absolute count is 0
        # the shaft does not move while the drive is off: a restarted sim finds it where it was
        self.axis: ServoAxis = build_axis(
            self.model, self._settings(self.memory.stored), persistent.mechanical_angle_rad
        )

        self.trace = SimTrace()
        self.speed_command_input = SpeedCommandInput()  # CN2-31/32 SPD-CMD (.spd_cmd), 0 V unwired
        #: clears of the multi-turn data finished (OWW's ``q`` comes when one finishes)
        self.multi_turn_clears_done = 0
        self.clock_s = 0.0  # simulated time since the drive was built (not reset by PWC)
        self._recorder: SimRecorder | None = None
        self._power_on()

    # ------------------------------------------------------------------ construction helpers
    @classmethod
    def from_url(cls, url: str, **kwargs: Any) -> SimDrive:
        from fha_studio.hardware.sim.options import config_from_url

        return cls(config=config_from_url(url), **kwargs)

    def _store_as_delivered(self, persistent: PersistentState) -> None:
        """A new EEPROM: the ``preset`` items, and with ``battery=lost`` multi-turn data that no
        longer matches the shaft (the backup failed while the drive was stored)."""
        for mode, number, value in self.config.preset:
            try:
                self.memory.write(mode, number, value, servo_on=False)
            except SimRefused as exc:
                raise SimConfigError(
                    f"simulated drive option preset {mode}.{number}={value}: {exc.reason}"
                ) from None
        if self.config.battery is Battery.LOST:
            turns = self.constants.lost_multi_turn_turns
            persistent.absolute_zero_rad -= turns * TWO_PI / self.ratio

    def _save_eeprom(self) -> None:
        self.memory.save(PersistentState(
            alarm_history=self.supervisor.history,
            mechanical_angle_rad=self.axis.output_pos_rad,
            absolute_zero_rad=self._absolute_zero_rad,
        ))

    # ------------------------------------------------------------------ power
    def _settings(self, values: dict[ItemId, int]) -> ServoSettings:
        by_key = self.memory.by_key(values)
        settings = servo_settings(self.model, by_key, self.servo_rate_hz, self.config.quantised)
        if self.config.wiring in MOTION_WIRING_FAULTS:
            # a lead open or swapped: the motor makes no useful torque
            settings = settings.replace(current_limit_a=0.0)
        return settings

    def _power_on(self) -> None:
        """Control power on: active items from the EEPROM, counters from zero, no alarm."""
        axis = self.axis
        self.memory.power_on()
        self.time_s = 0.0
        self.servo_on = False
        self.motion = SimMotion(axis, self.model, self.constants, self._param("jog_speed") * 0.01 * RPM)
        self._oww_done_at: float | None = None
        self._step_debt = 0.0
        self._steps_to_supervision = 0
        # (time_s, cumulative current integral A s, physical sense) after each step of _advance
        self._current_history: deque[tuple[float, float]] = deque([(0.0, axis.current_integral_a_s)])
        self.trace = SimTrace()
        self.excitation = SimExcitation()  # EXA / EXL / EXG: stopped by STP, servo off, an alarm
        axis.servo_off()
        axis.set_settings(self._settings(self.memory.active))
        self._direction = axis.settings.direction_sign
        # the feedback counter (monitor 100) starts at 0 at power-on with an incremental encoder
        # and reads the absolute position with an absolute one
        absolute = self.absolute_encoder
        self._feedback_zero_rad = self._absolute_zero_rad if absolute else axis.output_pos_rad
        self._command_zero_rad = axis.command_pos_rad - self._feedback_zero_rad
        self.supervisor.power_on(axis)
        axis.reset_peaks()
        self._update_brake()
        self.wiring_trip = WiringFaultTrip(self.config.wiring, self.constants)
        if self.config.wiring is Wiring.ENCODER_OPEN:
            self.raise_alarm(50)  # no valid signal from the encoder
        elif self.config.battery is not Battery.OK:
            self.raise_alarm(56)  # the backup battery's voltage is low

    def power_cycle(self) -> None:
        """Simulated control-power cycle (PWC): restart-required items take effect, alarms clear,
        an incremental position is lost. Refused (``s``) while the servo is on."""
        with self.lock:
            if self.servo_on:
                raise servo_is_on("servo on: switch it off before a power cycle")
            self._save_eeprom()
            self._power_on()

    # ------------------------------------------------------------------ parameters
    def _param(self, key: str) -> int:
        return self.memory.value(key)

    def _accel_rad_s2(self) -> float:
        return self._param("jog_acceleration") * RPM

    def item_id(self, mode: Mode, number: int) -> ItemId:
        """The item ``number`` of ``mode`` this drive has (PSL / TSL / JSL select it); ``x`` for
        one it does not have."""
        try:
            item = self.parameters.item(mode, number)
        except KeyError as exc:
            raise rejected(str(exc.args[0])) from None
        return (item.mode, item.number)

    def read_parameter(self, mode: Mode | str, number: int) -> int:
        """The stored (EEPROM) value of an item; for restart-required items it may differ from
        the active one until the next power cycle."""
        with self.lock:
            return self.memory.stored_value(mode, number)

    def active_parameter(self, key: str) -> int:
        """The value in effect now (restart-required items: as of the last power-on)."""
        with self.lock:
            return self._param(key)

    def write_parameter(self, mode: Mode | str, number: int, value: int) -> None:
        """Store a tune / parameter / test item in the EEPROM. Raises SimRefused: ``x`` for an
        unknown, read-only or out-of-range value, ``s`` for a parameter-mode item with servo on."""
        with self.lock:
            active_changed = self.memory.write(mode, number, value, servo_on=self.servo_on)
            self._save_eeprom()
            if active_changed:
                self.axis.set_settings(self._settings(self.memory.active))

    # ------------------------------------------------------------------ positions
    @property
    def physical_angle_rad(self) -> float:
        """Output angle from the motor encoder, CW positive seen from the flange (the sensor disk
        turns with it)."""
        return self.axis.output_pos_rad

    @property
    def load_angle_rad(self) -> float:
        """Load-side angle (after the gear's compliance, kinematic error, lost motion)."""
        return self.axis.load_pos_rad

    @property
    def output_ppr(self) -> int:
        return self.model.output_resolution_ppr

    def _pulses(self, angle_rad: float) -> int:
        return math.floor(angle_rad / TWO_PI * self.output_ppr + 0.5)

    @property
    def feedback_pulses(self) -> int:
        """Monitor 100: feedback position in output pulses, command sense, 0 at power-on with an
        incremental encoder."""
        sense = self._encoder_sign * self._direction
        return self._pulses(sense * (self.axis.output_pos_rad - self._feedback_zero_rad))

    @property
    def speed_mode(self) -> bool:
        """Control mode (system 0) is speed: no position loop, the error counter stays at zero."""
        return self.axis.settings.control_mode == "speed"

    @property
    def command_pulses(self) -> int:
        """Monitor 101: command position in output pulses, command sense."""
        if self.speed_mode:
            return self.feedback_pulses
        sense = self._encoder_sign * self._direction
        return self._pulses(sense * (self.axis.command_pos_rad - self._feedback_zero_rad))

    @property
    def error_pulses(self) -> int:
        """Monitor 102: the error counter, command - feedback."""
        return self.command_pulses - self.feedback_pulses

    @property
    def input_pulses(self) -> int:
        """Command pulses counted at the CN2 input since power-on (through the electronic gear)."""
        s = self.axis.settings
        pulses = self.command_pulses - self._pulses(self._direction * self._command_zero_rad)
        return round(pulses * s.electronic_gear_denominator / s.electronic_gear_numerator)

    @property
    def load_pulses(self) -> int:
        """Monitor 107: the load-side encoder in output pulses, physical sense."""
        return self._pulses(self.load_angle_rad)

    @property
    def output_speed_rpm(self) -> float:
        """Output speed, r/min, command sense."""
        return self._direction * self.axis.output_speed_rad_s / RPM

    @property
    def motor_current_a(self) -> float:
        """Motor current, A, command sense."""
        return self._direction * self.axis.current_a

    @property
    def motor_current_mean_a(self) -> float:
        """Monitor 112: the motor current's mean over the last CURRENT_MEAN_WINDOW_S, A, command
        sense (the instantaneous current just after power-on, before any time has passed)."""
        t0, q0 = self._current_history[0]
        if self.time_s <= t0:
            return self.motor_current_a
        return self._direction * (self.axis.current_integral_a_s - q0) / (self.time_s - t0)

    def _note_current(self) -> None:
        """Keep the newest point at least CURRENT_MEAN_WINDOW_S old, and those after it."""
        history = self._current_history
        history.append((self.time_s, self.axis.current_integral_a_s))
        while len(history) > 1 and self.time_s - history[1][0] >= CURRENT_MEAN_WINDOW_S - 1e-12:
            history.popleft()

    @property
    def output_torque_nm(self) -> float:
        """Output torque, N m, command sense."""
        return self._direction * self.axis.torque_nm

    @property
    def flange_torque_nm(self) -> float:
        """Monitor 111: a torque sensor between the output flange and the load, N m, physical sense
        (+ = the flange driving the load CW): an instrument on the load, as the load encoder."""
        return self.axis.flange_torque_nm

    @property
    def absolute_counts(self) -> int:
        """Multi-turn x 8192 + single-turn of the absolute motor encoder (DGR), physical sense."""
        angle = self._encoder_sign * (self.axis.output_pos_rad - self._absolute_zero_rad)
        turns = angle / TWO_PI * self.ratio
        return math.floor(turns * ABSOLUTE_COUNTS_PER_TURN + 0.5)

    @property
    def _angle_deg(self) -> float:
        return math.degrees(self.physical_angle_rad)

    # ------------------------------------------------------------------ I/O and sensors
    def set_inputs(self, mask: int) -> None:
        """Set the simulated CN2 inputs (INP): bits 4, 5, 9, 10. Bits 6-8 (origin, limit switches)
        set sensor signals of an actuator without option L; with option L the sensors drive them
        and INP's bits 6-8 are ignored (so a client's read-modify-write of IOS latches nothing)."""
        with self.lock:
            if self.io.set_inputs(mask):
                self._clear_error_counter()
            self._update_brake()

    def _clear_error_counter(self) -> None:
        # CN2-2 CLEAR: the error counter is cleared (command := feedback), and with it alarm 60
        self.axis.clear_error()
        self.motion.idle()
        if self.supervisor.code == 60:
            self.supervisor.code = 0

    @property
    def brake_holding(self) -> bool:
        """True while the brake holds: fitted and its 24 V coil unpowered (non-excitation brake)."""
        return self.io.brake_holding

    def _update_brake(self) -> None:
        self.axis.set_brake(self.io.brake_holding, self.brake_holding_torque_nm or 0.0)

    @property
    def moving(self) -> bool:
        """The axis is moving (:attr:`SimMotion.moving <.motion.SimMotion.moving>`)."""
        return self.motion.moving

    def watchdog_decel_rad_s2(self, speed_rad_s: float) -> float:
        """The deceleration the JOG watchdog stops the command with [rad/s^2] (.motion)."""
        return self.motion.watchdog_decel_rad_s2(speed_rad_s)

    def io_bits(self) -> int:
        """The I/O bit mask of IOS / monitor 106 (docs/protocol.md, I/O table)."""
        with self.lock:
            in_position = self.servo_on and abs(self.error_pulses) <= self._param("in_position_range")
            return self.io.bits(
                self._angle_deg,
                servo_on=self.servo_on,
                alarm=self.alarm,
                alm_bits=self.supervisor.alm_bits(),
                in_position=in_position,
                moving=self.moving,
            )

    def blocked_directions(self) -> tuple[bool, bool]:
        """(FWD blocked, REV blocked): an inhibit input or a limit switch stops a motion that way."""
        with self.lock:
            return self.io.blocked(self._angle_deg, self._direction)

    def set_sensor_angle(self, which: SensorName | str, angle_deg: float) -> None:
        """Move the origin slit (``"origin"``) or a limit-switch dog (``"ls1"``, ``"ls2"``), as in
        the sensor adjustment procedure of FHA-C manual 4-7-2 (sim only)."""
        with self.lock:
            self.io.set_sensor_angle(which, angle_deg)

    # ------------------------------------------------------------------ servo and motion
    def set_servo(self, on: bool) -> None:
        """Servo on / off: SVO over CN3 (full profile), or the controller's servo-ON input on CN2
        (any profile; the only way with the ``documented`` one). On is refused (``x``) while an
        alarm is active; a holding brake is not an error (the motor then works against it)."""
        with self.lock:
            if on:
                if self.alarm:
                    raise rejected(f"alarm {self.supervisor.describe()} is active: clear it first")
                if not self.servo_on:
                    self.axis.servo_on()  # the error counter starts empty: command := feedback
                    self.motion.idle()
                self.servo_on = True
            else:
                self._servo_off()

    def turn_by_hand(self, angle_deg: float) -> None:
        """Someone turns the output flange by ``angle_deg`` (CW positive seen from the flange)
        with the servo off, as in the encoder check or the sensor-dog adjustment (FHA-C manual
        4-7-2). Refused (``x``) with the servo on or while the brake holds."""
        with self.lock:
            if self.servo_on:
                raise rejected("the servo is on: the axis cannot be turned by hand")
            if self.brake_holding:
                raise rejected("the brake holds: release it (24 V on the brake) to turn the axis by hand")
            self.axis.turn_by_hand(math.radians(angle_deg))

    def controller_command(self, angle_deg: float) -> None:
        """The controller's pulse train on CN2: turn the output by ``angle_deg`` in the command
        sense (FWD positive; the rotary direction, system 8, decides CW or CCW). Needs the servo
        on (``x`` otherwise), as on a real drive."""
        self.move_by(angle_deg)

    def _servo_off(self) -> None:
        self.servo_on = False
        self.motion.idle()
        self.axis.servo_off()

    def _check_can_move(self, what: str) -> None:
        if self.alarm:
            raise rejected(f"{what}: alarm {self.supervisor.describe()} is active")
        if not self.servo_on:
            raise rejected(f"{what}: the servo is off")

    def jog(self, speed_rpm: float) -> None:
        """Jog at ``speed_rpm`` (output, command sense) for 100 ms; repeat to keep jogging."""
        with self.lock:
            self._check_can_move("JOG")
            max_rpm = self.model.max_speed_rpm or 0.0
            if abs(speed_rpm) > max_rpm + 1e-9:
                raise rejected(f"JOG {speed_rpm:g} r/min is above the maximum speed {max_rpm:g} r/min")
            self.motion.jog(speed_rpm * RPM, self._accel_rad_s2(), self.time_s)

    def set_move_speed(self, speed_rpm: float) -> None:
        """The speed of the next MOV (SPD), output r/min."""
        with self.lock:
            max_rpm = self.model.max_speed_rpm or 0.0
            if not 0 < speed_rpm <= max_rpm + 1e-9:
                raise rejected(f"SPD {speed_rpm:g} r/min outside 0 ... {max_rpm:g}")
            self.motion.move_speed_rad_s = speed_rpm * RPM

    def move_by(self, angle_deg: float) -> None:
        """Move by ``angle_deg`` (output, command sense) at the SPD speed."""
        with self.lock:
            self._check_can_move("MOV")
            self.motion.move_by(math.radians(angle_deg), self._accel_rad_s2(), self.time_s)

    def stop(self) -> None:
        """Decelerate to standstill and hold (servo stays on)."""
        with self.lock:
            if self.moving and self.servo_on:
                self.motion.stop(self._accel_rad_s2(), self.time_s)

    # ------------------------------------------------------------------ alarms
    @property
    def alarm(self) -> int:
        """The active alarm's code, 0 for none."""
        return self.supervisor.code

    @property
    def alarm_history(self) -> list[SimAlarmRecord]:
        """The alarm history, newest first (kept in the EEPROM)."""
        return self.supervisor.history

    def raise_alarm(self, code: int) -> None:
        """Raise an alarm (as the drive's supervision does, or injected for training: FLT)."""
        with self.lock:
            if not self.supervisor.record(code, self.time_s):
                return
            # on an alarm the motor is de-energised and coasts (HA-655 manual p.10)
            self._servo_off()
            self._save_eeprom()

    def clear_alarm(self) -> None:
        """ACL: clears alarms 20 and 60 (as the real driver); others need a power cycle (``x``)."""
        with self.lock:
            if self.supervisor.clear() == 60:
                self.axis.clear_error()

    @property
    def overload_threshold_a2s(self) -> float:
        """I^2 t above the continuous current at which alarm 20 trips, A^2 s."""
        return self.supervisor.overload_threshold_a2s

    @property
    def overload_rate(self) -> float:
        """Monitor 105 as a fraction: 1.0 = alarm 20."""
        return self.supervisor.overload_rate

    # ------------------------------------------------------------------ absolute encoder
    def clear_multi_turn(self) -> None:
        """OWW: starts clearing the multi-turn data; the ``q`` comes ``oww_clear_s`` later."""
        with self.lock:
            if self.servo_on:
                raise rejected("OWW: the servo is on")
            if not self.absolute_encoder:
                raise rejected("OWW: the encoder is incremental")
            if self._oww_done_at is not None:
                raise rejected("OWW: repeated before the first acknowledge")
            self._oww_done_at = self.time_s + self.oww_clear_s

    def _finish_oww(self) -> None:
        multi = math.floor(self.absolute_counts / ABSOLUTE_COUNTS_PER_TURN)
        delta = multi * TWO_PI / self.ratio  # output angle of the cleared motor turns
        self._absolute_zero_rad += delta
        self._feedback_zero_rad = self._absolute_zero_rad
        self._oww_done_at = None
        self._save_eeprom()
        self.multi_turn_clears_done += 1

    # ------------------------------------------------------------------ time
    def advance(self, seconds: float) -> None:
        """Advance the simulation by ``seconds`` of drive time (stepped mode)."""
        if self._realtime.elsewhere():
            raise RuntimeError("SimDrive.advance() is for stepped mode; this drive runs in real time")
        with self.lock:
            self._advance(seconds)

    def _advance(self, seconds: float) -> None:
        rate = self.servo_rate_hz
        exact = self._step_debt + seconds * rate
        steps = int(exact)
        self._step_debt = exact - steps
        per_tick = max(1, round(SUPERVISION_PERIOD_S * rate))
        dt = 1.0 / rate
        axis = self.axis
        while steps > 0:
            if self._steps_to_supervision <= 0:
                self._supervise()
                self._steps_to_supervision = per_tick
            chunk = min(steps, self._steps_to_supervision)
            tracing = self.trace.active
            if tracing:
                chunk = min(chunk, self.trace.steps_until_sample())
            added = self.excitation.values(chunk) if self.excitation.active else None
            axis.step(chunk, spd_cmd_speeds(self, chunk, added))
            steps -= chunk
            self._steps_to_supervision -= chunk
            self.time_s += chunk * dt
            self.clock_s += chunk * dt
            self._note_current()
            if tracing and self.trace.after_steps(chunk):
                self.trace.sample(self._trace_value, self.alarm)

    def _trace_value(self, item: int) -> int:
        try:
            return monitor_wire(self, item)
        except SimRefused:
            return 0

    def _supervise(self) -> None:
        """Every 1 ms: OWW, watchdog, inhibits and limit switches, alarms."""
        t = self.time_s
        axis = self.axis
        if self._oww_done_at is not None and t >= self._oww_done_at:
            self._finish_oww()
        self.excitation.supervise(t, self.servo_on and not self.alarm, excitation_offset_rad(self))
        motion = self.motion
        motion.supervise(t)
        if self.wiring_trip.active and self.wiring_trip.tick(
            self.servo_on and motion.kind in (MotionKind.JOG, MotionKind.MOVE)
        ):
            sign = motion.sign * self._direction
            self.raise_alarm(60)
            if self.wiring_trip.lurches:  # the axis lurched the wrong way before the trip
                self.axis.turn_by_hand(-sign * self.wiring_trip.lurch_rad)
        if self.servo_on and motion.moving and self.io.blocks(
            self._angle_deg,
            forward=motion.sign > 0,
            physical_cw=motion.sign * self._direction > 0,
        ):
            motion.halt(t)
        self._supervise_alarms()
        if self._recorder is not None:
            self._recorder.tick(self.clock_s, axis)

    def _supervise_alarms(self) -> None:
        allowance: float | None = None
        if self.servo_on and not self.speed_mode:
            item = self.memory.item("position_error_allowance")
            allowance = self._param("position_error_allowance") * item.scale
        multi_turn = None
        if self.absolute_encoder:
            multi_turn = math.floor(self.absolute_counts / ABSOLUTE_COUNTS_PER_TURN)
        tripped = self.supervisor.check(self.axis, error_allowance_pulses=allowance, multi_turn=multi_turn)
        if tripped:
            self.raise_alarm(tripped[0])

    def start(self) -> None:
        """Run in real time in a thread (``sim-drive``) until :meth:`close`."""
        with self.lock:
            if not self._closed:
                self._realtime.start()

    @property
    def running(self) -> bool:
        return self._realtime.running

    def close(self) -> None:
        """Stop the real-time thread, save the EEPROM (shaft position, absolute data), remove a
        temporary EEPROM. Safe to call twice."""
        self._realtime.stop()
        with self.lock:
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
    def start_recording(self, path: str | Path, sample_rate_hz: float = 1000.0, *,
                        torque_sensor: bool = False) -> None:
        """Write what the axis does to an ``fha-recording/1`` CSV (t, pos, current, cmd_pos,
        load_pos, vel; physical frame, CW positive) until :meth:`stop_recording` or :meth:`close`.
        ``torque_sensor``: also ``torque``, a torque sensor between the output flange and the load
        (monitor 111)."""
        with self.lock:
            self.stop_recording()
            self._recorder = SimRecorder(
                Path(path),
                sample_rate_hz,
                actuator_code=self.actuator_code,
                load_inertia_kgm2=self.config.load_inertia_kgm2,
                supply_voltage=self.actuator.supply_voltage,
                recorded_by=f"FHA Studio simulated drive {_version} ({self.driver})",
                torque_sensor=torque_sensor,
            )

    def stop_recording(self) -> None:
        with self.lock:
            recorder, self._recorder = self._recorder, None
            if recorder is not None:
                recorder.close()

    # ------------------------------------------------------------------ monitors
    def monitor(self, item: int) -> int:
        """Wire value of monitor item ``item`` (:func:`.monitors.monitor_wire`); SimRefused
        (``x``) for an item the drive does not have."""
        with self.lock:
            return monitor_wire(self, item)


__all__ = ["SimAlarmRecord", "SimDrive", "SimRefused", "SimReply"]
