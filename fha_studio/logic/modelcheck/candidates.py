"""The candidate effects: how each one shows in a residual channel (its regressor columns).

Ids and parameter names are those of fha_studio.physics.Effects, so that a found effect can be
switched on in the updated model and in the simulated drive by the same name.
Torque channel (N m): what the motor supplied (Kt x current) minus what the nominal model needs
((J_actuator + J_load_declared) x acceleration). Position channel (arcsec): load_pos - pos.

Every regressor is computed on the whole uniformly sampled record and smoothed with the analysis
filter (see signals.py), so measured and modelled sides carry the same bandwidth.
Each candidate turns its fitted linear coefficients (and shape parameters) into contract
parameters with one-sigma uncertainties (delta method) and gives its *size*: the effect's typical
magnitude in the channel's unit, which the practical-significance floor is compared with.

Everything effect-specific lives here, as attributes of the `Candidate`: how it shows (columns),
its parameters, its size, whether it acts on the motor side of the gear (for the position
channel's gear torque), whether it re-fits a nominal parameter first, how its detection limit
reads in its own parameter, how it enters the updated model, which look-alikes it has and the
one-line advice for a person. The workflow never branches on an effect id; a new effect is one
entry in TORQUE_CANDIDATES or POSITION_CANDIDATES (see docs/physics.md, "Adding an effect").
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fha_studio.logic.modelcheck.shapes import cycles_within, stribeck_within
from fha_studio.logic.modelcheck.signals import ARCSEC_PER_RAD, Signals
from fha_studio.logic.wording import with_unit
from fha_studio.physics.servo import MIN_SERVO_RATE_HZ

TORQUE = "torque"
POSITION = "position"
# A drive reads its speed as the encoder pulses counted per servo period. While the motor turns a
# few pulses per period or fewer (the creep into a target), that count is coarse (0s and 1s at the
# slowest) and the speed loop answers it with a current pattern of its own: on the simulated drive
# with friction a bump of some 5 % of the friction torque over the creep, gone with ideal feedback.
# Over the fraction of a motor turn a creep covers, a sinusoid of any order fits it, so a torque
# ripple must also stand where the motor turns faster (or stands still). The servo rate is not in
# the HA-655's manual: the slowest loop the physics models gives the lowest, most permissive speed.
QUANTISED_PULSES_PER_PERIOD = 4.0
# the torque channel split by an output torque sensor: the gear's part and the load's (workflow.py)
CHANNEL_UNITS = {TORQUE: "N m", POSITION: "arcsec", "gear torque": "N m", "load torque": "N m"}


@dataclass
class ChannelContext:
    """What candidates need to build their columns for one channel."""

    sig: Signals
    channel: str
    # torque carried by the gear (N m, smoothed), for the position channel
    gear_torque_nm: np.ndarray | None = None
    # torque breakpoints of the wind-up curve (catalogue T1, T2) the data reaches beyond
    breakpoints_nm: tuple[float, ...] = ()
    nominal_inertia_kgm2: float = 0.0  # J_actuator + J_load declared (the nominal model's inertia)
    cache: dict[tuple[object, ...], np.ndarray] = field(default_factory=dict)
    # > 1: a candidate that `decimates` builds only every rows_step-th sample of the valid part
    rows_step: int = 1
    # the declared encoder's pulse (rad at the output; 0: not known): the drive's loops see whole pulses
    pulse_rad: float = 0.0

    def smooth(self, full_rate_column: np.ndarray) -> np.ndarray:
        """A column computed on the whole record, smoothed onto the valid part (every rows_step-th
        sample of it)."""
        return self.sig.filt.apply_every(full_rate_column, self.rows_step)

    @property
    def quantised_below_rad_s(self) -> float:
        """The output speed below which the drive's speed feedback is ruled by the encoder's
        quantum (QUANTISED_PULSES_PER_PERIOD pulses per servo period; 0 when the pulse is unknown)."""
        return QUANTISED_PULSES_PER_PERIOD * self.pulse_rad * MIN_SERVO_RATE_HZ

    def full_sign_speed(self, memory: bool = False) -> np.ndarray:
        """Direction of motion on the whole record: 0 while standing, or (memory) the last direction."""
        key = ("dir", memory)
        if key not in self.cache:
            v = self.sig.full_speed_rad_s
            threshold = 3.0 * max(self.sig.pos_noise_rad, 1e-9) / (self.sig.filt.window * self.sig.filt.dt_s)
            d = np.where(v > threshold, 1.0, np.where(v < -threshold, -1.0, np.nan if memory else 0.0))
            self.cache[key] = _hold_last(d) if memory else d
        return self.cache[key]


def _hold_last(d: np.ndarray) -> np.ndarray:
    """Fill NaN with the last valid value (0 before the first)."""
    valid = ~np.isnan(d)
    idx = np.where(valid, np.arange(len(d)), 0)
    np.maximum.accumulate(idx, out=idx)
    out = d[idx]
    out[np.isnan(out)] = 0.0
    if valid.any():
        out[: int(np.argmax(valid))] = 0.0
    return out


@dataclass(frozen=True)
class Param:
    """One fitted contract parameter."""

    name: str
    value: float
    std: float
    unit: str


def _clamp_nonnegative(params: dict[str, float], model: Any) -> dict[str, float] | None:
    """Updated-model parameters of a friction-like effect: a fitted negative level becomes zero."""
    return {k: max(v, 0.0) if k != "velocity_rad_s" else abs(v) for k, v in params.items()}


def _as_is(params: dict[str, float], model: Any) -> dict[str, float] | None:
    return dict(params)


def _limit_as_size(size: float, ctx: ChannelContext) -> float:
    return size


@dataclass(frozen=True)
class Candidate:
    """A candidate effect and how to see it (every effect-specific behaviour is an attribute)."""

    id: str
    channel: str
    label: str  # human name
    n_linear: int
    build: Callable[[ChannelContext, tuple[float, ...]], np.ndarray]  # smoothed columns (n, n_linear)
    to_params: Callable[[np.ndarray, np.ndarray, tuple[float, ...], np.ndarray, ChannelContext], list[Param]]
    size: Callable[[np.ndarray, ChannelContext], float]
    shape_grid: Sequence[tuple[float, ...]] = ((),)
    shape_refine: bool = False  # refine the (continuous) shape by least squares
    shape_names: tuple[str, ...] = ()
    # bounds of the refinement around a grid shape (default: +-0.25 cycles per motor turn)
    shape_bounds: Callable[[tuple[float, ...]], tuple[list[float], list[float]]] = lambda s: (
        [s[0] - 0.25],
        [s[0] + 0.25],
    )
    look_elsewhere: bool = False  # a searched frequency: the size must stand above off-frequency noise
    sign: int = 0  # +1/-1: the first coefficient must have this sign to be physical (0 = any)
    all_positive: bool = False  # every coefficient must be >= 0 (levels by direction)
    primary: str = ""  # parameter the detection limit is stated in
    primary_unit: str = ""  # its unit (default: the channel's)
    needs_ratio: bool = False
    motor_side: bool = False  # acts on the motor side of the gear (not carried by the gear)
    nominal: bool = False  # re-fits a nominal parameter: tried before any missing effect
    # a detection limit (channel unit) in the primary parameter's unit
    limit_in_param: Callable[[float, ChannelContext], float] = _limit_as_size
    # the fitted parameters as the updated model takes them (None: leave the effect out)
    model_params: Callable[[dict[str, float], Any], dict[str, float] | None] = _as_is
    # sets of candidates that together look like this one (tested as a whole against it)
    look_alikes: tuple[tuple[str, ...], ...] = ()
    extends: tuple[str, ...] = ()  # candidates this one contains (nested: the BIC decides between them)
    # the same columns as another candidate read another way: never chosen, named only as its look-alike
    only_as_alternative: bool = False
    # one line for a person: what to do next, from the fitted parameters
    advice: Callable[[dict[str, float]], str] = lambda p: "add it to the model (Save updated model…)"
    # why a fitted shape lies outside what the recording spans ("" when it does not): checked in
    # every re-fit, since the joint refinement of all parameters is not bounded
    shape_check: Callable[[tuple[float, ...], ChannelContext], str] | None = None
    # the columns without the creep into a target (where the encoder's quantum rules the speed
    # feedback): when given, the effect must also stand on them, or the creep alone shows it
    beyond_creep: Callable[[ChannelContext, tuple[float, ...]], np.ndarray] | None = None
    # build honours ChannelContext.rows_step (smooths with ctx.smooth only): a searched shape's
    # columns are rebuilt at every trial, and the selection then computes only the rows it fits
    decimates: bool = False


def _amp_phase(beta: np.ndarray, cov: np.ndarray) -> tuple[float, float, float, float]:
    """A sin(x + phi) = a sin x + b cos x: amplitude, phase (deg) and their sigmas from (a, b)."""
    a, b = float(beta[0]), float(beta[1])
    amp = math.hypot(a, b)
    phase = math.degrees(math.atan2(b, a))
    if amp == 0:
        return 0.0, 0.0, math.sqrt(max(cov[0, 0], 0.0)), 180.0
    g_amp = np.array([a / amp, b / amp])
    g_ph = np.degrees(np.array([-b / amp**2, a / amp**2]))
    s_amp = math.sqrt(max(float(g_amp @ cov[:2, :2] @ g_amp), 0.0))
    s_ph = math.sqrt(max(float(g_ph @ cov[:2, :2] @ g_ph), 0.0))
    return amp, phase, s_amp, s_ph


def _sd(cov: np.ndarray, i: int) -> float:
    return math.sqrt(max(float(cov[i, i]), 0.0))


def _rms(x: np.ndarray | None) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if x is not None and len(x) else 0.0


# ------------------------------------------------------------------------------------ torque channel


def _coulomb_cols(ctx, shape):
    # a stuck axis keeps the friction it last slid against (the servo's integrator holds it)
    return ctx.sig.regressor(ctx.full_sign_speed(memory=True))[:, None]


def _viscous_cols(ctx, shape):
    return ctx.sig.speed_f_rad_s[:, None]


def _gravity_cols(ctx, shape):
    p = ctx.sig.raw_pos_rad
    return np.column_stack([ctx.sig.regressor(np.sin(p)), ctx.sig.regressor(np.cos(p))])


def _offset_cols(ctx, shape):
    return np.ones((len(ctx.sig.t_s), 1))


def _inertia_cols(ctx, shape):
    return ctx.sig.accel_rad_s2[:, None]


def _periodic_motor_cols(ctx, shape):
    (cycles,) = shape
    angle = cycles * ctx.sig.ratio * ctx.sig.raw_pos_rad
    return np.column_stack([ctx.smooth(np.sin(angle)), ctx.smooth(np.cos(angle))])


def _periodic_beyond_creep_cols(ctx, shape):
    # the same sinusoid, zero while the motor creeps (moving below ctx.quantised_below_rad_s)
    (cycles,) = shape
    angle = cycles * ctx.sig.ratio * ctx.sig.raw_pos_rad
    creeping = (ctx.full_sign_speed() != 0.0) & (np.abs(ctx.sig.full_speed_rad_s) < ctx.quantised_below_rad_s)
    read = (~creeping).astype(float)
    return np.column_stack([ctx.smooth(np.sin(angle) * read), ctx.smooth(np.cos(angle) * read)])


def _one(name: str, unit: str, scale: float = 1.0):
    def convert(beta, cov, shape, shape_cov, ctx):
        return [Param(name, float(beta[0]) * scale, _sd(cov, 0) * abs(scale), unit)]

    return convert


def _gravity_params(beta, cov, shape, shape_cov, ctx):
    amp, ph, s_amp, s_ph = _amp_phase(beta, cov)
    return [Param("amplitude_nm", amp, s_amp, "N m"), Param("phase_deg", ph, s_ph, "deg")]


def _periodic_params(amp_name: str, unit: str):
    def convert(beta, cov, shape, shape_cov, ctx):
        amp, ph, s_amp, s_ph = _amp_phase(beta, cov)
        s_c = math.sqrt(max(float(shape_cov[0, 0]), 0.0)) if shape_cov.size else 0.0
        return [
            Param(amp_name, amp, s_amp, unit),
            Param("cycles_per_motor_rev", float(shape[0]), s_c, "1/rev"),
            Param("phase_deg", ph, s_ph, "deg"),
        ]

    return convert


def _amp_size(beta, ctx):
    return math.hypot(float(beta[0]), float(beta[1]))


RIPPLE_CYCLES = (1.0, 2.0, 3.0, 4.0, 6.0, 8.0)
KINEMATIC_CYCLES = (2.0, 1.0, 4.0)
STRIBECK_SPEEDS_RAD_S = (0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5)


def _asymmetric_cols(ctx, shape):
    # friction levels by direction; a stuck axis keeps the level it last slid against
    d = ctx.full_sign_speed(memory=True)
    return np.column_stack(
        [ctx.sig.regressor((d > 0).astype(float)), -ctx.sig.regressor((d < 0).astype(float))]
    )


def _asymmetric_params(beta, cov, shape, shape_cov, ctx):
    return [
        Param("torque_pos_nm", float(beta[0]), _sd(cov, 0), "N m"),
        Param("torque_neg_nm", float(beta[1]), _sd(cov, 1), "N m"),
    ]


def _stribeck_cols(ctx, shape):
    # extra friction while sliding slowly, fading with speed; a stuck axis keeps the friction it
    # last slid against, the breakaway level (the servo's integrator holds it, see Coulomb friction)
    (v_s,) = shape
    v = ctx.sig.full_speed_rad_s
    return ctx.smooth(ctx.full_sign_speed(memory=True) * np.exp(-((v / v_s) ** 2)))[:, None]


def _stribeck_params(beta, cov, shape, shape_cov, ctx):
    s_v = math.sqrt(max(float(shape_cov[0, 0]), 0.0)) if shape_cov.size else 0.0
    return [
        Param("static_torque_nm", float(beta[0]), _sd(cov, 0), "N m"),
        Param("velocity_rad_s", abs(float(shape[0])), s_v, "rad/s"),
    ]


def _torque_constant_cols(ctx, shape):
    # ratio x Kt x current = J a + F: read with the catalogue Kt, the residual is (1/ratio - 1) x the
    # torque the nominal model needs (plus the other effects scaled by 1/ratio). With the torque
    # channel alone that is exactly an inertia error: only a known torque tells them apart.
    return (ctx.nominal_inertia_kgm2 * ctx.sig.accel_rad_s2)[:, None]


def _torque_constant_params(beta, cov, shape, shape_cov, ctx):
    b = float(beta[0])
    ratio = 1.0 / (1.0 + b) if b > -1.0 else math.inf
    return [Param("ratio", ratio, _sd(cov, 0) * ratio**2 if math.isfinite(ratio) else math.inf, "1")]


def _per_rms(signal: Callable[[ChannelContext], np.ndarray]) -> Callable[[float, ChannelContext], float]:
    """A detection limit (N m) in a coefficient per unit of a signal's RMS (N m s/rad, kg m^2)."""
    return lambda size, ctx: size / max(_rms(signal(ctx)), 1e-12)


def _inertia_model_params(params: dict[str, float], model: Any) -> dict[str, float] | None:
    # an inertia error that leaves no positive load-side inertia cannot enter the model
    return None if model.load_side_inertia_kgm2 + params["inertia_kgm2"] <= 0 else dict(params)


def _ratio_model_params(params: dict[str, float], model: Any) -> dict[str, float] | None:
    return dict(params) if 0.1 <= params["ratio"] <= 10.0 else None


def _nm(x: float) -> str:
    return f"{x:.3g} N·m"


TORQUE_CANDIDATES: tuple[Candidate, ...] = (
    Candidate(
        "inertia_error",
        TORQUE,
        "Inertia error",
        1,
        _inertia_cols,
        _one("inertia_kgm2", "kg m^2"),
        lambda b, c: abs(float(b[0])) * _rms(c.sig.accel_rad_s2),
        primary="inertia_kgm2",
        primary_unit="kg m^2",
        nominal=True,
        limit_in_param=_per_rms(lambda c: c.sig.accel_rad_s2),
        model_params=_inertia_model_params,
        advice=lambda p: (
            f"{'add' if p['inertia_kgm2'] > 0 else 'take off'} {abs(p['inertia_kgm2']):.3g} kg·m² "
            f"{'to' if p['inertia_kgm2'] > 0 else 'from'} the declared load inertia; check what is mounted "
            "on the output (a part missed in the sizing)"
        ),
    ),
    Candidate(
        "coulomb_friction",
        TORQUE,
        "Coulomb friction",
        1,
        _coulomb_cols,
        _one("torque_nm", "N m"),
        lambda b, c: abs(float(b[0])),
        sign=1,
        primary="torque_nm",
        motor_side=True,
        model_params=_clamp_nonnegative,
        advice=lambda p: (
            f"add {_nm(p['torque_nm'])} Coulomb friction to the model; if the axis is new, check the brake "
            "releases fully and the seals or the load's bearings do not drag"
        ),
    ),
    Candidate(
        "viscous_friction",
        TORQUE,
        "Viscous friction",
        1,
        _viscous_cols,
        _one("coefficient_nm_s_per_rad", "N m s/rad"),
        lambda b, c: abs(float(b[0])) * _rms(c.sig.speed_rad_s),
        sign=1,
        primary="coefficient_nm_s_per_rad",
        primary_unit="N m s/rad",
        motor_side=True,
        limit_in_param=_per_rms(lambda c: c.sig.speed_rad_s),
        model_params=_clamp_nonnegative,
        advice=lambda p: (
            f"add {p['coefficient_nm_s_per_rad']:.3g} N·m·s/rad viscous friction to the model; a cold gear "
            "is stiffer: compare after a warm-up run"
        ),
    ),
    Candidate(
        "gravity_load",
        TORQUE,
        "Gravity load (unbalance)",
        2,
        _gravity_cols,
        _gravity_params,
        _amp_size,
        primary="amplitude_nm",
        advice=lambda p: (
            f"add a {_nm(p['amplitude_nm'])} unbalance to the model; balance the load or size the "
            "actuator for the holding torque, and mind it when the servo is off (the brake holds it)"
        ),
    ),
    Candidate(
        "load_torque_offset",
        TORQUE,
        "Load torque offset",
        1,
        _offset_cols,
        _one("torque_nm", "N m"),
        lambda b, c: abs(float(b[0])),
        primary="torque_nm",
        advice=lambda p: (
            f"add a constant {_nm(p['torque_nm'])} load torque to the model; look for a spring, a cable "
            "chain or a process force pushing the load"
        ),
    ),
    Candidate(
        "torque_ripple",
        TORQUE,
        "Torque ripple",
        2,
        _periodic_motor_cols,
        _periodic_params("amplitude_nm", "N m"),
        _amp_size,
        shape_grid=tuple((c,) for c in RIPPLE_CYCLES),
        shape_refine=True,
        decimates=True,
        shape_names=("cycles_per_motor_rev",),
        look_elsewhere=True,
        shape_check=cycles_within(RIPPLE_CYCLES),
        primary="amplitude_nm",
        needs_ratio=True,
        motor_side=True,
        beyond_creep=_periodic_beyond_creep_cols,
        advice=lambda p: (
            f"add {_nm(p['amplitude_nm'])} ripple at {p['cycles_per_motor_rev']:.3g} cycles per motor turn "
            "to the model; if it is large, have the motor and its encoder alignment checked"
        ),
    ),
    Candidate(
        "asymmetric_friction",
        TORQUE,
        "Friction that differs by direction",
        2,
        _asymmetric_cols,
        _asymmetric_params,
        lambda b, c: 0.5 * abs(float(b[0]) - float(b[1])),  # the asymmetry: what Coulomb friction lacks
        all_positive=True,
        primary="torque_pos_nm",
        motor_side=True,
        model_params=_clamp_nonnegative,
        look_alikes=(("coulomb_friction", "load_torque_offset"),),
        extends=("coulomb_friction",),
        advice=lambda p: (
            f"add friction of {_nm(p['torque_pos_nm'])} turning CW and {_nm(p['torque_neg_nm'])} turning CCW "
            "to the model; a direction-dependent drag often comes from a seal or a preloaded bearing"
        ),
    ),
    Candidate(
        "stribeck_friction",
        TORQUE,
        "Breakaway friction at low speed (Stribeck)",
        1,
        _stribeck_cols,
        _stribeck_params,
        lambda b, c: abs(float(b[0])),
        shape_grid=tuple((v,) for v in STRIBECK_SPEEDS_RAD_S),
        shape_refine=True,
        decimates=True,
        shape_names=("velocity_rad_s",),
        shape_bounds=lambda s: ([0.5 * s[0]], [2.0 * s[0]]),
        shape_check=stribeck_within,
        sign=1,
        primary="static_torque_nm",
        motor_side=True,
        model_params=_clamp_nonnegative,
        advice=lambda p: (
            f"add {_nm(p['static_torque_nm'])} breakaway friction below about "
            f"{p['velocity_rad_s'] * 30.0 / math.pi:.2g} r/min to the model; avoid crawling at such speeds "
            "(stick-slip), or lubricate"
        ),
    ),
    Candidate(
        "torque_constant_error",
        TORQUE,
        "Torque constant (or current monitor) error",
        1,
        _torque_constant_cols,
        _torque_constant_params,
        lambda b, c: abs(float(b[0])) * _rms(c.nominal_inertia_kgm2 * c.sig.accel_rad_s2),
        primary="ratio",
        primary_unit="1",
        # a relative error of the torque per ampere the record would show (as a ratio's distance from 1)
        limit_in_param=lambda size, c: size / max(_rms(c.nominal_inertia_kgm2 * c.sig.accel_rad_s2), 1e-12),
        model_params=_ratio_model_params,
        only_as_alternative=True,
        advice=lambda p: (
            f"the motor gives {p['ratio']:.3g} x the catalogue torque per ampere: check the current "
            "monitor's scaling (monitor item and its full scale) and the actuator's model code"
        ),
    ),
)


# ---------------------------------------------------------------------------------- position channel


def _kinematic_cols(ctx, shape):
    return _periodic_motor_cols(ctx, shape)


def _compliance_cols(ctx, shape):
    # wind-up = tau/K1 below T1, then a change of slope at each breakpoint reached (manual 1-9-2)
    tau = ctx.gear_torque_nm
    cols = [tau]
    regions = int(shape[0]) if shape else 0
    for t_break in ctx.breakpoints_nm[:regions]:
        cols.append(np.sign(tau) * np.maximum(np.abs(tau) - t_break, 0.0))
    return np.column_stack(cols)


def _compliance_params(beta, cov, shape, shape_cov, ctx):
    # load_pos - pos = c tau (arcsec per N m) with c = -1/K in each region (slopes add up)
    out = []
    names = ("stiffness_nm_per_rad", "k2_nm_per_rad", "k3_nm_per_rad")
    for i in range(len(beta)):
        g = np.zeros(len(beta))
        g[: i + 1] = 1.0
        c = float(g @ beta)
        var = float(g @ cov @ g)
        k = -ARCSEC_PER_RAD / c if c != 0 else math.inf
        out.append(
            Param(names[i], k, abs(k) * math.sqrt(max(var, 0.0)) / abs(c) if c else math.inf, "N m/rad")
        )
    return out


def _lost_motion_cols(ctx, shape):
    # the load lags by half the dead band in the direction of motion (or of the gear torque)
    if shape and shape[0] > 0 and ctx.gear_torque_nm is not None:
        key = "torque_dir"
        if key not in ctx.cache:
            tau = ctx.gear_torque_nm
            thr = 0.05 * max(_rms(tau), 1e-9)
            ctx.cache[key] = _hold_last(np.where(tau > thr, 1.0, np.where(tau < -thr, -1.0, np.nan)))
        return -ctx.cache[key][:, None]
    return -ctx.sig.regressor(ctx.full_sign_speed(memory=True))[:, None]


def _lost_motion_params(beta, cov, shape, shape_cov, ctx):
    return [Param("width_arcsec", 2.0 * float(beta[0]), 2.0 * _sd(cov, 0), "arcsec")]


POSITION_CANDIDATES: tuple[Candidate, ...] = (
    Candidate(
        "kinematic_error",
        POSITION,
        "Kinematic error of the gear",
        2,
        _kinematic_cols,
        _periodic_params("amplitude_arcsec", "arcsec"),
        _amp_size,
        shape_grid=tuple((c,) for c in KINEMATIC_CYCLES),
        shape_refine=True,
        decimates=True,
        shape_names=("cycles_per_motor_rev",),
        look_elsewhere=True,
        shape_check=cycles_within(KINEMATIC_CYCLES),
        primary="amplitude_arcsec",
        needs_ratio=True,
        advice=lambda p: (
            f"add {p['amplitude_arcsec']:.3g} arc-sec kinematic error at "
            f"{p['cycles_per_motor_rev']:.3g} cycles per motor turn to the model; compare with the gear's "
            "accuracy in the catalogue (1-9-1)"
        ),
    ),
    Candidate(
        "torsional_compliance",
        POSITION,
        "Torsional compliance (wind-up)",
        1,
        _compliance_cols,
        _compliance_params,
        lambda b, c: abs(float(b[0])) * _rms(c.gear_torque_nm),
        sign=-1,
        shape_grid=((0.0,), (1.0,), (2.0,)),
        primary="stiffness_nm_per_rad",
        primary_unit="N m/rad",
        # wind-up smaller than the limit (arcsec) would not show: the stiffest spring still visible
        limit_in_param=lambda size, c: _rms(c.gear_torque_nm) * ARCSEC_PER_RAD / max(size, 1e-12),
        model_params=lambda p, m: (
            {k: v for k, v in p.items() if math.isfinite(v) and v > 0}
            if math.isfinite(p.get("stiffness_nm_per_rad", math.nan)) and p["stiffness_nm_per_rad"] > 0
            else None
        ),
        advice=lambda p: (
            f"add the gear's wind-up (K1 {p['stiffness_nm_per_rad']:.3g} N·m/rad) to the model; if it is "
            "softer than the catalogue's, check the load's mounting and its screws' torque"
        ),
    ),
    Candidate(
        "lost_motion",
        POSITION,
        "Lost motion (dead band)",
        1,
        _lost_motion_cols,
        _lost_motion_params,
        lambda b, c: abs(float(b[0])),
        sign=1,
        shape_grid=((0.0,), (1.0,)),
        primary="width_arcsec",
        limit_in_param=lambda size, c: 2.0 * size,
        model_params=_clamp_nonnegative,
        advice=lambda p: (
            f"add {p['width_arcsec']:.3g} arc-sec lost motion to the model; a harmonic gear has almost none: "
            "check the load's coupling and keys for play"
        ),
    ),
)

CANDIDATES: dict[str, Candidate] = {c.id: c for c in TORQUE_CANDIDATES + POSITION_CANDIDATES}

LABELS = {c.id: c.label for c in TORQUE_CANDIDATES + POSITION_CANDIDATES}


# Parameters in words, for a person (the ids and names above are the machine contract).
PARAM_WORDS = {
    "torque_nm": "torque",
    "coefficient_nm_s_per_rad": "coefficient",
    "amplitude_nm": "amplitude",
    "amplitude_arcsec": "amplitude",
    "phase_deg": "phase",
    "cycles_per_motor_rev": "cycles per motor turn",
    "inertia_kgm2": "inertia",
    "stiffness_nm_per_rad": "stiffness K1",
    "k2_nm_per_rad": "stiffness K2",
    "k3_nm_per_rad": "stiffness K3",
    "width_arcsec": "width",
    "torque_pos_nm": "turning CW",
    "torque_neg_nm": "turning CCW",
    "static_torque_nm": "breakaway above Coulomb",
    "velocity_rad_s": "fading by",
    "ratio": "torque per ampere / catalogue",
}
#: Units of a count or a ratio: the words before the number already say what it counts.
DIMENSIONLESS_UNITS = frozenset({"1/rev", "1"})


def param_words(name: str, value: float, unit: str, sigma: float | None = None) -> str:
    """'torque 11.9 ± 0.1 N·m': a fitted parameter as a person reads it (the unit in the manual's
    spelling, :mod:`fha_studio.logic.wording`)."""
    text = f"{PARAM_WORDS.get(name, name.replace('_', ' '))} {value:.3g}"
    if sigma is not None and math.isfinite(sigma) and sigma > 0:
        text += f" ± {sigma:.2g}"
    return text if unit in DIMENSIONLESS_UNITS else with_unit(text, unit)


def label_of(effect_ids: str) -> str:
    """The human name of an effect id, or of look-alike ids joined by " + "."""
    return " + ".join(LABELS.get(i, i) for i in effect_ids.split(" + "))


# Which recording would tell two look-alikes apart.
SEPARATING_TESTS: dict[frozenset[str], str] = {
    frozenset(
        {"gravity_load", "load_torque_offset"}
    ): "move over at least half an output turn: gravity changes with position, an offset does not",
    frozenset(
        {"gravity_load", "torque_ripple"}
    ): "record a full output turn at two loads (or with the load removed): gravity scales with the "
    "load's unbalance, ripple follows the motor turn",
    frozenset(
        {"coulomb_friction", "viscous_friction"}
    ): "record constant-speed runs at several speeds: Coulomb friction stays the same, "
    "viscous grows with speed",
    frozenset(
        {"coulomb_friction", "load_torque_offset"}
    ): "move in both directions: friction changes sign with the direction, an offset does not",
    frozenset(
        {"coulomb_friction", "inertia_error"}
    ): "record a move with a long constant-speed part: friction stays while accelerating stops",
    frozenset(
        {"viscous_friction", "inertia_error"}
    ): "record moves with different accelerations to the same speed: inertia follows acceleration, "
    "viscous friction follows speed",
    frozenset({"inertia_error", "load_torque_offset"}): "record moves accelerating in both directions",
    frozenset(
        {"inertia_error", "gravity_load"}
    ): "record moves with different accelerations over the same positions",
    frozenset(
        {"viscous_friction", "gravity_load"}
    ): "record the same positions at different speeds and in both directions",
    frozenset({"viscous_friction", "load_torque_offset"}): "record at several speeds in both directions",
    frozenset(
        {"torsional_compliance", "lost_motion"}
    ): "record slow reversals at low torque and a hold under steady torque: lost motion is a step at "
    "reversals, wind-up grows with the torque",
    frozenset(
        {"kinematic_error", "torsional_compliance"}
    ): "record the same positions at two loads: kinematic error follows the motor angle, wind-up the torque",
    frozenset(
        {"kinematic_error", "lost_motion"}
    ): "record slow moves over several motor turns in both directions",
    frozenset({"asymmetric_friction", "coulomb_friction + load_torque_offset"}): (
        "record a standstill with the servo on before the first move: a load offset needs current "
        "there, friction does not"
    ),
    frozenset({"coulomb_friction", "stribeck_friction"}): (
        "record constant-speed runs at several low speeds: breakaway (Stribeck) friction fades with "
        "speed, Coulomb friction does not"
    ),
    frozenset({"viscous_friction", "stribeck_friction"}): (
        "record constant-speed runs from very low to high speeds: Stribeck friction is largest at the "
        "lowest speeds, viscous friction at the highest"
    ),
    frozenset({"inertia_error", "torque_constant_error"}): (
        "apply a known load torque (a known mass on a known arm, or a torque wrench against the held "
        "axis) and compare it with Kt x current: a torque-constant error scales it, an inertia error "
        "does not"
    ),
}
DEFAULT_SEPARATING_TEST = (
    "record a longer motion covering more speeds, positions and accelerations, in both directions"
)


def separating_test(a: str, b: str) -> str:
    """The recording that would separate effect a from effect b."""
    return SEPARATING_TESTS.get(frozenset({a, b}), DEFAULT_SEPARATING_TEST)
