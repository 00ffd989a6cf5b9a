"""`ServoAxis`: the plant of an `AxisModel` under an HA-655-like servo, stepped at servo_rate_hz.

Control structure (position mode of the HA-655 manual, tune mode items Kp/Kv/Tv/feed-forward):

    speed command   w_ref = Kp x (cmd - pos) + FF x d(cmd)/dt          [rad/s]
    current command i = Kv x (e + (1/Tv) x integral(e dt)),  e = w_ref - w     [A]
    clamped to the current limit, with conditional integration (no wind-up while saturated).

The current loop is taken as ideal (the motor torque is Kt x the commanded current within a
servo period). Feedback is the ideal motor-side position (quantisation belongs to the monitors,
see `MonitorOptions` in simulate.py).

Frames: the physical frame has positive = CW seen from the output flange (output_pos_rad,
load_pos_rad, output_speed_rad_s, current_a, torque_nm). The command frame is the drive's own
count: positive = FWD command. With rotary_direction 0 (parameter 8, the default) FWD = CW, so
the frames agree; with 1 they are mirrored. Commands (jog, move_by, pulses) and the pulse
counters (command_pulses, feedback_pulses, error_pulses) are in the command frame.

Electronic gear: command input pulses x numerator / denominator = output encoder pulses.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np

from fha_studio.catalog.tables import rotary_direction, rotary_direction_setting
from fha_studio.physics import _kernel
from fha_studio.physics.model import AxisModel
from fha_studio.physics.motion import MotionGenerator
from fha_studio.physics.stiffness import ARCSEC_PER_RAD

MIN_SERVO_RATE_HZ = 5000.0
# tuned_for(): the speed-loop bandwidth stays below this multiple of the load's anti-resonance
ANTI_RESONANCE_BANDWIDTH_FACTOR = 1.5
RAD_S_PER_RPM = 2.0 * math.pi / 60.0


@dataclass(frozen=True)
class ServoSettings:
    """Servo loop settings in SI (the sim maps the HA-655's tune/parameter values onto these).

    position_loop_gain_per_s: Kp, speed command per position error (1/s).
    speed_loop_gain_a_s_per_rad: Kv, current per output speed error (A per rad/s).
    speed_loop_integral_time_s: Tv (inf = no integral action).
    feed_forward_gain: share of the command speed fed forward to the speed loop (0..1).
    current_limit_a: None = the actuator's maximum current.
    rotary_direction: parameter 8; 0 = FWD turns CW seen from the output flange, 1 = reversed.
    in_position_range_pulses: the IN-POS window, in output encoder pulses.
    control_mode: parameter 0, "position" or "speed". In speed mode the command profile's speed
    is the speed-loop reference (jog = the speed command), there is no position loop and the
    error counter stays at zero.
    quantised_feedback: the loops see the encoder in whole pulses and the speed as the pulse
    difference per period, low-passed at speed_filter_hz (0 = unfiltered), as a real drive; the
    current then carries the quantisation noise a real drive's current has. Off: ideal feedback.
    """

    position_loop_gain_per_s: float = 30.0
    speed_loop_gain_a_s_per_rad: float = 10.0
    speed_loop_integral_time_s: float = 0.02
    feed_forward_gain: float = 0.0
    current_limit_a: float | None = None
    electronic_gear_numerator: int = 1
    electronic_gear_denominator: int = 1
    rotary_direction: int = 0
    in_position_range_pulses: int = 10
    servo_rate_hz: float = MIN_SERVO_RATE_HZ
    control_mode: str = "position"
    quantised_feedback: bool = False
    speed_filter_hz: float = 500.0

    def __post_init__(self) -> None:
        def check(name: str, ok: bool, what: str) -> None:
            if not ok:
                raise ValueError(f"servo settings: {name} must be {what}, got {getattr(self, name)!r}")

        check("position_loop_gain_per_s", self.position_loop_gain_per_s >= 0, "non-negative")
        check("speed_loop_gain_a_s_per_rad", self.speed_loop_gain_a_s_per_rad > 0, "positive")
        check("speed_loop_integral_time_s", self.speed_loop_integral_time_s > 0, "positive (inf = off)")
        check("feed_forward_gain", 0.0 <= self.feed_forward_gain <= 1.0, "between 0 and 1")
        check("current_limit_a", self.current_limit_a is None or self.current_limit_a >= 0, "non-negative")
        check("electronic_gear_numerator", isinstance(self.electronic_gear_numerator, int)
              and self.electronic_gear_numerator > 0, "a positive integer")
        check("electronic_gear_denominator", isinstance(self.electronic_gear_denominator, int)
              and self.electronic_gear_denominator > 0, "a positive integer")
        directions = rotary_direction()
        check("rotary_direction", self.rotary_direction in {s.value for s in directions},
              " or ".join(f"{s.value} (FWD = {s.fwd_direction})" for s in directions))
        check("in_position_range_pulses", self.in_position_range_pulses >= 0, "non-negative")
        check("servo_rate_hz", self.servo_rate_hz >= MIN_SERVO_RATE_HZ, f"at least {MIN_SERVO_RATE_HZ:g}")
        check("control_mode", self.control_mode in ("position", "speed"), '"position" or "speed"')
        check("speed_filter_hz", self.speed_filter_hz >= 0, "non-negative")

    @classmethod
    def tuned_for(cls, model: AxisModel, speed_bandwidth_hz: float = 20.0,
                  **overrides: object) -> ServoSettings:
        """Gains from a speed-loop bandwidth on the rigid-body inertia of the model.

        Kv = 2 pi f J / Kt, Tv = 4 / (2 pi f), Kp = 2 pi f / 5: a conventional cascade with the
        position loop well inside the speed loop. With a catalogue stiffness curve, f is capped at
        1.5 x the load's anti-resonance sqrt(K1 / J_load_side) / 2 pi (above it a heavy load on a
        160:1 gear rings); the cap uses the catalogue curve whether or not torsional_compliance is
        on, so a model and its nominal twin get the same gains.
        """
        f = speed_bandwidth_hz
        if model.stiffness is not None:
            f_anti = math.sqrt(model.stiffness.k1_nm_per_rad / model.load_side_inertia_kgm2) / (2.0 * math.pi)
            f = min(f, ANTI_RESONANCE_BANDWIDTH_FACTOR * f_anti)
        w = 2.0 * math.pi * f
        values: dict[str, object] = dict(
            position_loop_gain_per_s=w / 5.0,
            speed_loop_gain_a_s_per_rad=w * model.total_inertia_kgm2 / model.torque_constant_nm_per_a,
            speed_loop_integral_time_s=4.0 / w,
        )
        values.update(overrides)
        return cls(**values)  # type: ignore[arg-type]

    def replace(self, **changes: object) -> ServoSettings:
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)  # type: ignore[arg-type]

    @property
    def direction_sign(self) -> float:
        """+1 when a FWD command turns the flange CW (the 1-10 table's row for
        ``rotary_direction``), -1 when it turns it CCW."""
        return 1.0 if rotary_direction_setting(self.rotary_direction).fwd_turns_cw else -1.0


@dataclass(frozen=True)
class PanelGains:
    """The HA-655's tune items 0-3 as the front panel shows them, and what they mean in SI.

    The one reading of them (resources/drive/ha655-parameters.toml states it in the notes on tune
    items 0-2; docs/physics.md repeats it): the speed loop gain (tune 0, Hz) is the speed loop's
    crossover frequency with the actuator's own inertia J_A alone, Kv = 2 pi f J_A / Kt. The drive
    does not know the load, so a load J_L lowers the crossover in proportion, to about
    f J_A / (J_A + J_L). Tv (tune 1) in ms; Kp (tune 2) is output speed (rad/s) per rad of position
    error; feed-forward (tune 3) in % of the command speed.

    Used wherever panel values and physical gains meet, through :func:`servo_settings`: the
    simulated drive's loops, tuning's loops and proposals, the bench move fit; and the model
    check, which gives the loop it identifies in panel units.
    """

    speed_loop_gain_hz: float
    speed_loop_integral_compensation_ms: float
    position_loop_gain_per_s: float
    feed_forward_gain_pct: float

    @classmethod
    def from_items(cls, values: Mapping[str, int]) -> PanelGains:
        """Tune items 0-3 from the drive's items (wire values by key)."""
        return cls(
            speed_loop_gain_hz=values["speed_loop_gain"],
            speed_loop_integral_compensation_ms=values["speed_loop_integral_compensation"],
            position_loop_gain_per_s=values["position_loop_gain"],
            feed_forward_gain_pct=values["feed_forward_gain"],
        )

    @staticmethod
    def speed_gain_per_hz(model: AxisModel) -> float:
        """Kv (A s/rad) per Hz of tune 0: 2 pi J_A / Kt, the actuator's own inertia only."""
        return 2.0 * math.pi * model.actuator_inertia_kgm2 / model.torque_constant_nm_per_a

    def servo_fields(self, model: AxisModel) -> dict[str, float]:
        """The ``ServoSettings`` fields these items set, in SI."""
        return dict(
            position_loop_gain_per_s=float(self.position_loop_gain_per_s),
            speed_loop_gain_a_s_per_rad=self.speed_loop_gain_hz * self.speed_gain_per_hz(model),
            speed_loop_integral_time_s=self.speed_loop_integral_compensation_ms / 1000.0,
            feed_forward_gain=self.feed_forward_gain_pct / 100.0,
        )

    @classmethod
    def of_settings(cls, model: AxisModel, settings: ServoSettings) -> PanelGains:
        """The panel values (not rounded) that would give ``settings``' gains on ``model``."""
        return cls(
            speed_loop_gain_hz=settings.speed_loop_gain_a_s_per_rad / cls.speed_gain_per_hz(model),
            speed_loop_integral_compensation_ms=1000.0 * settings.speed_loop_integral_time_s,
            position_loop_gain_per_s=settings.position_loop_gain_per_s,
            feed_forward_gain_pct=100.0 * settings.feed_forward_gain,
        )

    @staticmethod
    def crossover_hz(model: AxisModel, speed_loop_gain_hz: float) -> float:
        """Where a speed loop gain of ``speed_loop_gain_hz`` crosses over on the whole rigid body
        of ``model`` (actuator and load): f J_A / (J_A + J_L), the proportional part alone."""
        return speed_loop_gain_hz * model.actuator_inertia_kgm2 / model.total_inertia_kgm2

    @staticmethod
    def speed_loop_gain_for(model: AxisModel, crossover_hz: float) -> float:
        """The speed loop gain (Hz, not rounded) that crosses over at ``crossover_hz`` on
        ``model``'s rigid body: the inverse of :meth:`crossover_hz`."""
        return crossover_hz * model.total_inertia_kgm2 / model.actuator_inertia_kgm2


def servo_settings(model: AxisModel, values: Mapping[str, int], servo_rate_hz: float,
                   quantised_feedback: bool = True) -> ServoSettings:
    """The HA-655's items (wire values by key) as ServoSettings for ``model``: the one mapping the
    simulated drive, tuning and the bench move fit share.

    Tune items 0-3 as :class:`PanelGains` reads them (the speed loop gain on the actuator's own
    inertia, whatever the load: a drive does not know it); control mode (system 0): 0 position,
    1 speed; the electronic gear, rotary direction and in-position range as the items say. With
    ``quantised_feedback`` the loops see whole encoder pulses, as a real drive does.
    """
    return ServoSettings(
        **PanelGains.from_items(values).servo_fields(model),
        electronic_gear_numerator=int(values["electronic_gear_numerator"]),
        electronic_gear_denominator=int(values["electronic_gear_denominator"]),
        rotary_direction=int(values["rotary_direction"]),
        in_position_range_pulses=int(values["in_position_range"]),
        servo_rate_hz=servo_rate_hz,
        control_mode="speed" if values["control_mode"] == 1 else "position",
        quantised_feedback=quantised_feedback,
    )


def kernel_params(model: AxisModel, settings: ServoSettings) -> _kernel.KernelParams:
    """Flatten model + settings for the loop (and pick the substep count)."""
    e = model.effects
    dt = 1.0 / settings.servo_rate_hz
    jm, jl = model.motor_side_inertia_kgm2, model.load_side_inertia_kgm2
    stiff = model.gear_stiffness
    compliant = stiff is not None
    if stiff is not None:
        k1, k2, k3 = stiff.k1_nm_per_rad, stiff.k2_nm_per_rad, stiff.k3_nm_per_rad
        t1, t2, th1, th2 = stiff.t1_nm, stiff.t2_nm, stiff.theta1_rad, stiff.theta2_rad
        j_eq = jm * jl / (jm + jl)
        damping = 2.0 * model.gear_damping_ratio * math.sqrt(k1 * j_eq)
        nsub = _kernel.substeps_for(jm, jl, stiff.max_stiffness_nm_per_rad, dt)
    else:
        k1 = k2 = k3 = t1 = t2 = th1 = th2 = damping = 0.0
        nsub = 1
    ratio = model.ratio or 0.0
    tv = settings.speed_loop_integral_time_s
    ilim = model.max_current_a if settings.current_limit_a is None else min(settings.current_limit_a,
                                                                             model.max_current_a)
    speed_mode = settings.control_mode == "speed"
    return _kernel.KernelParams(
        dt=dt, nsub=nsub, direction=settings.direction_sign,
        kp=0.0 if speed_mode else settings.position_loop_gain_per_s, kv=settings.speed_loop_gain_a_s_per_rad,
        tv_inv=0.0 if math.isinf(tv) else 1.0 / tv, ff=1.0 if speed_mode else settings.feed_forward_gain,
        ilim=ilim,
        # the plant's torque per ampere: a torque-constant error scales what the motor really gives
        kt=model.torque_constant_nm_per_a * (e.torque_constant_error.ratio if e.torque_constant_error
                                             else 1.0),
        jm=jm, jl=jl, j_total=jm + jl,
        compliant=compliant, k1=k1, k2=k2, k3=k3, t1=t1, t2=t2, th1=th1, th2=th2, damping=damping,
        fc=e.coulomb_friction.torque_nm if e.coulomb_friction else 0.0,
        visc=e.viscous_friction.coefficient_nm_s_per_rad if e.viscous_friction else 0.0,
        grav_a=e.gravity_load.amplitude_nm if e.gravity_load else 0.0,
        grav_phase=math.radians(e.gravity_load.phase_deg) if e.gravity_load else 0.0,
        offset=e.load_torque_offset.torque_nm if e.load_torque_offset else 0.0,
        rip_a=e.torque_ripple.amplitude_nm if e.torque_ripple else 0.0,
        rip_w=e.torque_ripple.cycles_per_motor_rev * ratio if e.torque_ripple else 0.0,
        rip_phase=math.radians(e.torque_ripple.phase_deg) if e.torque_ripple else 0.0,
        ke_a=e.kinematic_error.amplitude_arcsec / ARCSEC_PER_RAD if e.kinematic_error else 0.0,
        ke_w=e.kinematic_error.cycles_per_motor_rev * ratio if e.kinematic_error else 0.0,
        ke_phase=math.radians(e.kinematic_error.phase_deg) if e.kinematic_error else 0.0,
        lm_half=0.5 * e.lost_motion.width_arcsec / ARCSEC_PER_RAD if e.lost_motion else 0.0,
        resistance=model.phase_resistance_ohm,
        fc_pos_extra=e.asymmetric_friction.torque_pos_nm if e.asymmetric_friction else 0.0,
        fc_neg_extra=e.asymmetric_friction.torque_neg_nm if e.asymmetric_friction else 0.0,
        stribeck_a=e.stribeck_friction.static_torque_nm if e.stribeck_friction else 0.0,
        stribeck_v=e.stribeck_friction.velocity_rad_s if e.stribeck_friction else 1.0,
        pulse_rad=model.output_pulse_rad if settings.quantised_feedback else 0.0,
        speed_filter_alpha=(1.0 - math.exp(-2.0 * math.pi * settings.speed_filter_hz * dt)
                            if settings.speed_filter_hz > 0 else 1.0),
        j_sensed=jl - (model.flange_inertia_kgm2 or 0.0),
    )


SMALL_STEP_COUNT = 16
TRACE_CHANNELS = ("t", "cmd_pos", "pos", "load_pos", "vel", "current", "speed_cmd", "flange_torque",
                  "controller_pos")
#: the channels the kernel records; ``controller_pos`` is the axis's own (see ``controller_pos_rad``)
_KERNEL_CHANNELS = len(TRACE_CHANNELS) - 1


class ServoAxis:
    """One simulated axis: plant + servo + command generator. Not thread-safe (one owner).

    Units: rad, rad/s, A, N m, s, J; pulses = output encoder pulses (model.output_resolution_ppr
    per output turn). See the module docstring for frames and signs.
    """

    def __init__(self, model: AxisModel, settings: ServoSettings | None = None, *,
                 initial_pos_rad: float = 0.0) -> None:
        self._model = model
        self._settings = settings if settings is not None else ServoSettings.tuned_for(model)
        self._params = kernel_params(model, self._settings)
        self._state = _kernel.KernelState(xm=float(initial_pos_rad), xl=float(initial_pos_rad))
        self._state.xl = self._load_rest_position(self._state.xm)
        self._servo_on = False
        d = self._settings.direction_sign
        self._state.cprev = d * self._state.xm
        self._generator = MotionGenerator(d * self._state.xm)
        self._pulse_offset_rad = 0.0
        # the controller's command (command frame): the generator's while the servo is on, plus
        # what the error counter's re-basings took away from the generator (see controller_pos_rad)
        self._controller_rad = d * self._state.xm
        self._controller_offset_rad = 0.0
        self._trace: tuple[list, ...] | None = None
        self._trace_every = 1
        self._trace_max = 0

    # ----- configuration ------------------------------------------------------------------
    @property
    def model(self) -> AxisModel:
        return self._model

    @property
    def settings(self) -> ServoSettings:
        return self._settings

    def set_settings(self, settings: ServoSettings) -> None:
        """Change gains/limits/direction live (state kept; a direction change re-bases the command)."""
        old_d = self._settings.direction_sign
        self._settings = settings
        self._params = kernel_params(self._model, settings)
        if settings.direction_sign != old_d:
            self._rebase_command()

    def set_model(self, model: AxisModel) -> None:
        """Swap the plant parameters (e.g. another load or effect set), keeping the state."""
        self._model = model
        self._params = kernel_params(model, self._settings)

    @property
    def substeps(self) -> int:
        """Plant integration substeps per servo period (from the stiffest gear region)."""
        return self._params.nsub

    # ----- time -----------------------------------------------------------------------------
    @property
    def servo_period_s(self) -> float:
        return self._params.dt

    @property
    def time_s(self) -> float:
        """Simulated time since construction."""
        return self._state.step_index * self._params.dt

    def step(self, n: int = 1, speed_injection: list[float] | None = None) -> None:
        """Advance n servo periods. ``speed_injection``: n speeds (rad/s, command frame) added to
        the speed command, one per period (an excitation for a frequency response), or None."""
        if n <= 0:
            return
        if speed_injection is not None and len(speed_injection) != n:
            raise ValueError(f"speed_injection: {len(speed_injection)} values for {n} periods")
        p = self._params
        k0 = self._state.step_index + 1
        if self._servo_on:
            off = self._pulse_offset_rad
            if n <= SMALL_STEP_COUNT:  # numpy's call overhead dominates for a few periods
                state_at = self._generator.state_at
                cmd = [state_at((k0 + j) * p.dt)[0] + off for j in range(n)]
            else:
                cmd = (self._generator.positions(np.arange(k0, k0 + n) * p.dt) + off).tolist()
        else:
            cmd = None
        rec = self._trace
        recorded = len(rec[0]) if rec is not None else 0
        kernel_rec = rec[:_KERNEL_CHANNELS] if rec is not None else None
        _kernel.run(p, self._state, cmd, n, self._servo_on, kernel_rec, self._trace_every,
                    speed_injection if self._servo_on else None)
        if cmd is not None:
            self._controller_rad = cmd[-1] + self._controller_offset_rad
        if rec is not None:
            self._record_controller(rec, recorded, cmd, k0)
            overflow = len(rec[0]) - self._trace_max
            if overflow > 0:
                for ch in rec:
                    del ch[:overflow]
        if not self._servo_on:
            self._generator.hold(self.time_s, self._state.cprev)
            self._pulse_offset_rad = 0.0

    def _record_controller(self, rec: tuple[list, ...], recorded: int, cmd: list[float] | None,
                           k0: int) -> None:
        """The controller's command at the periods the kernel just recorded (its times say which)."""
        new = rec[0][recorded:]
        if cmd is None:  # the servo is off: the controller sends nothing
            rec[-1].extend([self._controller_rad] * len(new))
            return
        off = self._controller_offset_rad
        if len(new) == len(cmd):  # every period recorded
            rec[-1].extend([c + off for c in cmd])
        else:
            dt = self._params.dt
            rec[-1].extend([cmd[round(t / dt) - k0] + off for t in new])

    def advance(self, seconds: float) -> None:
        """Advance by a duration (rounded to whole servo periods)."""
        self.step(round(seconds / self._params.dt))

    # ----- servo on/off, brake -------------------------------------------------------------
    @property
    def servo_is_on(self) -> bool:
        return self._servo_on

    def servo_on(self) -> None:
        """Energise: the command starts at the present position (error counter cleared)."""
        if not self._servo_on:
            self._rebase_command()
            self._state.integ = 0.0
            self._servo_on = True

    def servo_off(self) -> None:
        """De-energise: no current, the axis coasts (friction, brake and load act)."""
        self._servo_on = False
        self._state.current = 0.0

    def turn_by_hand(self, angle_rad: float) -> None:
        """Someone turns the de-energised axis by ``angle_rad`` (physical frame, CW +) and lets go:
        motor and load side move together and come to rest there. Refused with the servo on."""
        if self._servo_on:
            raise RuntimeError("cannot turn the axis by hand: the servo is on")
        s = self._state
        s.xm += float(angle_rad)
        s.xl = self._load_rest_position(s.xm)
        s.vm = s.vl = 0.0
        s.fb_prev = None
        self._rebase_command()

    def set_brake(self, engaged: bool, holding_torque_nm: float = 0.0) -> None:
        """Motor brake (non-excitation type: the sim engages it when the coil is unpowered).

        While engaged, it holds the motor side up to holding_torque_nm (output-referred).
        """
        self._state.brake_torque = float(holding_torque_nm) if engaged else 0.0

    @property
    def brake_engaged(self) -> bool:
        return self._state.brake_torque > 0.0

    # ----- commands (command frame) ----------------------------------------------------------
    def _default_speed(self, speed: float | None) -> float:
        if speed is not None:
            return abs(float(speed))
        vmax = self._model.max_speed_rad_s
        if vmax is None:
            raise ValueError("motion: give a speed (the model has no maximum speed)")
        return vmax

    def _default_accel(self, accel: float | None) -> float:
        return self._model.max_acceleration_rad_s2() if accel is None else float(accel)

    def jog(self, speed_rad_s: float, accel_rad_s2: float | None = None) -> None:
        """Ramp to speed_rad_s (signed, + = FWD) at accel (default: the torque-limited accel)."""
        self._require_servo("jog")
        self._generator.jog(self.time_s, float(speed_rad_s), self._default_accel(accel_rad_s2))

    def stop(self, decel_rad_s2: float | None = None) -> None:
        """Ramp the command to standstill (default: the torque-limited accel), then hold."""
        self._generator.stop(self.time_s, self._default_accel(decel_rad_s2))

    def move_by(self, angle_rad: float, speed_rad_s: float | None = None,
                accel_rad_s2: float | None = None) -> None:
        """Trapezoidal move by angle_rad (+ = FWD) at speed (default max speed) and accel (default
        the torque-limited accel). The command must be at standstill."""
        self._require_servo("move")
        self._generator.move_by(self.time_s, float(angle_rad), self._default_speed(speed_rad_s),
                                self._default_accel(accel_rad_s2))

    def move_by_pulses(self, command_pulses: int, speed_rad_s: float | None = None,
                       accel_rad_s2: float | None = None) -> None:
        """move_by in command input pulses (through the electronic gear)."""
        self.move_by(self.command_pulses_to_rad(command_pulses), speed_rad_s, accel_rad_s2)

    def add_command_pulses(self, command_pulses: int) -> None:
        """Pulse-train input: add command_pulses (through the electronic gear) to the command now."""
        if self._servo_on:
            self._pulse_offset_rad += self.command_pulses_to_rad(command_pulses)

    def command_pulses_to_rad(self, command_pulses: float) -> float:
        """Command input pulses -> output angle (rad) through the electronic gear."""
        s = self._settings
        return command_pulses * s.electronic_gear_numerator / s.electronic_gear_denominator * \
            self._model.output_pulse_rad

    @property
    def motion_done(self) -> bool:
        """True when the command profile has reached its final standstill (not jogging)."""
        return not math.isnan(self._generator.target_rad) and self.time_s >= self._generator.end_time_s()

    def _require_servo(self, what: str) -> None:
        if not self._servo_on:
            raise RuntimeError(f"cannot {what}: the servo is off")

    def _rebase_command(self) -> None:
        d = self._settings.direction_sign
        x = self._state.xm
        if self._settings.quantised_feedback:  # the drive only knows whole pulses
            x = self._to_pulses(x) * self._model.output_pulse_rad
        self._generator.hold(self.time_s, d * x)
        self._pulse_offset_rad = 0.0
        self._controller_offset_rad = self._controller_rad - d * x  # the controller's count goes on
        self._state.cprev = d * x

    def _load_rest_position(self, xm: float) -> float:
        p = self._params
        return xm + (p.ke_a * math.sin(p.ke_w * xm + p.ke_phase) if p.ke_a else 0.0)

    # ----- state (physical frame unless said) -------------------------------------------------
    @property
    def output_pos_rad(self) -> float:
        """Motor-side angle at the output (motor angle / ratio), what the motor encoder reports."""
        return self._state.xm

    @property
    def motor_pos_rad(self) -> float:
        """Motor shaft angle (output_pos_rad x ratio); nan without a ratio."""
        return self._state.xm * (self._model.ratio or math.nan)

    @property
    def load_pos_rad(self) -> float:
        """Angle of the output flange / load (after wind-up, kinematic error, lost motion)."""
        return self._state.xl

    @property
    def twist_rad(self) -> float:
        """Motor side minus load side."""
        return self._state.xm - self._state.xl

    @property
    def output_speed_rad_s(self) -> float:
        return self._state.vm

    @property
    def output_speed_rpm(self) -> float:
        return self._state.vm / RAD_S_PER_RPM

    @property
    def motor_speed_rpm(self) -> float:
        return self.output_speed_rpm * (self._model.ratio or math.nan)

    @property
    def load_speed_rad_s(self) -> float:
        return self._state.vl

    @property
    def current_a(self) -> float:
        """Motor current (A); Kt x current_a = output torque, + = CW."""
        return self._state.current

    @property
    def torque_nm(self) -> float:
        """Motor torque at the output, Kt x current (N m, + = CW)."""
        return self._model.torque_constant_nm_per_a * self._state.current

    @property
    def flange_torque_nm(self) -> float:
        """What a torque sensor between the output flange and the load reads (N m): the torque the
        flange exerts on the load, + = driving it CW. The load (its inertia beyond the sensor, the
        actuator's flange not included) x its acceleration + its own torques (gravity, load offset):
        with a compliant gear the gear's twist torque less what accelerates the flange, on a rigid
        axis from the last servo period's acceleration. Kt x current minus it is what the actuator
        takes (friction, its own inertia). 0 until the axis has been stepped."""
        return self._state.flange_torque

    @property
    def command_pos_rad(self) -> float:
        """The position command in the physical frame (rad)."""
        return self._settings.direction_sign * self._state.cprev

    @property
    def controller_pos_rad(self) -> float:
        """What the controller has commanded so far (command frame, rad, after the electronic gear):
        the command while the servo is on; it holds while the servo is off (the error counter then
        follows the feedback, the controller sends nothing) and does not jump when the error counter
        is cleared or the command re-based (the drive's command does)."""
        return self._controller_rad

    @property
    def speed_command_rad_s(self) -> float:
        """Speed-loop reference (command frame, rad/s)."""
        return self._state.vref

    def _speed_mode(self) -> bool:
        return self._settings.control_mode == "speed"

    def _to_pulses(self, rad: float) -> int:
        return math.floor(rad / self._model.output_pulse_rad + 0.5)

    @property
    def command_pulses(self) -> int:
        """Command position in output encoder pulses (command frame, after the electronic gear);
        in speed mode it follows the feedback."""
        if self._speed_mode():
            return self.feedback_pulses
        return self._to_pulses(self._state.cprev)

    @property
    def feedback_pulses(self) -> int:
        """Encoder position in output pulses (command frame)."""
        return self._to_pulses(self._settings.direction_sign * self._state.xm)

    @property
    def error_pulses(self) -> int:
        """Position error, command - feedback, in output pulses (the error counter)."""
        return self.command_pulses - self.feedback_pulses

    @property
    def in_position(self) -> bool:
        """IN-POS: servo on and |error| within the in-position range."""
        return self._servo_on and abs(self.error_pulses) <= self._settings.in_position_range_pulses

    # ----- accumulators for the drive's alarms ---------------------------------------------
    @property
    def current_integral_a_s(self) -> float:
        """Cumulative integral of current dt (A s, + = CW); difference it for a mean current (the
        instantaneous current carries the quantised feedback's noise)."""
        return self._state.i_integral

    @property
    def current_squared_integral_a2s(self) -> float:
        """Cumulative integral of current^2 dt (A^2 s); difference it for an I^2 t model."""
        return self._state.i2_integral

    @property
    def motor_work_j(self) -> float:
        """Cumulative mechanical work of the motor on the axis, integral of Kt i w dt (J)."""
        return self._state.work_j

    @property
    def regenerated_energy_j(self) -> float:
        """Cumulative energy returned to the DC bus (J): motor generating beyond its copper loss
        (1.5 x phase resistance x i^2, an assumption on the current convention)."""
        return self._state.regen_j

    @property
    def peak_speed_rad_s(self) -> float:
        """Largest |motor-side output speed| since reset_peaks() (rad/s)."""
        return self._state.peak_speed

    @property
    def peak_error_pulses(self) -> float:
        """Largest |position error| since reset_peaks(), in output pulses (0 in speed mode)."""
        if self._speed_mode():
            return 0.0
        return self._state.peak_error / self._model.output_pulse_rad

    def snapshot(self) -> dict[str, float | int | bool]:
        """The present values a drive's monitors and alarms read, in one dict (units in the keys)."""
        return {
            "time_s": self.time_s,
            "servo_on": self._servo_on,
            "output_pos_rad": self.output_pos_rad,
            "load_pos_rad": self.load_pos_rad,
            "output_speed_rad_s": self.output_speed_rad_s,
            "output_speed_rpm": self.output_speed_rpm,
            "motor_speed_rpm": self.motor_speed_rpm,
            "current_a": self.current_a,
            "torque_nm": self.torque_nm,
            "flange_torque_nm": self.flange_torque_nm,
            "command_pos_rad": self.command_pos_rad,
            "command_pulses": self.command_pulses,
            "feedback_pulses": self.feedback_pulses,
            "error_pulses": self.error_pulses,
            "in_position": self.in_position,
            "current_squared_integral_a2s": self.current_squared_integral_a2s,
            "regenerated_energy_j": self.regenerated_energy_j,
            "motor_work_j": self.motor_work_j,
        }

    def reset_peaks(self) -> None:
        self._state.peak_speed = 0.0
        self._state.peak_error = 0.0

    def clear_error(self) -> None:
        """Clear the error counter (CLEAR input): the command jumps to the present position."""
        self._rebase_command()
        self._state.integ = 0.0

    # ----- trace ------------------------------------------------------------------------------
    def start_trace(self, every_n_periods: int = 1, max_samples: int = 1_000_000) -> None:
        """Record TRACE_CHANNELS every n servo periods (oldest samples dropped past max_samples)."""
        if every_n_periods < 1 or max_samples < 1:
            raise ValueError("trace: every_n_periods and max_samples must be at least 1")
        self._trace = tuple([] for _ in TRACE_CHANNELS)
        self._state.rec_count = 0
        self._trace_every = int(every_n_periods)
        self._trace_max = int(max_samples)

    def read_trace(self, clear: bool = True) -> dict[str, np.ndarray]:
        """The recorded samples (t s, cmd_pos rad, pos rad, load_pos rad, vel rad/s, current A,
        speed_cmd rad/s command frame, flange_torque N m (see :attr:`flange_torque_nm`),
        controller_pos rad command frame); clear=True empties the buffer, recording continues."""
        if self._trace is None:
            return {name: np.empty(0) for name in TRACE_CHANNELS}
        out = {name: np.array(ch) for name, ch in zip(TRACE_CHANNELS, self._trace, strict=True)}
        if clear:
            for ch in self._trace:
                ch.clear()
        return out

    def stop_trace(self) -> None:
        self._trace = None
