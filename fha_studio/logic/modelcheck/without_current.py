"""The workflow for a recording without current (a bench capture): the torque channel through the
closed loop (closedloop.py), then the same naming, consistency and position channel as with it."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from fha_studio.logic.modelcheck import workflow as wf
from fha_studio.logic.modelcheck.axis import DeclaredAxis, ModelCheckError, check_plausible, rms
from fha_studio.logic.modelcheck.candidates import CHANNEL_UNITS, POSITION, TORQUE, Candidate, ChannelContext
from fha_studio.logic.modelcheck.closedloop import (
    CANDIDATES_WITHOUT_CURRENT,
    SEPARATING_WITHOUT_CURRENT,
    closed_loop_signals,
    friction_proxies,
    loop_of,
    not_identifiable_lines,
)
from fha_studio.logic.modelcheck.coast import coast_gaps, coast_spans, name_from_coasts
from fha_studio.logic.modelcheck.consistency import RESIM_TOLERANCE_OF_FLOOR, Refused, settle
from fha_studio.logic.modelcheck.excitation import excitation_of
from fha_studio.logic.modelcheck.loopfit import (
    LoopFit,
    LoopParams,
    RecordedLoop,
    oe_channel,
    through_loop,
)
from fha_studio.logic.modelcheck.result import (
    ABSENT,
    CHECKED,
    ChannelReport,
    ChannelStatus,
    ModelCheckResult,
    Resimulation,
    Structure,
)
from fha_studio.logic.modelcheck.selection import ChannelSelector, FittedTerm
from fha_studio.logic.modelcheck.signals import Signals
from fha_studio.physics import ServoSettings
from fha_studio.recording import Recording

#: a breakaway's fading speed is searched below this share of the fastest recorded speed: well within
#: the speeds the axis ran at, where its curve flattens and is told from the loop's lag
STRIBECK_TOP_SHARE = 0.25
FOLLOWING_ERROR_FLOOR_ARCSEC = 1.0  # a re-simulated following error this much worse is worse
#: rows of the selection (the with-current path's TARGET_DECIMATED keeps more: its torque channel
#: has the bandwidth of the current; the following error here is smoothed to 25 Hz)
TARGET_DECIMATED = 1000


def run_without_current(
    rec: Recording, axis: DeclaredAxis, notes: list[str], *, servo: ServoSettings | None, resimulate: bool
) -> ModelCheckResult:
    """The model check of a recording that has the command and the position but no current.

    The closed loop is read before the first alarm: from it on the servo is off and the axis
    coasts (coast.py reads friction from the coasts)."""
    model = axis.model
    whole = rec
    coasts = coast_spans(rec)
    if coasts:
        rec = rec.slice(0, coasts[0].onset)
        notes = [_servo_on_line(whole, coasts), *notes]
    try:
        if coasts:  # the part before the alarm must be a recording the check can read on its own
            if not len(rec):
                raise ModelCheckError("the ALARM line is on from the first sample")
            check_plausible(rec, axis)
        sig = closed_loop_signals(rec, axis)
    except ModelCheckError as exc:
        if not coasts:
            raise
        at = float(whole.t_s[coasts[0].onset])
        raise ModelCheckError(
            f"the recording before the alarm at {at:.2f} s (the servo on) cannot be checked: {exc}; "
            "record moves with the servo on before the alarm"
        ) from None
    n = len(sig.t_s)
    # the following error the loop leaves is smooth (the analysis bandwidth): decimated to about
    # TARGET_DECIMATED rows, never below two per smoothing window half-width
    step = max(1, min(n // TARGET_DECIMATED, (sig.filt.window - 2) // 2))
    index = np.arange(0, n, step)
    floor_t = max(wf.TORQUE_FLOOR_MIN_NM, wf.TORQUE_FLOOR_FRACTION_OF_MAX * (model.max_torque_nm or 0.0))
    j = axis.nominal_inertia_kgm2
    # with a torque sensor on the output flange the loop fights the gear alone: the load's torque
    # is measured, and judged on its own channel (workflow.sensor_steps)
    sensor = wf.sensor_torque_nm(rec, sig)
    j_gear = j - model.load_inertia_kgm2
    j_loop = j if sensor is None else j_gear
    loop_model = RecordedLoop(sig, j_loop, sensor, index)
    ctx = ChannelContext(sig, TORQUE, nominal_inertia_kgm2=j)
    excitation = excitation_of(sig)
    candidates = tuple(
        c
        for c in CANDIDATES_WITHOUT_CURRENT
        if c.id not in excitation.excluded() and (sensor is None or c.motor_side)
    )
    candidates = tuple(_within_speeds(c, sig) for c in candidates)
    raw = {c.id: c for c in candidates}
    fit = loop_model.fit(friction_proxies(ctx, with_load=sensor is None))
    sel = _selector(loop_model, fit.params, ctx, candidates, index, floor_t)
    terms, steps = sel.select()
    # the loop once more with the chosen effects beside it (the proxies only approach them); the
    # selection again if it moved
    if terms:
        beside = np.column_stack([raw[t.id].build(ctx, t.shape) for t in terms])
        refit = loop_model.fit(beside, start=fit.params)
        if refit.params.moved(fit.params):
            fit = refit
            sel = _selector(loop_model, fit.params, ctx, candidates, index, floor_t)
            terms, steps = sel.select()
    max_torque = model.max_torque_nm or model.peak_torque_nm
    settled = settle(sel, terms, max_torque_nm=max_torque, actuator=axis.code)
    updated_model, updated_fit = _with_effects(loop_model, fit, settled.fitted, raw, ctx)
    # the torques: what the nominal model needs, the effects found, and what the loop shows beyond
    # them (the following error it leaves, in N m at its most sensitive frequency)
    effects_nm = np.zeros(n)
    for ft in settled.fitted:
        effects_nm += raw[ft.id].build(ctx, ft.shape) @ ft.beta
    shown = np.interp(np.arange(n), index, sel.y - settled.fit)
    inertial = j * sig.accel_rad_s2
    sig.torque_f_nm = inertial + effects_nm
    h = sig.filt.half
    eps = None if sig.cmd_pos_rad is None else sig.cmd_pos_rad[h:-h] - sig.pos_rad
    residual = {
        "t_s": sig.t_s,
        "torque_measured_nm": inertial + effects_nm + shown,
        "torque_nominal_nm": inertial,
        "torque_residual_nm": effects_nm + shown,
        "speed_rad_s": sig.speed_rad_s,
        "accel_rad_s2": sig.accel_rad_s2,
        "pos_rad": sig.pos_rad,
        "following_error_rad": eps,
    }
    name = TORQUE if sensor is None else wf.GEAR
    channel = wf.ChannelStep(
        name,
        ctx,
        sel.y,
        tuple(sel.candidates),
        floor_t,
        base=sel.base,
        torque_nm=sig.torque_f_nm,
        bursts=False,
        torque_is_cause=False,
        max_torque_nm=max_torque,
        actuator=axis.code,
    )
    report = ChannelReport(name, "N m", floor_t, steps, settled.ar_order, len(index))
    total = max(float(np.mean(sel.y**2)), 1e-300)
    cancelled = [
        Structure(
            c.channel,
            c.variable,
            c.net_rms,
            min(c.net_rms**2 / total, 1.0),
            c.unit,
            c.spans,
            c.ids,
            c.sizes,
            c.at,
            c.variable_unit,
        )
        for c in settled.cancelling
    ]
    chosen = [
        wf.Selected(
            channel,
            sel,
            settled.terms,
            settled.fitted,
            settled.fit,
            settled.base_beta,
            report,
            settled.refused,
            cancelled,
        )
    ]
    status = {
        name: ChannelStatus(name, CHECKED, "", float(np.max(np.abs(sig.torque_f_nm))), "N m"),
        "current": ChannelStatus(
            "current",
            ABSENT,
            "is absent: the torque is read through the closed loop from the following error and the speed",
        ),
    }
    if sensor is not None:
        load = wf.sensor_steps(
            wf._torque_step(sig, axis, sel.y, floor_t, index, excitation), sensor, model, sig, gear=False
        )[0]
        chosen.append(wf._select(load, index))
        status[load.channel] = ChannelStatus(load.channel, CHECKED, "", float(np.max(np.abs(load.y))), "N m")
    status[POSITION], position = wf._position_step(sig, model, ctx, settled.fitted, residual, index)
    if position is not None:
        chosen.append(wf._select(position, index))
    found = wf.Findings()
    for s in chosen:
        wf._name(s, sig, index, step, found)
    _separating_without_current(found)
    updated = wf._updated_model(model, found.effects)
    # the re-simulation: each model through the loop that explains the recording best beside it,
    # the nominal one alone, the updated one with the effects it names (their sizes held)
    nominal_fit = loop_model.fit(np.zeros((n, 0)), start=fit.params)
    named = [ft for ft in settled.fitted if ft.id in {e.id for e in found.effects}]
    if len(named) < len(settled.fitted):
        updated_model, updated_fit = _with_effects(loop_model, fit, named, raw, ctx)
    if not named:
        updated_model, updated_fit = loop_model, nominal_fit
    loop = loop_of(updated_fit, axis.model, servo, j_loop)
    resim = _resimulation(sig, loop_model, nominal_fit, updated_model, updated_fit, residual, effects_nm)
    fe_nominal = resim.following_error_rms_nominal_arcsec or 0.0
    fe_updated = resim.following_error_rms_updated_arcsec or 0.0
    if found.effects and fe_updated > fe_nominal + RESIM_TOLERANCE_OF_FLOOR * FOLLOWING_ERROR_FLOOR_ARCSEC:
        _refuse(
            found,
            f"its re-simulation follows worse than the nominal model's "
            f"({fe_nominal:.3g} -> {fe_updated:.3g} arcsec rms of following error)",
        )
    wf._hold_to_the_set(found, None, floor_t)
    if found.effects and not loop.plausible:
        _refuse(found, "the closed loop is not pinned down by this recording")
    from_coasts = name_from_coasts(whole, coasts, axis, floor_t, found.effects)
    found.effects.extend(from_coasts.effects)
    # the servo-on part's detection limit does not stand beside the same effect named from a coast
    found.limits = [d for d in found.limits if d.id not in {e.id for e in from_coasts.effects}]
    notes = [*from_coasts.lines, *notes]
    updated = wf._updated_model(model, found.effects)
    filt = sig.filt
    return ModelCheckResult(
        source=rec.source,
        actuator=axis.code,
        window_samples=filt.window,
        window_s=filt.window * filt.dt_s,
        bandwidth_hz=filt.bandwidth_hz,
        residual=residual,
        where=found.where,
        channels={s.step.channel: s.report for s in chosen},
        effects=found.effects,
        ambiguities=found.ambiguities,
        structures=found.structures,
        detection_limits=found.limits,
        gap=found.gaps,
        nominal_model=model,
        updated_model=updated,
        resimulation=resim if resimulate else None,
        notes=[*loop.lines(), *notes],
        channel_status=status,
        window_reason="fixed without a current: the acceleration sets what the loop's torque can show",
        refused=found.refused,
        not_seen=[
            *not_identifiable_lines(
                axis, sensor is not None, rec.load_pos_deg is not None, coast=from_coasts.viscous_shown
            ),
            *_saturation(sig, axis),
            *excitation.lines(coast=from_coasts.viscous_shown),
        ],
        torque_basis=f"on the declared {'' if sensor is None else 'actuator '}inertia "
        f"{(j if sensor is None else j_gear):.4g} kg m^2",
        loop=loop,
        coasts=coast_gaps(from_coasts.fits, j, found.effects),
    )


def _servo_on_line(rec: Recording, coasts) -> str:
    """Where the closed loop was read, and what of the recording it leaves out."""
    t = rec.t_s
    first = float(t[coasts[0].onset])
    text = f"The closed loop is read from the recording before the alarm at {first:.2f} s (the servo was on)"
    after = coasts[-1].stop < len(t)
    if after:
        text += (
            f"; after the ALARM line went off at {float(t[coasts[-1].stop]):.2f} s the recording does "
            "not say when the servo came back on: that part is left out"
        )
    return text + "."


#: the loop is linear only while the current stays within its limit
SATURATION_SHARE = 0.9


def _saturation(sig, axis: DeclaredAxis) -> list[str]:
    """A line when the motion asked for (nearly) the actuator's peak torque: the current was then at
    its limit, the loop not linear, and the loop columns do not hold there."""
    peak = axis.model.peak_torque_nm
    demand = np.abs(axis.nominal_inertia_kgm2 * sig.accel_rad_s2)
    if not len(demand) or float(np.max(demand)) < SATURATION_SHARE * peak:
        return []
    at = float(sig.t_s[int(np.argmax(demand))])
    return [
        f"The loop cannot be read where the current was at its limit: the motion needs up to "
        f"{float(np.max(demand)):.3g} N m (inertia x acceleration, at t = {at:.2f} s) against the actuator's "
        f"{peak:.3g} N m peak. Record moves with less acceleration."
    ]


def _refuse(found: wf.Findings, why: str) -> None:
    names = " + ".join(e.label.lower() for e in found.effects)
    for e in found.effects:
        found.refused.append(
            Refused(
                e.id,
                e.channel,
                e.label,
                dict(e.params),
                e.size,
                CHANNEL_UNITS[e.channel],
                f"the set {names} is not named: {why}",
            )
        )
    found.effects.clear()
    found.ambiguities.clear()


def _selector(
    loop_model: RecordedLoop,
    p: LoopParams,
    ctx: ChannelContext,
    candidates: tuple[Candidate, ...],
    index: np.ndarray,
    floor_t: float,
) -> ChannelSelector:
    """The selection on the following error the loop ``p`` leaves (in N m, see loopfit.oe_channel):
    the candidates seen through the loop, the loop's own parameters and its start fitted beside them."""
    y, base, _ = oe_channel(loop_model, p, index)
    seen = through_loop(candidates, loop_model, p)
    return ChannelSelector(ctx, y[index], seen, index, floor_t, CHANNEL_UNITS[TORQUE], base=base)



def _resimulation(
    sig: Signals,
    nominal: RecordedLoop,
    nominal_fit: LoopFit,
    updated: RecordedLoop,
    updated_fit: LoopFit,
    residual: dict[str, np.ndarray],
    effects_nm: np.ndarray,
) -> Resimulation:
    """The recorded command through each model's loop (loopfit.RecordedLoop.simulate): the positions
    against the measured one, and the torques each model puts on the axis."""
    ref = np.degrees(float(sig.cmd_pos_rad[0])) if sig.cmd_pos_rad is not None else 0.0
    measured = np.degrees(nominal.pos) + ref
    pos_nominal = np.degrees(nominal.simulate(nominal_fit.params)) + ref
    pos_updated = np.degrees(updated.simulate(updated_fit.params)) + ref
    torque = residual["torque_measured_nm"]
    inertial = residual["torque_nominal_nm"]
    d_nom = (measured - pos_nominal) * 3600.0
    d_upd = (measured - pos_updated) * 3600.0
    return Resimulation(
        t_s=sig.t_s,
        torque_measured_nm=torque,
        torque_nominal_nm=inertial,
        torque_updated_nm=inertial + effects_nm,
        pos_measured_deg=measured,
        pos_nominal_deg=pos_nominal,
        pos_updated_deg=pos_updated,
        rms_nominal_nm=rms(torque - inertial),
        rms_updated_nm=rms(torque - inertial - effects_nm),
        command="cmd_pos through the loop identified beside each model",
        following_error_rms_nominal_arcsec=rms(d_nom - np.mean(d_nom)),
        following_error_rms_updated_arcsec=rms(d_upd - np.mean(d_upd)),
    )


def _with_effects(
    loop_model: RecordedLoop,
    fit: LoopFit,
    fitted: list[FittedTerm],
    raw: dict[str, Candidate],
    ctx: ChannelContext,
) -> tuple[RecordedLoop, LoopFit]:
    """The loop model with the fitted effects' torques acting (their sizes held), and the loop that
    explains the recording best with them, from ``fit``."""
    torque = np.zeros(loop_model.n)
    for ft in fitted:
        torque += raw[ft.id].build(ctx, ft.shape) @ ft.beta
    if not fitted:
        return loop_model, fit
    model = loop_model.with_torque(torque)
    return model, model.fit(np.zeros((loop_model.n, 0)), start=fit.params)


def _within_speeds(cand: Candidate, sig: Signals) -> Candidate:
    """A breakaway's fading speed searched well below the fastest recorded speed only: without a
    torque measurement the friction's level at a steady speed is held by the loop's integral, and a
    friction that changes across the recorded speeds reads like the loop's lag (viscous friction,
    see closedloop.py): such a breakaway would be Coulomb friction read another way."""
    if cand.id != "stribeck_friction":
        return cand
    top = STRIBECK_TOP_SHARE * float(np.percentile(np.abs(sig.speed_rad_s), 99.0))
    grid = tuple(s for s in cand.shape_grid if s[0] <= top) or (cand.shape_grid[0],)

    def bounds(s: tuple[float, ...]) -> tuple[list[float], list[float]]:
        lo, hi = cand.shape_bounds(s)
        return [min(lo[0], top)], [max(min(hi[0], top), min(lo[0], top) * 1.001)]

    return replace(cand, shape_grid=grid, shape_bounds=bounds)


def _separating_without_current(found: wf.Findings) -> None:
    """The recordings that would separate look-alikes when the torque is read through the loop."""
    for i, amb in enumerate(found.ambiguities):
        test = SEPARATING_WITHOUT_CURRENT.get(frozenset({amb.chosen, amb.alternative}))
        if test is None:
            continue
        old = amb.separating_test
        found.ambiguities[i] = replace(amb, separating_test=test)
        for e in found.effects:
            if amb.alternative in e.alternatives and old in e.advice:
                e.advice = e.advice.replace(old, test)
