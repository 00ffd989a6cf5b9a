"""The workflow for a recording without current (a bench capture): the torque channel through the
closed loop (closedloop.py), then the same naming, consistency and position channel as with it."""

from __future__ import annotations

import numpy as np

from fha_studio.logic.modelcheck import workflow as wf
from fha_studio.logic.modelcheck.axis import DeclaredAxis
from fha_studio.logic.modelcheck.candidates import CHANNEL_UNITS, POSITION, TORQUE, ChannelContext
from fha_studio.logic.modelcheck.closedloop import (
    CANDIDATES_WITHOUT_CURRENT,
    best_integral_time,
    closed_loop_signals,
    decode_loop,
    following_error_gap_arcsec,
    friction_proxies,
    loop_columns,
    not_identifiable_lines,
)
from fha_studio.logic.modelcheck.consistency import RESIM_TOLERANCE_OF_FLOOR, Refused, settle
from fha_studio.logic.modelcheck.excitation import excitation_of
from fha_studio.logic.modelcheck.linalg import ols
from fha_studio.logic.modelcheck.resimulation import resimulate as resimulate_axis
from fha_studio.logic.modelcheck.result import (
    ABSENT,
    CHECKED,
    ChannelReport,
    ChannelStatus,
    ModelCheckResult,
    Structure,
)
from fha_studio.logic.modelcheck.selection import ChannelSelector
from fha_studio.physics import ServoSettings
from fha_studio.recording import Recording

FOLLOWING_ERROR_FLOOR_ARCSEC = 1.0  # a re-simulated following error this much worse is worse


def run_without_current(
    rec: Recording, axis: DeclaredAxis, notes: list[str], *, servo: ServoSettings | None, resimulate: bool
) -> ModelCheckResult:
    """The model check of a recording that has the command and the position but no current."""
    model = axis.model
    sig = closed_loop_signals(rec, axis)
    n = len(sig.t_s)
    step = max(1, min(n // wf.TARGET_DECIMATED, (sig.filt.window - 2) // 2))
    index = np.arange(0, n, step)
    floor_t = max(wf.TORQUE_FLOOR_MIN_NM, wf.TORQUE_FLOOR_FRACTION_OF_MAX * (model.max_torque_nm or 0.0))
    j = axis.nominal_inertia_kgm2
    # with a torque sensor on the output flange the loop fights the gear alone: the load's torque
    # is measured, and judged on its own channel (workflow.sensor_steps)
    sensor = wf.sensor_torque_nm(rec, sig)
    j_gear = j - model.load_inertia_kgm2
    y = -(j * sig.accel_rad_s2) if sensor is None else -(j_gear * sig.accel_rad_s2 + sensor)
    cols = loop_columns(sig)
    ctx = ChannelContext(sig, TORQUE, nominal_inertia_kgm2=j)
    excitation = excitation_of(sig)
    candidates = tuple(
        c
        for c in CANDIDATES_WITHOUT_CURRENT
        if c.id not in excitation.excluded() and (sensor is None or c.motor_side)
    )
    tv = best_integral_time(cols, y[index], index, friction_proxies(ctx, index))
    sel = ChannelSelector(
        ctx, y[index], candidates, index, floor_t, CHANNEL_UNITS[TORQUE], base=cols.base(tv, index)
    )
    terms, steps = sel.select()
    # Tv once more with the chosen effects in the model; the selection again if it moved
    if terms:
        tv2 = best_integral_time(cols, y[index], index, sel.design(terms)[:, sel.base.shape[1] :])
        if abs(np.log(tv2 / tv)) > 0.1:
            tv = tv2
            sel = ChannelSelector(
                ctx, y[index], candidates, index, floor_t, CHANNEL_UNITS[TORQUE], base=cols.base(tv, index)
            )
            terms, steps = sel.select()
    max_torque = model.max_torque_nm or model.peak_torque_nm
    settled = settle(sel, terms, max_torque_nm=max_torque, actuator=axis.code)
    loop = decode_loop(settled.base_beta, tv, axis.kt_nm_per_a, servo)
    # the loop's torque (Kt x the current it commanded), estimated: what the current would have shown
    loop_torque = -(cols.base(tv) @ settled.base_beta)
    sig.torque_f_nm = loop_torque
    residual = {
        "t_s": sig.t_s,
        "torque_measured_nm": loop_torque,
        "torque_nominal_nm": -y,
        "torque_residual_nm": loop_torque + y,
        "speed_rad_s": sig.speed_rad_s,
        "accel_rad_s2": sig.accel_rad_s2,
        "pos_rad": sig.pos_rad,
        "following_error_rad": cols.eps,
    }
    name = TORQUE if sensor is None else wf.GEAR
    channel = wf.ChannelStep(
        name,
        ctx,
        y,
        candidates,
        floor_t,
        base=sel.base,
        torque_nm=loop_torque,
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
        name: ChannelStatus(name, CHECKED, "", float(np.max(np.abs(loop_torque))), "N m"),
        "current": ChannelStatus(
            "current",
            ABSENT,
            "is absent: the torque is read through the closed loop from the following error and the speed",
        ),
    }
    if sensor is not None:
        load = wf.sensor_steps(
            wf._torque_step(sig, axis, y, floor_t, index, excitation), sensor, model, sig, gear=False
        )[0]
        chosen.append(wf._select(load, index))
        status[load.channel] = ChannelStatus(load.channel, CHECKED, "", float(np.max(np.abs(load.y))), "N m")
    status[POSITION], position = wf._position_step(sig, model, ctx, settled.fitted, residual, index)
    if position is not None:
        chosen.append(wf._select(position, index))
    found = wf.Findings()
    for s in chosen:
        wf._name(s, sig, index, step, found)
    updated = wf._updated_model(model, found.effects)
    resim = None
    if resimulate:
        # each model through the loop identified beside it: the nominal one with the loop that
        # explains the recording alone, the updated one with the loop fitted together with its effects
        nominal_beta, _ = ols(sel.y, sel.base)
        nominal_loop = decode_loop(nominal_beta, tv, axis.kt_nm_per_a, servo)
        resim = resimulate_axis(sig, axis, model, updated, loop.servo(), wf.RESIM_MAX_S)
        if found.effects:
            first = resimulate_axis(sig, axis, model, model, nominal_loop.servo(), wf.RESIM_MAX_S)
            resim.pos_nominal_deg, resim.torque_nominal_nm = first.pos_nominal_deg, first.torque_nominal_nm
        resim.command = "cmd_pos through the identified loop"
        fe_nominal, fe_updated = following_error_gap_arcsec(resim)
        resim.following_error_rms_nominal_arcsec = fe_nominal
        resim.following_error_rms_updated_arcsec = fe_updated
        if (
            found.effects
            and fe_updated > fe_nominal + RESIM_TOLERANCE_OF_FLOOR * FOLLOWING_ERROR_FLOOR_ARCSEC
        ):
            _refuse(
                found,
                f"its re-simulation follows worse than the nominal model's "
                f"({fe_nominal:.3g} -> {fe_updated:.3g} arcsec rms of following error)",
            )
    wf._hold_to_the_set(found, None, floor_t)
    if found.effects and not loop.plausible:
        _refuse(found, "the closed loop is not pinned down by this recording")
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
        resimulation=resim,
        notes=[*loop.lines(), *notes],
        channel_status=status,
        window_reason="fixed without a current: the acceleration sets what the loop's torque can show",
        refused=found.refused,
        not_seen=[
            *not_identifiable_lines(axis, sensor is not None),
            *_saturation(sig, axis),
            *excitation.lines(),
        ],
        torque_basis=f"on the declared {'' if sensor is None else 'actuator '}inertia "
        f"{(j if sensor is None else j_gear):.4g} kg m^2",
        loop=loop,
    )


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
