"""The model-check workflow: residuals -> where -> name -> add -> gap.

Step 1's signals come from signals.py; each channel (the torque, then the load-side position) is
described once as a :class:`ChannelStep` (its residual, candidates, floor and nuisance columns) and
goes through the same selection (selection.py, step 3), naming and gap; step 2's binning and the
structure no candidate explains are structure.py; the re-simulation is resimulation.py; the result
types and their summary are result.py.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from fha_studio.logic.modelcheck.axis import (
    DeclaredAxis,
    ModelCheckError,
    check_plausible,
    declared_axis,
)
from fha_studio.logic.modelcheck.bandwidth import BandwidthChoice, choose_bandwidth
from fha_studio.logic.modelcheck.candidates import (
    CANDIDATES,
    CHANNEL_UNITS,
    POSITION,
    POSITION_CANDIDATES,
    QUANTISED_PULSES_PER_PERIOD,
    TORQUE,
    TORQUE_CANDIDATES,
    Candidate,
    ChannelContext,
    Param,
    label_of,
    separating_test,
)
from fha_studio.logic.modelcheck.consistency import Refused, set_verdict, settle
from fha_studio.logic.modelcheck.excitation import Excitation, excitation_of
from fha_studio.logic.modelcheck.linalg import block_cv, block_edges
from fha_studio.logic.modelcheck.resimulation import resimulate as resimulate_axis
from fha_studio.logic.modelcheck.result import (
    ABSENT,
    CHECKED,
    TOO_LITTLE_SIGNAL,
    Ambiguity,
    ChannelReport,
    ChannelStatus,
    ChannelWhere,
    DetectionLimit,
    Effect,
    Gap,
    ModelCheckResult,
    Structure,
    fmt,
)
from fha_studio.logic.modelcheck.selection import ChannelSelector, FittedTerm, Term
from fha_studio.logic.modelcheck.signals import (
    ARCSEC_PER_RAD,
    Signals,
    build_signals,
    noise_sigma,
    window_bounds,
)
from fha_studio.logic.modelcheck.structure import (
    binned,
    breakaways,
    bursts_in_time,
    structure_by_variable,
    where_variables,
)
from fha_studio.physics import AxisModel, Effects, ServoSettings
from fha_studio.recording import Recording

# Practical-significance floors (assumptions, stated in the report).
TORQUE_FLOOR_FRACTION_OF_MAX = 0.005  # 0.5 % of the actuator's maximum torque
TORQUE_FLOOR_MIN_NM = 0.02
POSITION_FLOOR_ARCSEC = 2.0
RESIM_MAX_S = 60.0  # the re-simulation covers at most this much of a recording (bounded cost)
# A channel is checked when what it shows (smoothed) stands this many noise sigmas above its noise.
SIGNAL_NOISE_FACTOR = 4.0
TARGET_DECIMATED = 2500  # about this many samples for the selection (speed), see run_modelcheck


@dataclass
class ChannelStep:
    """One channel as step 3 sees it: what is fitted, against what, above which floor."""

    channel: str
    ctx: ChannelContext
    y: np.ndarray  # the residual of the nominal model (analysis rate)
    candidates: tuple[Candidate, ...]
    floor: float
    base: np.ndarray  # nuisance columns, always fitted (decimated): not effects of the axis
    torque_nm: np.ndarray  # the torque acting on the channel, a variable of step 2 (analysis rate)
    nominal_first: tuple[str, ...] = ()  # the nominal parameters, tried before any effect
    zero_arbitrary: bool = False  # the residual's zero means nothing (an external encoder's): centred
    bursts: bool = False  # look for bursts in time (an unmeasured load acts on the torque)
    torque_is_cause: bool = True  # the measured torque contains the torque residual itself: not a cause
    max_torque_nm: float | None = None  # what the actuator can produce (a larger effect is refused)
    actuator: str = "the actuator"


@dataclass
class Selected:
    """A channel after step 3: the chosen terms, their fit, and the nuisance coefficients."""

    step: ChannelStep
    sel: ChannelSelector
    terms: list[Term]
    fitted: list[FittedTerm]
    fit: np.ndarray  # the fitted residual (decimated)
    base_beta: np.ndarray
    report: ChannelReport
    refused: list[Refused] = field(default_factory=list)
    cancelled: list[Structure] = field(default_factory=list)  # cancelling pairs, as structures


@dataclass
class Findings:
    """Steps 2-5 gathered over the channels (a look-alike found on one is known to the next)."""

    effects: list[Effect] = field(default_factory=list)
    ambiguities: list[Ambiguity] = field(default_factory=list)
    structures: list[Structure] = field(default_factory=list)
    limits: list[DetectionLimit] = field(default_factory=list)
    gaps: dict[str, Gap] = field(default_factory=dict)
    where: dict[str, ChannelWhere] = field(default_factory=dict)
    refused: list[Refused] = field(default_factory=list)


# ------------------------------------------------------------------------------------------ workflow


def run_modelcheck(
    rec: Recording, *, window: int | None = None, resimulate: bool = True, servo: ServoSettings | None = None
) -> ModelCheckResult:
    """Run the whole workflow on a recording. Raises ModelCheckError when it cannot be checked.

    window: Savitzky-Golay window in samples (None: chosen from the noise, see signals.py).
    servo: the drive's loop settings, when known; the re-simulation then drives the recorded
    cmd_pos through them. Without them (the usual case: a recording does not carry the gains) the
    re-simulation follows the measured motion (smoothed) with a stiff servo and feed-forward, so the
    overlay compares the models rather than a guess of the gains.
    """
    axis = declared_axis(rec)
    notes = check_plausible(rec, axis)
    if not rec.has_current:  # a bench capture: entry.run_modelcheck reads it through the closed loop
        raise ModelCheckError(
            "the recording has no current column: the torque channel needs the motor current"
        )
    model = axis.model
    sig, bandwidth, floor_t = _analysis_signals(rec, axis, window)
    if sig.resampled:
        notes.append("Note: the sampling was not uniform; the signals were resampled onto a uniform grid.")
    n = len(sig.t_s)
    # decimate the smoothed signals for the selection: about TARGET_DECIMATED samples, never below
    # two per smoothing window half-width (the smoothed band stays below the new Nyquist frequency)
    step = max(1, min(n // TARGET_DECIMATED, (sig.filt.window - 2) // 2))
    index = np.arange(0, n, step)

    # ---- step 1: residuals
    torque_nominal = axis.nominal_inertia_kgm2 * sig.accel_rad_s2
    residual: dict[str, np.ndarray] = {
        "t_s": sig.t_s,
        "torque_measured_nm": sig.torque_f_nm,
        "torque_nominal_nm": torque_nominal,
        "torque_residual_nm": sig.torque_f_nm - torque_nominal,
        "speed_rad_s": sig.speed_rad_s,
        "accel_rad_s2": sig.accel_rad_s2,
        "pos_rad": sig.pos_rad,
    }

    # ---- step 3, channel by channel: the torque first (the position channel needs its motor-side effects)
    status: dict[str, ChannelStatus] = {TORQUE: _torque_status(sig, axis, torque_nominal, floor_t)}
    excitation = excitation_of(sig)
    torque = _torque_step(sig, axis, residual["torque_residual_nm"], floor_t, index, excitation)
    chosen: list[Selected] = []
    delay_ms = 0.0
    sensor = sensor_torque_nm(rec, sig)
    if status[TORQUE].checked and sensor is not None:  # the gear and the load, each on its own
        for part in sensor_steps(torque, sensor, model, sig):
            chosen.append(_select(part, index))
            status[part.channel] = ChannelStatus(part.channel, CHECKED, "", _shows(part.y), "N m")
    elif status[TORQUE].checked:
        chosen.append(_select(torque, index))
        delay_ms = -1000.0 * float(chosen[0].base_beta[0])
        if abs(delay_ms) > 0.05:
            notes.append(
                f"Note: the current is {'late' if delay_ms > 0 else 'early'} against the position by "
                f"{abs(delay_ms):.2f} ms (fitted as a recorder property, not an effect of the axis)."
            )
    fitted_t = chosen[0].fitted if chosen else []
    status[POSITION], position = _position_step(sig, model, torque.ctx, fitted_t, residual, index)
    if position is not None:
        chosen.append(_select(position, index))

    # ---- name: effects, look-alikes, structure, detection limits; the gap on held-out data
    found = Findings()
    for s in chosen:
        _name(s, sig, index, step, found)
    notes.extend(_creep_notes(chosen, found))

    # ---- add: the updated model, named only when it is consistent with the recording
    updated = _updated_model(model, found.effects)
    resim = resimulate_axis(sig, axis, model, updated, servo, RESIM_MAX_S) if resimulate else None
    _hold_to_the_set(found, resim, floor_t)
    if len(found.effects) < len(_updated_effects(updated)):
        updated = _updated_model(model, found.effects)
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
        notes=notes,
        current_delay_ms=delay_ms,
        channel_status=status,
        window_reason=sig.window_reason,
        bandwidth_profile=() if bandwidth is None else bandwidth.profile,
        refused=found.refused,
        not_seen=excitation.lines() if status[TORQUE].checked else [],
    )


def _analysis_signals(
    rec: Recording, axis: DeclaredAxis, window: int | None
) -> tuple[Signals, BandwidthChoice | None, float]:
    """Step 1's signals at the analysis bandwidth (from the data unless ``window`` is given), the
    bandwidth choice, and the torque channel's practical floor."""
    model = axis.model
    sig = _signals(rec, axis, window)
    floor_t = max(
        TORQUE_FLOOR_MIN_NM,
        TORQUE_FLOOR_FRACTION_OF_MAX * (model.max_torque_nm or 3.0 * float(np.max(np.abs(sig.torque_f_nm)))),
    )
    bandwidth = None
    if (
        window is None
        and _torque_status(sig, axis, axis.nominal_inertia_kgm2 * sig.accel_rad_s2, floor_t).checked
    ):
        # the analysis bandwidth from the data: where the rigid model still explains the torque
        bandwidth = choose_bandwidth(
            pos_rad=sig.raw_pos_rad,
            current_a=sig.raw_current_a,
            dt_s=sig.filt.dt_s,
            kt_nm_per_a=axis.kt_nm_per_a,
            inertia_kgm2=axis.nominal_inertia_kgm2,
            ratio=axis.ratio,
            pos_noise_rad=sig.pos_noise_rad,
            current_noise_a=sig.current_noise_a,
            shortest=sig.filt.window,
            longest=window_bounds(len(sig.raw_t_s))[1],
            floor_nm=floor_t,
        )
        if bandwidth.window != sig.filt.window:
            sig = _signals(rec, axis, bandwidth.window)
        sig.window_reason = bandwidth.reason
    return sig, bandwidth, floor_t


def _torque_step(
    sig: Signals,
    axis: DeclaredAxis,
    y_nm: np.ndarray,
    floor_nm: float,
    index: np.ndarray,
    excitation: Excitation,
) -> ChannelStep:
    """The torque channel: Kt x current - J x acceleration, against the torque candidates the
    motion can show (``excitation``)."""
    # Nuisance, always fitted: a time offset between the current monitor and the encoder (sampling
    # instants, monitor delay) shows as -delay x J x jerk. It belongs to the recorder, not the axis.
    jerk_col = (axis.nominal_inertia_kgm2 * sig.jerk_rad_s3)[index][:, None]
    return ChannelStep(
        TORQUE,
        ChannelContext(
            sig, TORQUE, nominal_inertia_kgm2=axis.nominal_inertia_kgm2, pulse_rad=axis.model.output_pulse_rad
        ),
        y_nm,
        tuple(c for c in TORQUE_CANDIDATES if c.id not in excitation.excluded()),
        floor_nm,
        base=jerk_col,
        torque_nm=sig.torque_f_nm,
        nominal_first=tuple(c.id for c in TORQUE_CANDIDATES if c.nominal),
        bursts=True,
        torque_is_cause=False,
        max_torque_nm=axis.model.max_torque_nm or axis.model.peak_torque_nm,
        actuator=axis.code if axis.code != "custom" else "the declared axis",
    )


GEAR, LOAD = "gear torque", "load torque"
SIDE_WORDS = {GEAR: " in the gear", LOAD: " at the load"}


def sensor_torque_nm(rec: Recording, sig: Signals) -> np.ndarray | None:
    """The output torque sensor's column (N m), smoothed like the analysis, or None."""
    raw = rec.channels.get("torque")
    if raw is None:
        return None
    if sig.resampled:
        raw = np.interp(sig.raw_t_s, rec.t_s, raw)
    return sig.filt.apply(raw)


def sensor_steps(
    torque: ChannelStep, sensor_nm: np.ndarray, model: AxisModel, sig: Signals, gear: bool = True
) -> list[ChannelStep]:
    """With a torque sensor on the output flange the torque channel splits in two: the gear's
    (Kt x current - the flange's torque - the actuator's inertia x acceleration: friction, ripple)
    and the load's (the flange's torque - the load's inertia x acceleration: gravity, a load torque,
    an inertia error). ``gear``: False without a current (the load judged alone)."""
    j_load = model.load_inertia_kgm2
    j_gear = model.total_inertia_kgm2 - j_load
    y_load = sensor_nm - j_load * sig.accel_rad_s2
    steps = [
        replace(
            torque,
            channel=LOAD,
            y=y_load,
            candidates=tuple(c for c in torque.candidates if not c.motor_side and not c.only_as_alternative),
            torque_nm=sensor_nm,
            torque_is_cause=True,
        )
    ]
    if gear:
        y_gear = sig.torque_f_nm - sensor_nm - j_gear * sig.accel_rad_s2
        gear_candidates = tuple(c for c in torque.candidates if c.motor_side)
        steps.insert(0, replace(torque, channel=GEAR, y=y_gear, candidates=gear_candidates, nominal_first=()))
    return steps


def _position_step(
    sig: Signals,
    model: AxisModel,
    ctx_t: ChannelContext,
    fitted_t: list[FittedTerm],
    residual: dict[str, np.ndarray],
    index: np.ndarray,
) -> tuple[ChannelStatus, ChannelStep | None]:
    """The position channel (load_pos - pos, needs the load-side encoder) against the gear torque:
    its status, and the step when it is checked. Adds its residuals to ``residual``."""
    if sig.load_diff_f_rad is None:
        return ChannelStatus(
            POSITION,
            ABSENT,
            "is absent: the recording has no load-side encoder position (an external encoder on the load)",
        ), None
    motor_side = np.zeros(len(sig.t_s))
    for ft in fitted_t:
        cand = CANDIDATES[ft.id]
        if cand.motor_side:  # friction and ripple act before the gear: it does not carry them
            motor_side += cand.build(ctx_t, ft.shape) @ ft.beta
    gear_torque = sig.torque_f_nm - model.motor_side_inertia_kgm2 * sig.accel_rad_s2 - motor_side
    residual["gear_torque_nm"] = gear_torque
    y_pos = sig.load_diff_f_rad * ARCSEC_PER_RAD
    residual["load_diff_arcsec"] = y_pos
    status = _position_status(sig, y_pos)
    if not status.checked:
        return status, None
    breaks: list[float] = []
    if model.stiffness is not None:
        for t_break in (model.stiffness.t1_nm, model.stiffness.t2_nm):
            if np.mean(np.abs(gear_torque) > t_break) < 0.05:
                break  # too little data beyond it to see another region
            breaks.append(t_break)
    return status, ChannelStep(
        POSITION,
        ChannelContext(sig, POSITION, gear_torque_nm=gear_torque, breakpoints_nm=tuple(breaks)),
        y_pos,
        POSITION_CANDIDATES,
        POSITION_FLOOR_ARCSEC,
        base=np.ones((len(index), 1)),  # the external encoder's zero is not an effect
        torque_nm=gear_torque,
        zero_arbitrary=True,
    )


def _select(ch: ChannelStep, index: np.ndarray) -> Selected:
    """Step 3 on one channel: forward/backward selection, then the final fit."""
    unit = CHANNEL_UNITS[ch.channel]
    sel = ChannelSelector(ch.ctx, ch.y[index], ch.candidates, index, ch.floor, unit, base=ch.base)
    terms, steps = sel.select(nominal_first=ch.nominal_first)
    # every effect holds its floor, shape and the actuator's torque in the joint fit; cancelling
    # pairs are taken out as one structure (consistency.py)
    settled = settle(sel, terms, max_torque_nm=ch.max_torque_nm, actuator=ch.actuator)
    report = ChannelReport(ch.channel, unit, ch.floor, steps, settled.ar_order, len(index))
    total = max(float(np.mean(sel.y**2)), 1e-300)
    cancelled = [
        Structure(
            c.channel, c.variable, c.net_rms, min(c.net_rms**2 / total, 1.0), c.unit, c.spans,
            c.ids, c.sizes, c.at, c.variable_unit,
        )
        for c in settled.cancelling
    ]
    return Selected(
        ch, sel, settled.terms, settled.fitted, settled.fit, settled.base_beta, report,
        settled.refused, cancelled,
    )


def _name(s: Selected, sig: Signals, index: np.ndarray, step: int, found: Findings) -> None:
    """Steps 2-5 on one selected channel, into ``found``: its effects and look-alikes, the effects
    it could have revealed (detection limits), the structure no candidate explains, where the
    residual lies before and after, and the gap on held-out data."""
    ch, sel, terms = s.step.channel, s.sel, s.terms
    unit = CHANNEL_UNITS[ch]
    found.refused.extend(s.refused)
    found.structures.extend(s.cancelled)
    for a, b, dbic, alt_params in sel.substitutes(terms):
        found.ambiguities.append(Ambiguity(ch, a, b, dbic, separating_test(a, b), alt_params))
    for ft in s.fitted:
        alternatives = [amb.alternative for amb in found.ambiguities if ft.id in amb.chosen.split(" + ")]
        effect = _effect(ft, alternatives, found.ambiguities)
        if ch in SIDE_WORDS:  # an output torque sensor told the gear and the load apart
            effect.label += SIDE_WORDS[ch]
        found.effects.append(effect)
    chosen = {t.id for t in terms}
    for cand in sel.candidates:
        if cand.id in chosen or any(a.alternative == cand.id for a in found.ambiguities):
            continue
        size, _ = sel.detection_limit(terms, cand)
        found.limits.append(_limit(cand, ch, size, unit, sel))
    variables, var_units = where_variables(sig, index, s.step.torque_nm)
    after = sel.y - s.fit
    causes = {k: v for k, v in variables.items() if s.step.torque_is_cause or k != "torque"}
    block_len = max(30, 4 * sig.filt.window // step)
    by_variable = structure_by_variable(after, causes, sel.floor, block_len)
    if by_variable is not None:
        found.structures.append(Structure(ch, by_variable[0], by_variable[1], by_variable[2], unit))
    # an unmeasured load acts on the torque; the position channel's model errors (a dead band's
    # transitions) sit at reversals and would read as bursts there
    if s.step.bursts:
        length = max(5, 4 * sig.filt.window // step)
        bursts = bursts_in_time(after, sig.t_s[index], sel.floor, length, breakaways(s.step.ctx))
        if bursts is not None:
            found.structures.append(Structure(ch, "time", bursts[0], bursts[1], unit, bursts[2]))
    before = sel.y - np.median(sel.y) if s.step.zero_arbitrary else sel.y
    found.where[ch] = ChannelWhere(
        ch,
        unit,
        sig.t_s[index],
        before,
        after,
        variables,
        var_units,
        {k: binned(v, before, k, var_units[k]) for k, v in variables.items()},
        {k: binned(v, after, k, var_units[k]) for k, v in variables.items()},
    )
    found.gaps[ch] = _gap(sel, terms, ch, unit, sig.t_s[index])


def _creep_notes(chosen: list[Selected], found: Findings) -> list[str]:
    """One line for each effect left unnamed only because the creep into a target alone shows it
    (its last trial failed that gate): the drive's speed from whole encoder pulses, not the axis."""
    named = {e.id for e in found.effects}
    lines = []
    for s in chosen:
        last = {t.id: t for st in s.report.steps for t in st.trials}
        labels = {c.id: c for c in s.step.candidates}
        for trial in last.values():
            if trial.failed != ("creep",) or trial.id in named:
                continue
            cand = labels[trial.id]
            searched = "cycles_per_motor_rev" in cand.shape_names
            at = f" at {trial.shape[0]:.2f} cycles per motor turn" if searched else ""
            speed_rpm = s.step.ctx.quantised_below_rad_s * 60.0 / (2.0 * np.pi)
            lines.append(
                f"Note: {cand.label.lower()} ({trial.size:.3g} {s.report.unit}{at}) is not named: only "
                "the creep into a target shows it, where the drive counts fewer than "
                f"{QUANTISED_PULSES_PER_PERIOD:g} encoder pulses per servo period (below {speed_rpm:.2g} "
                "r/min at the output) and its speed loop makes a current pattern of its own."
            )
    return lines


def _signals(rec: Recording, axis: DeclaredAxis, window: int | None) -> Signals:
    """Step 1's analysis signals; a window the recording cannot support is a ModelCheckError."""
    try:
        return build_signals(
            rec.t_s,
            np.radians(rec.pos_deg),
            rec.current_a,
            kt_nm_per_a=axis.kt_nm_per_a,
            inertia_kgm2=axis.nominal_inertia_kgm2,
            ratio=axis.ratio,
            load_pos_rad=None if rec.load_pos_deg is None else np.radians(rec.load_pos_deg),
            cmd_pos_rad=None if rec.cmd_pos_deg is None else np.radians(rec.cmd_pos_deg),
            window=window,
        )
    except ValueError as exc:
        raise ModelCheckError(str(exc)) from None


def _shows(x: np.ndarray) -> float:
    """What a smoothed channel shows at most: the 99.5th percentile of its distance from its median."""
    return float(np.percentile(np.abs(x - np.median(x)), 99.5)) if len(x) else 0.0


def _torque_status(
    sig: Signals, axis: DeclaredAxis, nominal_nm: np.ndarray, floor_nm: float
) -> ChannelStatus:
    """The torque channel has too little signal when neither the measured torque (Kt x current) nor
    the torque the nominal model needs rises above the practical floor and the smoothed monitor
    noise: nothing an effect could add would then stand out."""
    noise = axis.kt_nm_per_a * sig.current_noise_a * sig.filt.noise_gain
    level = max(floor_nm, SIGNAL_NOISE_FACTOR * noise)
    shown = max(_shows(sig.torque_f_nm), _shows(nominal_nm))
    if shown >= level:
        return ChannelStatus(TORQUE, CHECKED, "", shown, "N m")
    return ChannelStatus(
        TORQUE,
        TOO_LITTLE_SIGNAL,
        f"shows nothing above {fmt(level)} N m (measured {fmt(shown)} N m at most; the current "
        f"monitor's noise is {fmt(sig.current_noise_a)} A per sample)",
        level,
        "N m",
    )


def _position_status(sig: Signals, y_arcsec: np.ndarray) -> ChannelStatus:
    """The position channel has too little signal when load_pos - pos stays within the practical
    floor and the smoothed noise of the two encoders."""
    raw = sig.raw_load_pos_rad - sig.raw_pos_rad if sig.raw_load_pos_rad is not None else np.zeros(1)
    noise = noise_sigma(raw) * ARCSEC_PER_RAD * sig.filt.noise_gain
    level = max(POSITION_FLOOR_ARCSEC, SIGNAL_NOISE_FACTOR * noise)
    shown = _shows(y_arcsec)
    if shown >= level:
        return ChannelStatus(POSITION, CHECKED, "", shown, "arcsec")
    return ChannelStatus(
        POSITION,
        TOO_LITTLE_SIGNAL,
        f"shows nothing above {fmt(level)} arcsec between the load and motor encoders "
        f"({fmt(shown)} arcsec at most)",
        level,
        "arcsec",
    )


def _effect(ft: FittedTerm, alternatives: list[str], ambiguities: list[Ambiguity]) -> Effect:
    params = {p.name: p.value for p in ft.params}
    sig = {p.name: p.std for p in ft.params}
    units = {p.name: p.unit for p in ft.params}
    if alternatives:
        test = next(a.separating_test for a in ambiguities if ft.id in a.chosen.split(" + "))
        advice = f"the data cannot tell it from {' or '.join(label_of(a) for a in alternatives)}: {test}"
    else:
        advice = CANDIDATES[ft.id].advice(params)
    return Effect(ft.id, ft.channel, ft.label, params, sig, units, ft.size, alternatives, advice)


def _limit(cand: Candidate, ch: str, size: float, unit: str, sel: ChannelSelector) -> DetectionLimit:
    value = cand.limit_in_param(size, sel.ctx)
    return DetectionLimit(cand.id, ch, size, unit, cand.primary, value, cand.primary_unit or unit)


def _gap(sel: ChannelSelector, terms, ch: str, unit: str, t: np.ndarray) -> Gap:
    y = sel.y
    base = sel.design([])
    before, pred0 = block_cv(y, base)
    after, pred = block_cv(y, sel.design(terms))
    measured = y - pred0 if base.shape[1] else y
    edges = block_edges(len(y))
    return Gap(
        ch, unit, before, after, t, measured, pred - pred0, [(float(t[a]), float(t[b - 1])) for a, b in edges]
    )


def _hold_to_the_set(found: Findings, resim, floor_nm: float) -> None:
    """The named set as a whole: per channel, it must shrink the held-out gap; over the axis, its
    re-simulation must not be worse than the nominal model's. Otherwise nothing of it is named."""
    for ch, gap in found.gaps.items():
        mine = [e for e in found.effects if e.channel == ch]
        why = set_verdict(resim_nominal=None, resim_updated=None, floor=floor_nm,
                          gaps=[(ch, gap.rms_before, gap.rms_after, gap.unit)]) if mine else ""
        if why:
            _refuse_all(found, mine, why)
    if resim is not None and found.effects:
        why = set_verdict(resim_nominal=resim.rms_nominal_nm, resim_updated=resim.rms_updated_nm,
                          floor=floor_nm, gaps=[])
        if why:
            _refuse_all(found, list(found.effects), why)


def _refuse_all(found: Findings, effects: list[Effect], why: str) -> None:
    names = " + ".join(e.label.lower() for e in effects)
    for e in effects:
        found.refused.append(
            Refused(e.id, e.channel, e.label, dict(e.params), e.size, CHANNEL_UNITS[e.channel],
                    f"the set {names} is not named: {why}")
        )
    gone = {id(e) for e in effects}
    found.effects[:] = [e for e in found.effects if id(e) not in gone]
    found.ambiguities[:] = [a for a in found.ambiguities if any(e.id in a.chosen.split(" + ")
                                                                for e in found.effects)]


def _updated_effects(model: AxisModel) -> list[str]:
    return [e["id"] for e in model.effects.to_list()]


def _updated_model(model: AxisModel, effects: list[Effect]) -> AxisModel:
    e = Effects()
    for eff in effects:
        params = CANDIDATES[eff.id].model_params(dict(eff.params), model)
        if params is not None:
            e = e.with_effect(eff.id, **params)
    return model.with_effects(e)


__all__ = ["ModelCheckError", "ModelCheckResult", "Param", "run_modelcheck"]
