"""Friction from a coast: what a recording without current shows once an alarm has taken the loop away.

On an alarm the HA-655 de-energises the motor and the axis coasts (no dynamic brake is documented);
the encoder outputs keep counting and the ALARM line says when it began. With no current, no loop
and the declared inertia J, the axis obeys

    J a = -c s - b w - g T_known(pos),   s = sign(w) (constant within one coast),

c the friction level in the coast's direction (Coulomb friction and any constant load torque, one
number per direction: two coasts in opposite directions separate them), b viscous friction, and
T_known the load's torques already named (gravity), its size g fitted again. For T_known = 0 the
speed is w(t) = (w0 + c s / b) e^(-b t / J) - c s / b, so the position is linear in (pos0, w0, c,
g) for a given k = b / J: the fit searches k alone and solves the rest by least squares on the recorded
position (no second difference of a quantised encoder is taken). The uncertainties come from the
residual, widened by its correlation from row to row; an effect below three of them, or whose
torque stays under the channel's floor, is not named. A coast that stops faster than any friction
of an FHA-C could stop it (a brake the controller engaged) names nothing.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import minimize_scalar

from fha_studio.logic.modelcheck.axis import DeclaredAxis, rms
from fha_studio.logic.modelcheck.candidates import CANDIDATES, LABELS, TORQUE
from fha_studio.logic.modelcheck.linalg import ols
from fha_studio.logic.modelcheck.result import CoastGap, Effect, fmt_pm
from fha_studio.physics import AxisModel
from fha_studio.recording import Recording

#: the current's decay after the alarm (the motor's electrical time constant is well under it): the
#: coast's fit starts this much after the ALARM line goes on
DE_ENERGISE_S = 0.005
#: the half-width of the speed estimate that finds where the axis stops
SPEED_SPAN_S = 0.01
#: the axis has stopped when it runs slower than this share of its speed at the alarm
STOPPED_SHARE = 0.02
#: a coast tells something only when a torque at the channel's floor would move the axis by this
#: many encoder counts over it
MIN_COUNTS_FROM_FLOOR = 20.0
#: an estimate is named when it is this many of its standard deviations from nil
NAMED_SIGMAS = 3.0
#: a coast that needs more than this many times the catalogue's friction at maximum speed (TF, FHA-C
#: manual 2-4-4) to stop was stopped by a brake, not friction (the brakes hold 3 to 5 TF, 1-10)
BRAKE_TIMES_CATALOGUE_FRICTION = 2.0
#: the same without a catalogue friction (a custom axis): a share of the maximum torque
BRAKE_SHARE_OF_MAX_TORQUE = 0.5
#: the fastest decay searched: a time constant of this share of the coast
FASTEST_DECAY_SHARE = 0.02
#: two estimates of one friction agree when they differ by less than this many standard deviations
#: of their difference
AGREE_SIGMAS = 3.0
RPM_PER_RAD_S = 30.0 / math.pi


@dataclass(frozen=True)
class CoastSpan:
    """Rows of a recording: the alarm's onset and the coast's end (the alarm off, or the end)."""

    onset: int
    stop: int


def coast_spans(rec: Recording) -> list[CoastSpan]:
    """Each span where the ALARM line is on (empty when it was not recorded or never on)."""
    alarm = rec.channels.get("alarm")
    if alarm is None:
        return []
    on = np.concatenate([[0], (np.asarray(alarm) > 0.5).astype(np.int8), [0]])
    edges = np.flatnonzero(np.diff(on))
    return [CoastSpan(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


@dataclass(frozen=True)
class CoastFit:
    """One coast's fit. Times from the recording's start (s); speeds rad/s at the output."""

    alarm_s: float
    direction: int  # +1 forward, -1 reverse (the recording's positive sense)
    speed_at_alarm_rad_s: float
    duration_s: float  # of the part fitted (to where the axis stopped, or the alarm or recording ended)
    stopped: bool  # the axis came to rest within the coast
    level_nm: float  # c: friction (and any constant load torque) in this direction
    level_sigma_nm: float
    viscous_nm_s_per_rad: float  # b
    viscous_sigma_nm_s_per_rad: float
    t_s: np.ndarray
    speed_measured_rad_s: np.ndarray  # from the recorded position, smoothed over SPEED_SPAN_S
    speed_nominal_rad_s: np.ndarray  # no friction: the speed at the coast's start held
    speed_fitted_rad_s: np.ndarray  # the fit's own curve (before naming)
    pos_measured_rad: np.ndarray
    pos_nominal_rad: np.ndarray
    braked: bool = False  # stopped faster than friction could stop it
    why_not: str = ""  # a coast that tells nothing: why
    load_nm: np.ndarray | None = None  # the named load's torque along the coast (gravity), N m

    def speed_with(self, level_nm: float, viscous_nm_s_per_rad: float, inertia_kgm2: float) -> np.ndarray:
        """The speed from the coast's start with the given friction (rad/s, zero once stopped)."""
        t = self.t_s - self.t_s[0]
        k = viscous_nm_s_per_rad / inertia_kgm2
        w0 = self.speed_at_start_rad_s
        s = self.direction
        w = w0 * np.exp(-k * t) - s * level_nm / inertia_kgm2 * _h(k, t)
        if self.load_nm is not None:
            w = w + np.gradient(_known_response(k, t, self.load_nm, inertia_kgm2), t)
        w[s * w < 0] = 0.0  # friction holds it once at rest
        return w

    @property
    def speed_at_start_rad_s(self) -> float:
        return float(self.speed_fitted_rad_s[0])


def _h(k: float, t: np.ndarray) -> np.ndarray:
    """(1 - e^(-k t)) / k, t where k = 0."""
    return t if k * float(t[-1]) < 1e-9 else -np.expm1(-k * t) / k


def _q(k: float, t: np.ndarray) -> np.ndarray:
    """(k t - 1 + e^(-k t)) / k^2, the double integral of e^(-k t)'s complement: t^2 / 2 where k = 0."""
    kt = k * t
    if float(kt[-1]) < 1e-4:
        return t**2 / 2.0 - k * t**3 / 6.0
    return (kt + np.expm1(-kt)) / k**2


def _known_response(k: float, t: np.ndarray, known_nm: np.ndarray, inertia_kgm2: float) -> np.ndarray:
    """The position (rad) a known torque opposing the motion (N m, per row) moves the axis by, from
    rest: x'' + k x' = -T / J, the torque held over each row."""
    if not np.any(known_nm):
        return np.zeros_like(t)
    dt = np.diff(t, prepend=t[0])
    decay = np.exp(-k * dt)
    gain = _h(k, dt) if k > 0 else dt
    w = np.zeros_like(t)
    for i in range(1, len(t)):
        w[i] = w[i - 1] * decay[i] - known_nm[i - 1] / inertia_kgm2 * gain[i]
    return np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(t))])


def _design(k: float, t: np.ndarray, s: int, inertia_kgm2: float) -> np.ndarray:
    return np.column_stack([np.ones_like(t), _h(k, t), -s * _q(k, t) / inertia_kgm2])


def _speed(t: np.ndarray, pos: np.ndarray, span_s: float) -> np.ndarray:
    """Central differences over +-span_s (one-sided at the ends)."""
    dt = float(np.median(np.diff(t)))
    m = max(1, round(span_s / dt))
    i = np.arange(len(t))
    a, b = np.clip(i - m, 0, len(t) - 1), np.clip(i + m, 0, len(t) - 1)
    return (pos[b] - pos[a]) / np.maximum(t[b] - t[a], 1e-12)


def fit_coast(
    rec: Recording,
    span: CoastSpan,
    inertia_kgm2: float,
    count_rad: float,
    floor_nm: float,
    most_friction_nm: float,
    known_torque_nm: Callable[[np.ndarray], np.ndarray] | None = None,
) -> CoastFit:
    """The coast of ``span``: where the axis stopped, and c and b fitted to its position."""
    t_all, pos_all = rec.t_s, np.radians(rec.pos_deg)
    alarm_s = float(t_all[span.onset])
    first = int(np.searchsorted(t_all, alarm_s + DE_ENERGISE_S))
    rows = slice(first, span.stop)
    t, pos = t_all[rows], pos_all[rows]
    empty = np.zeros(0)

    def told_nothing(why: str, w0: float = 0.0, direction: int = 1) -> CoastFit:
        return CoastFit(alarm_s, direction, w0, 0.0, False, 0.0, math.inf, 0.0, math.inf, empty, empty, empty,
                        empty, empty, empty, why_not=why)

    if len(t) < 8:
        return told_nothing("the recording ends (or the alarm clears) as the coast begins")
    w = _speed(t, pos, SPEED_SPAN_S)
    w0 = float(w[0])
    direction = 1 if w0 >= 0 else -1
    slow = np.flatnonzero(direction * w <= STOPPED_SHARE * abs(w0))
    end = int(slow[0]) if len(slow) else len(t)
    stopped = bool(len(slow))
    duration = float(t[end - 1] - t[0]) if end > 1 else 0.0
    # how far a torque at the floor moves the axis over this coast, in counts (while it runs)
    shown_counts = 0.5 * floor_nm / inertia_kgm2 * duration**2 / count_rad

    def braked(needed_nm: float) -> CoastFit:
        return replace(
            told_nothing("", w0, direction),
            braked=True,
            why_not=(
                f"it slowed from {abs(w0) * RPM_PER_RAD_S:.3g} r/min {'to rest ' if stopped else ''}within "
                f"{duration:.3g} s, which takes {needed_nm:.3g} N m on the declared inertia, more than "
                "friction of this actuator could "
                f"({most_friction_nm:.3g} N m): a brake (or the load) stopped it"
            ),
        )

    if stopped and duration > 0:
        needed = inertia_kgm2 * abs(w0) / max(duration, float(t[1] - t[0]))
        if needed > most_friction_nm:
            return braked(needed)
    if shown_counts < MIN_COUNTS_FROM_FLOOR:
        return told_nothing(
            f"it lasts {duration:.3g} s from {abs(w0) * RPM_PER_RAD_S:.3g} r/min: too short or too slow for "
            "a friction at the detection floor to show in the position",
            w0,
            direction,
        )
    t, pos = t[:end], pos[:end]
    tr = t - t[0]
    known = known_torque_nm(pos) if known_torque_nm is not None else np.zeros_like(t)

    def design(k: float) -> np.ndarray:
        x = _design(k, tr, direction, inertia_kgm2)
        if known_torque_nm is None:
            return x
        # the named load's torque with its size free: a few per cent off in it would otherwise
        # read as friction (a pendulum's coast is mostly its gravity)
        return np.column_stack([x, _known_response(k, tr, known, inertia_kgm2)])

    def solve(k: float) -> tuple[np.ndarray, np.ndarray]:
        x = design(k)
        beta, _ = ols(pos, x)
        if beta[2] < 0:
            # no pushing friction: at a steady speed a drag and a push would cancel in any size
            keep = [i for i in range(x.shape[1]) if i != 2]
            beta = np.insert(ols(pos, x[:, keep])[0], 2, 0.0)
        return pos - x @ beta, beta

    k_max = 1.0 / (FASTEST_DECAY_SHARE * duration)
    best = minimize_scalar(lambda u: float(np.sum(solve(u**2)[0] ** 2)), bounds=(0.0, math.sqrt(k_max)),
                           method="bounded", options={"xatol": 1e-6 * math.sqrt(k_max)})
    k = float(best.x) ** 2
    r0 = float(np.sum(solve(0.0)[0] ** 2))
    if r0 <= float(best.fun):
        k = 0.0
    resid, beta = solve(k)
    # the uncertainties: the Jacobian in (pos0, w0, c[, the load's size], k), the residual's
    # variance, widened by the residual's correlation from row to row (quantisation and smoothing
    # make neighbours alike)
    dk = 1e-4 * k_max
    x = design(k)
    dx = (design(k + dk) @ beta - x @ beta) / dk
    jac = np.column_stack([x, dx])
    n, p = jac.shape
    var = float(np.sum(resid**2)) / max(n - p, 1)
    rho = float(np.corrcoef(resid[:-1], resid[1:])[0, 1]) if n > 3 and np.std(resid) > 0 else 0.0
    rho = min(max(rho, 0.0), 0.999)
    cov = np.linalg.pinv(jac.T @ jac) * var * (1.0 + rho) / (1.0 - rho)
    sigma = np.sqrt(np.maximum(np.diag(cov), 0.0))
    b, b_sigma = k * inertia_kgm2, float(sigma[-1]) * inertia_kgm2
    c, c_sigma = float(beta[2]), float(sigma[2])
    if c > most_friction_nm:
        return braked(c)
    w_fit = beta[1] * np.exp(-k * tr) - direction * c / inertia_kgm2 * _h(k, tr)
    if known_torque_nm is not None:  # the load's share of the speed: the derivative of its response
        w_fit = w_fit + beta[3] * np.gradient(_known_response(k, tr, known, inertia_kgm2), tr)
    return CoastFit(
        alarm_s=alarm_s,
        direction=direction,
        speed_at_alarm_rad_s=w0,
        duration_s=duration,
        stopped=stopped,
        level_nm=c,
        level_sigma_nm=c_sigma,
        viscous_nm_s_per_rad=b,
        viscous_sigma_nm_s_per_rad=b_sigma,
        t_s=t,
        speed_measured_rad_s=w[:end],
        speed_nominal_rad_s=np.full(end, float(beta[1])),
        speed_fitted_rad_s=w_fit,
        pos_measured_rad=pos,
        pos_nominal_rad=beta[0] + beta[1] * tr,
        load_nm=None if known_torque_nm is None else known,
    )


@dataclass
class CoastFindings:
    """What the coasts of a recording named, said and showed."""

    effects: list[Effect] = field(default_factory=list)  # named from the coasts alone
    lines: list[str] = field(default_factory=list)  # for the report's notes
    fits: list[CoastFit] = field(default_factory=list)  # the coasts that tell something
    viscous_shown: bool = False  # a coast could show viscous friction (named or not)


def most_friction_nm(model: AxisModel) -> float:
    """The torque beyond which a brake, not friction, stopped a coast (BRAKE_TIMES_CATALOGUE_FRICTION)."""
    tf = model.friction_torque_nm
    if tf:
        return BRAKE_TIMES_CATALOGUE_FRICTION * tf
    return BRAKE_SHARE_OF_MAX_TORQUE * (model.max_torque_nm or model.peak_torque_nm)


def _weighted(values: list[tuple[float, float]]) -> tuple[float, float]:
    """The inverse-variance mean of (value, sigma) pairs and its sigma."""
    w = [1.0 / max(s, 1e-300) ** 2 for _, s in values]
    mean = sum(wi * v for wi, (v, _) in zip(w, values, strict=True)) / sum(w)
    return mean, 1.0 / math.sqrt(sum(w))


def _where(fits: list[CoastFit]) -> str:
    at = " and ".join(f"{f.alarm_s:.2f} s" for f in fits)
    coasts = "coasts" if len(fits) > 1 else "coast"
    return f"from the {coasts} after the alarm at {at}; rests on the declared inertia"


def name_from_coasts(
    rec: Recording,
    spans: list[CoastSpan],
    axis: DeclaredAxis,
    floor_nm: float,
    effects: list[Effect],
) -> CoastFindings:
    """Fit each coast, name viscous friction (and Coulomb friction, or check the one the servo-on
    part named) into ``effects``, and the coasts' speed against the nominal and the updated model."""
    out = CoastFindings()
    model = axis.model
    j = axis.nominal_inertia_kgm2
    count_rad = 2.0 * math.pi / model.output_resolution_ppr if model.output_resolution_ppr else 1e-6
    gravity = next((e for e in effects if e.id == "gravity_load"), None)
    known = None
    if gravity is not None:
        amp, phase = gravity.params["amplitude_nm"], math.radians(gravity.params["phase_deg"])

        def known(pos: np.ndarray) -> np.ndarray:
            return amp * np.sin(pos + phase)

    fits = [fit_coast(rec, sp, j, count_rad, floor_nm, most_friction_nm(model), known) for sp in spans]
    useful = []
    for f in fits:
        if f.why_not:
            out.lines.append(f"The coast after the alarm at {f.alarm_s:.2f} s names nothing: {f.why_not}.")
        else:
            useful.append(f)
    if not useful:
        return out
    out.viscous_shown = True
    out.fits = useful
    where = _where(useful)
    # viscous friction: one number whatever the direction
    b, b_sigma = _weighted([(f.viscous_nm_s_per_rad, f.viscous_sigma_nm_s_per_rad) for f in useful])
    top_speed = max(abs(f.speed_at_start_rad_s) for f in useful)
    if b > NAMED_SIGMAS * b_sigma and b * top_speed >= floor_nm:
        out.effects.append(_effect("viscous_friction", "coefficient_nm_s_per_rad", b, b_sigma,
                                   b * rms(np.concatenate([f.speed_fitted_rad_s for f in useful])), where))
    else:
        out.lines.append(
            f"Viscous friction {where}: {fmt_pm(b, b_sigma, 'N m s/rad')}, under the detection floor "
            f"({fmt_pm(floor_nm / top_speed, 0.0, 'N m s/rad')} at its speed, or {NAMED_SIGMAS:g} standard "
            "deviations): not named."
        )
    # the level in each direction: Coulomb friction plus any constant load torque (a load pulling
    # one way adds to one direction's level and takes from the other's)
    by_dir = {
        d: _weighted([(f.level_nm, f.level_sigma_nm) for f in useful if f.direction == d])
        for d in (1, -1)
        if any(f.direction == d for f in useful)
    }
    if len(by_dir) == 2:
        (up, su), (down, sd) = by_dir[1], by_dir[-1]
        level, level_sigma = 0.5 * (up + down), 0.5 * math.hypot(su, sd)
        offset, offset_sigma = 0.5 * (up - down), level_sigma
        basis = "the mean of both directions"
        if abs(offset) > NAMED_SIGMAS * offset_sigma and abs(offset) >= floor_nm:
            out.lines.append(
                f"The coasts' friction differs by direction: {fmt_pm(up, su, 'N m')} forward, "
                f"{fmt_pm(down, sd, 'N m')} in reverse ({where}): half the difference is a constant load "
                "torque, or friction that differs by direction (no coast tells them apart)."
            )
            effect = _effect("load_torque_offset", "torque_nm", offset, offset_sigma, abs(offset), where)
            effect.alternatives = ["asymmetric_friction"]
            effect.advice = (
                f"{effect.advice}; or friction that differs by direction: record the current through "
                "slow runs both ways to tell them apart"
            )
            out.effects.append(effect)
    else:
        ((d, (level, level_sigma)),) = by_dir.items()
        basis = f"{'forward' if d > 0 else 'reverse'} only, so any constant load torque is in it too"
    loop_coulomb = next((e for e in effects if e.id == "coulomb_friction"), None)
    if loop_coulomb is not None:
        _check_coulomb(loop_coulomb, level, level_sigma, len(by_dir) == 2, f"{basis}; {where}", out)
    elif level > NAMED_SIGMAS * level_sigma and level >= floor_nm:
        out.effects.append(
            _effect("coulomb_friction", "torque_nm", level, level_sigma, level, f"{where}; {basis}")
        )
    else:
        out.lines.append(
            f"Coulomb friction {where}: {fmt_pm(level, level_sigma, 'N m')}, under the detection floor "
            f"({fmt_pm(floor_nm, 0.0, 'N m')}, or {NAMED_SIGMAS:g} standard deviations): not named."
        )
    return out


def _check_coulomb(
    loop: Effect, level: float, level_sigma: float, both_ways: bool, where: str, out: CoastFindings
) -> None:
    """The servo-on part's Coulomb friction against the coast's level: agreeing, their weighted
    mean is named; disagreeing, it is said, and the coasts' value named when they ran both ways
    (then no constant load torque is in it), else the servo-on value kept."""
    fc, fc_sigma = loop.params["torque_nm"], loop.uncertainty["torque_nm"]
    said = (
        f"Coulomb friction: the servo-on moves give {fmt_pm(fc, fc_sigma, 'N m')}, the coast "
        f"{fmt_pm(level, level_sigma, 'N m')} ({where})"
    )
    if abs(level - fc) <= AGREE_SIGMAS * math.hypot(level_sigma, fc_sigma):
        value, sigma = _weighted([(fc, fc_sigma), (level, level_sigma)])
        out.lines.append(f"{said}: they agree; the value named is their weighted mean.")
        loop.basis = "the servo-on moves and the coast weighted; rests on the declared inertia"
    elif both_ways:
        value, sigma = level, level_sigma
        out.lines.append(
            f"{said}: they disagree beyond their uncertainties; the coasts' value is named (read without "
            "the loop, both directions)."
        )
        loop.basis = where
    else:
        out.lines.append(
            f"{said}: they disagree beyond their uncertainties; the servo-on value is kept. A constant "
            "load torque or friction that differs by direction (a coast the other way separates them) "
            "would do this, or a loop read imperfectly."
        )
        return
    loop.params["torque_nm"], loop.uncertainty["torque_nm"] = value, sigma
    loop.size = value
    loop.advice = CANDIDATES[loop.id].advice(loop.params)  # says the value named, not the servo-on one


def _effect(effect_id: str, param: str, value: float, sigma: float, size: float, basis: str) -> Effect:
    params = {param: value}
    cand = CANDIDATES[effect_id]
    unit = "N m s/rad" if effect_id == "viscous_friction" else "N m"
    return Effect(effect_id, TORQUE, LABELS[effect_id], params, {param: sigma}, {param: unit}, size,
                  advice=cand.advice(params), basis=basis)


def coast_gaps(fits: list[CoastFit], inertia_kgm2: float, effects: list[Effect]) -> list[CoastGap]:
    """Each coast's speed from its start: recorded, the nominal model's (no friction) and the
    updated model's (the Coulomb and viscous friction and the constant load torque it names)."""
    by_id = {e.id: e for e in effects}
    fc = by_id["coulomb_friction"].params["torque_nm"] if "coulomb_friction" in by_id else 0.0
    offset = by_id["load_torque_offset"].params["torque_nm"] if "load_torque_offset" in by_id else 0.0
    b = by_id["viscous_friction"].params["coefficient_nm_s_per_rad"] if "viscous_friction" in by_id else 0.0
    gaps = []
    for f in fits:
        measured = f.speed_measured_rad_s * RPM_PER_RAD_S
        nominal = f.speed_nominal_rad_s * RPM_PER_RAD_S
        updated = f.speed_with(fc + f.direction * offset, b, inertia_kgm2) * RPM_PER_RAD_S
        gaps.append(CoastGap(f.alarm_s, f.t_s, measured, nominal, updated, rms(measured - nominal),
                             rms(measured - updated)))
    return gaps
