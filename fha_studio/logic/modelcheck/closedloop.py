"""The model check of a recording without current: the torque read through the closed loop.

A bench capture of an HA-655 gives the command, the encoder position (and SPD-MON, IN-POS) but no
current. The disturbance then shows in the following error and the speed response, through the
loop that fought it. The HA-655's position mode (docs/physics.md, "Servo") is

    speed command = Kp (cmd - pos) + FF cmd',  Kt i = Kt Kv (e + integral(e) / Tv),  e = speed command - speed

and the plant J a = Kt i - d (d: what the effects take). Integrated once, every term is a column
the recording holds (the following error and its integral, the command's speed and the command,
the speed and the position), so for one Tv the loop torque is linear in (g Kp, g FF, g) with
g = Kt Kv, plus one constant (the integrator's state at the start):

    -J a = -g Kp E1 - g FF E2 - g E3 - c + d,   E1 = eps + int(eps)/Tv, E2 = cmd' + cmd/Tv, E3 = -(v + pos/Tv)

These loop columns are the nuisance ("base") columns of the same selection the torque channel uses
(selection.py, consistency.py); Tv is found by a one-dimensional search. The tune items' units are
not documented on the HA-655, so the loop comes from the recording and is compared with the panel's
values when the caller knows them, not taken from them.

What cannot be identified this way, said in the report: a constant load torque and the part of
friction that differs by direction are held by the speed loop's integral (the constant column);
an inertia error trades off against the loop's gain scale g (the columns are -J a itself); viscous
friction trades off against the loop's speed gain and feed-forward (tried on the simulated drive: a
viscous drag of 5 N m s/rad came out as a 13 % larger Kv and no friction); every torque in N m
rests on the declared inertia; a torque-constant error has no current to act on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from fha_studio.logic.modelcheck.axis import DeclaredAxis, ModelCheckError, rms
from fha_studio.logic.modelcheck.candidates import TORQUE, TORQUE_CANDIDATES, ChannelContext
from fha_studio.logic.modelcheck.linalg import ols
from fha_studio.logic.modelcheck.signals import ARCSEC_PER_RAD, Signals, build_signals, window_for_bandwidth
from fha_studio.physics import ServoSettings
from fha_studio.recording import Recording

#: without a current the torque is only as good as the acceleration: a fixed analysis bandwidth,
#: well under the speed loop's and over what friction and gravity change at
ANALYSIS_BANDWIDTH_HZ = 25.0
#: Tv searched between these (s); beyond the top the loop has no integral action worth the name
TV_RANGE_S = (0.002, 2.0)
#: effects a recording without a torque measurement cannot show (see the module text)
NOT_IDENTIFIABLE = (
    "inertia_error",
    "load_torque_offset",
    "asymmetric_friction",
    "torque_constant_error",
    "viscous_friction",
)
CANDIDATES_WITHOUT_CURRENT = tuple(c for c in TORQUE_CANDIDATES if c.id not in NOT_IDENTIFIABLE)


@dataclass(frozen=True)
class Loop:
    """The closed loop identified from a recording (and, when known, the panel's values)."""

    position_gain_per_s: float  # Kp
    feed_forward: float  # FF
    integral_time_s: float  # Tv
    torque_per_speed_error_nm_s_per_rad: float  # g = Kt Kv, resting on the declared inertia
    speed_gain_a_s_per_rad: float  # Kv = g / Kt
    panel: ServoSettings | None = None

    def servo(self) -> ServoSettings:
        """The identified loop as servo settings, for the re-simulation."""
        return ServoSettings(
            position_loop_gain_per_s=max(self.position_gain_per_s, 1e-3),
            speed_loop_gain_a_s_per_rad=max(self.speed_gain_a_s_per_rad, 1e-9),
            speed_loop_integral_time_s=self.integral_time_s,
            feed_forward_gain=min(max(self.feed_forward, 0.0), 1.0),
            quantised_feedback=True,  # a drive's loops see whole encoder pulses
        )

    @property
    def plausible(self) -> bool:
        """A loop that can be: positive gains, an integral within the searched range, FF 0..1.5."""
        return (
            self.position_gain_per_s > 0
            and self.integral_time_s < TV_RANGE_S[1] * 0.99
            and -0.5 <= self.feed_forward <= 1.5
        )

    def lines(self) -> list[str]:
        if not self.plausible:
            return [
                "The closed loop is not pinned down by this recording (the fit gives Kp "
                f"{self.position_gain_per_s:.3g} 1/s, Tv {1000.0 * self.integral_time_s:.3g} ms, "
                f"feed-forward {self.feed_forward:.2f}, no loop a drive runs): record moves with clear "
                "accelerations that keep the current within its limit."
            ]
        text = (
            f"Closed loop identified from the recording: Kp {self.position_gain_per_s:.3g} 1/s, "
            f"Kv {self.speed_gain_a_s_per_rad:.3g} A s/rad "
            f"(Kt Kv {self.torque_per_speed_error_nm_s_per_rad:.3g} N m s/rad on the declared inertia), "
            f"Tv {1000.0 * self.integral_time_s:.3g} ms, "
            f"feed-forward {self.feed_forward:.2f}"
        )
        if self.panel is None:
            return [text + " (no panel values given to compare)."]
        p = self.panel

        def pct(found: float, panel: float) -> str:
            return f"{100.0 * (found / panel - 1.0):+.0f} %" if panel and math.isfinite(panel) else "n/a"

        return [
            text + ".",
            "  Against the panel's values read as docs/physics.md does (speed command = Kp x error, "
            f"current = Kv x (e + integral/Tv)): Kp {p.position_loop_gain_per_s:.3g} "
            f"({pct(self.position_gain_per_s, p.position_loop_gain_per_s)}), "
            f"Kv {p.speed_loop_gain_a_s_per_rad:.3g} "
            f"({pct(self.speed_gain_a_s_per_rad, p.speed_loop_gain_a_s_per_rad)}), "
            f"Tv {1000.0 * p.speed_loop_integral_time_s:.3g} ms "
            f"({pct(self.integral_time_s, p.speed_loop_integral_time_s)}), "
            f"feed-forward {p.feed_forward_gain:.2f}.",
        ]


@dataclass
class LoopColumns:
    """The smoothed loop columns on the analysis samples, combined for any Tv."""

    eps: np.ndarray
    int_eps: np.ndarray
    cmd_speed: np.ndarray
    cmd: np.ndarray
    speed: np.ndarray
    pos: np.ndarray

    def base(self, tv_s: float, rows: np.ndarray | slice = slice(None)) -> np.ndarray:
        k = 1.0 / tv_s
        return np.column_stack(
            [
                self.eps[rows] + k * self.int_eps[rows],
                self.cmd_speed[rows] + k * self.cmd[rows],
                -(self.speed[rows] + k * self.pos[rows]),
                np.ones_like(self.eps[rows]),
            ]
        )


def closed_loop_signals(rec: Recording, axis: DeclaredAxis) -> Signals:
    """Step 1 without a current: position derivatives at ANALYSIS_BANDWIDTH_HZ (the torque is zero
    until the loop is identified)."""
    if rec.cmd_pos_deg is None:
        raise ModelCheckError(
            "the recording has neither a current nor a command (cmd_pos): without the command the "
            "closed loop cannot be read; record the command pulses with the encoder"
        )
    t = rec.t_s
    dt = float(np.median(np.diff(t)))
    window = window_for_bandwidth(ANALYSIS_BANDWIDTH_HZ, len(t), dt)
    try:
        return build_signals(
            t,
            np.radians(rec.pos_deg),
            np.zeros(len(t)),
            kt_nm_per_a=axis.kt_nm_per_a,
            inertia_kgm2=axis.nominal_inertia_kgm2,
            ratio=axis.ratio,
            load_pos_rad=None if rec.load_pos_deg is None else np.radians(rec.load_pos_deg),
            cmd_pos_rad=np.radians(rec.cmd_pos_deg),
            window=window,
        )
    except ValueError as exc:
        raise ModelCheckError(str(exc)) from None


def loop_columns(sig: Signals) -> LoopColumns:
    assert sig.cmd_pos_rad is not None
    f = sig.filt
    dt = f.dt_s
    cmd = sig.cmd_pos_rad - sig.cmd_pos_rad[0]
    pos = sig.raw_pos_rad - sig.raw_pos_rad[0]
    eps = cmd - pos
    int_eps = np.concatenate([[0.0], np.cumsum(0.5 * (eps[1:] + eps[:-1])) * dt])
    return LoopColumns(
        eps=f.apply(eps),
        int_eps=f.apply(int_eps),
        cmd_speed=f.apply(np.gradient(cmd, dt)),
        cmd=f.apply(cmd),
        speed=sig.speed_f_rad_s,
        pos=f.apply(pos),
    )


def best_integral_time(cols: LoopColumns, y: np.ndarray, index: np.ndarray, extra: np.ndarray) -> float:
    """Tv (s) that lets the loop columns (and ``extra``, the effects in the model) explain y best."""

    def rss(log_tv: float) -> float:
        x = np.column_stack([cols.base(math.exp(log_tv), index), extra])
        return ols(y, x)[1]

    lo, hi = (math.log(v) for v in TV_RANGE_S)
    grid = np.linspace(lo, hi, 13)
    scores = [rss(g) for g in grid]
    k = int(np.argmin(scores))
    a, b = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    sol = minimize_scalar(rss, bounds=(a, b), method="bounded", options={"xatol": 1e-3})
    return float(math.exp(sol.x if sol.fun <= scores[k] else grid[k]))


def friction_proxies(ctx: ChannelContext, index: np.ndarray) -> np.ndarray:
    """Friction and gravity columns: Tv is searched with them in the model, so that it is not bent to
    fit them (a gravity load is nearly linear in the position over a part of a turn, as the
    integral's position term is)."""
    by_id = {c.id: c for c in CANDIDATES_WITHOUT_CURRENT}
    columns = [
        by_id[i].build(ctx, by_id[i].shape_grid[0])[index] for i in ("coulomb_friction", "gravity_load")
    ]
    return np.column_stack([*columns, ctx.sig.speed_f_rad_s[index]])


def decode_loop(beta: np.ndarray, tv_s: float, kt_nm_per_a: float, panel: ServoSettings | None) -> Loop:
    """The loop from the base coefficients of -J a (see the module text); ModelCheckError when the
    fit is not a loop (a gain of the wrong sign)."""
    g = -float(beta[2])
    if not g > 0:
        raise ModelCheckError(
            "the closed loop could not be identified from the recording (the speed loop's gain comes "
            "out negative): is cmd_pos the command in the same direction as pos?"
        )
    return Loop(
        position_gain_per_s=float(beta[0]) / float(beta[2]),
        feed_forward=float(beta[1]) / float(beta[2]),
        integral_time_s=tv_s,
        torque_per_speed_error_nm_s_per_rad=g,
        speed_gain_a_s_per_rad=g / kt_nm_per_a,
        panel=panel,
    )


def not_identifiable_lines(axis: DeclaredAxis, sensor: bool = False) -> list[str]:
    """What a recording without current cannot show; ``sensor``: it has an output torque sensor,
    which measures the load's side (then only the gear is read through the loop)."""
    if sensor:
        j_gear = axis.nominal_inertia_kgm2 - axis.model.load_inertia_kgm2
        return [
            "Without a current the gear is read through the closed loop, the load on the torque sensor: "
            "a constant drag in the gear and the part of its friction that differs by direction are held "
            "by the speed loop's integral and leave no trace in the following error; viscous friction "
            "trades off against the speed loop's gain and feed-forward. Record the current to see them.",
            f"The gear's torques, in N m, rest on the declared actuator inertia ({j_gear:.4g} kg m^2); "
            "the load's are measured.",
        ]
    return [
        "Without a torque measurement (no current, no torque column) these cannot be seen: a constant "
        "load torque and the part of friction that differs by direction are held by the speed loop's "
        "integral and leave no trace in the following error; an inertia error trades off against the "
        "loop's gain scale, and viscous friction against the speed loop's gain and feed-forward. "
        "Record the current (or an output torque sensor) to see them.",
        "Every torque above, in N m, rests on the declared inertia "
        f"({axis.nominal_inertia_kgm2:.4g} kg m^2): an inertia off by x % scales them all by x %.",
    ]


def following_error_gap_arcsec(resim) -> tuple[float, float]:
    """RMS of measured - re-simulated position (the following error's difference, the command being
    the same), nominal and updated model (arcsec)."""
    d_nom = (resim.pos_measured_deg - resim.pos_nominal_deg) * 3600.0
    d_upd = (resim.pos_measured_deg - resim.pos_updated_deg) * 3600.0
    return rms(d_nom - np.mean(d_nom)), rms(d_upd - np.mean(d_upd))


__all__ = [
    "ARCSEC_PER_RAD",
    "CANDIDATES_WITHOUT_CURRENT",
    "NOT_IDENTIFIABLE",
    "TORQUE",
    "Loop",
    "LoopColumns",
    "best_integral_time",
    "closed_loop_signals",
    "decode_loop",
    "following_error_gap_arcsec",
    "friction_proxies",
    "loop_columns",
    "not_identifiable_lines",
]
