"""The model-check workflow: residuals -> where -> name -> add -> gap. Results are arrays per step."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.signal import savgol_filter

from fha_studio.logic.modelcheck.axis import (
    DeclaredAxis,
    ModelCheckError,
    check_plausible,
    declared_axis,
    rms,
)
from fha_studio.logic.modelcheck.bandwidth import BandwidthPoint, choose_bandwidth
from fha_studio.logic.modelcheck.candidates import (
    CANDIDATES,
    CHANNEL_UNITS,
    LABELS,
    PARAM_WORDS,
    POSITION,
    POSITION_CANDIDATES,
    TORQUE,
    TORQUE_CANDIDATES,
    Candidate,
    ChannelContext,
    Param,
    label_of,
    separating_test,
)
from fha_studio.logic.modelcheck.selection import (
    BIC_MIN,
    ChannelSelector,
    FittedTerm,
    SelectionStep,
    Term,
    block_cv,
    block_edges,
)
from fha_studio.logic.modelcheck.signals import (
    ARCSEC_PER_RAD,
    POLYORDER,
    Signals,
    build_signals,
    window_bounds,
)
from fha_studio.logic.wording import unit_words
from fha_studio.physics import AxisModel, Effects, ServoSettings, simulate
from fha_studio.recording import Recording

# Practical-significance floors (assumptions, stated in the report).
TORQUE_FLOOR_FRACTION_OF_MAX = 0.005  # 0.5 % of the actuator's maximum torque
TORQUE_FLOOR_MIN_NM = 0.02
POSITION_FLOOR_ARCSEC = 2.0
STRUCTURE_MIN_FRACTION = 0.15  # a structured residual explains >= 15 % of the residual's variance
BURST_FACTOR = 6.0  # a burst in time: local RMS this many times the residual's median local RMS
BURST_FLOOR_FACTOR = 3.0  # ... and above this many practical floors
BREAKAWAY_SETTLE_S = 0.1  # a burst peaking this soon after a breakaway from standstill is stick-slip
BURST_EDGE_FACTOR = 3.0  # ... and it lasts while the local RMS stays above this many times the median
RESIM_MAX_S = 60.0  # the re-simulation covers at most this much of a recording (bounded cost)
RESIM_BANDWIDTH_HZ = 60.0  # speed-loop bandwidth of the stiff servo that follows the measured motion
# A channel is checked when what it shows (smoothed) stands this many noise sigmas above its noise.
SIGNAL_NOISE_FACTOR = 4.0
TARGET_DECIMATED = 2500  # about this many samples for the selection (speed), see run_modelcheck


# ------------------------------------------------------------------------------------ result types


@dataclass
class Binned:
    """A residual binned against one variable (what a person plots to see the effect)."""

    variable: str
    unit: str
    centers: np.ndarray
    mean: np.ndarray  # mean residual per bin (channel unit)
    sem: np.ndarray  # standard error of the mean per bin
    count: np.ndarray


@dataclass
class ChannelWhere:
    """Step 2 for one channel: the residual against time and the state variables, before and after."""

    channel: str
    unit: str
    t_s: np.ndarray  # decimated times
    residual_before: np.ndarray  # nominal model
    residual_after: np.ndarray  # updated model (in-sample)
    variables: dict[str, np.ndarray]  # decimated variable values (for scatter plots)
    variable_units: dict[str, str]
    before: dict[str, Binned]
    after: dict[str, Binned]


@dataclass
class Effect:
    """A named missing effect (step 3/4)."""

    id: str
    channel: str
    label: str
    params: dict[str, float]
    uncertainty: dict[str, float]  # one sigma, same keys
    units: dict[str, str]
    size: float  # typical magnitude in the channel unit
    alternatives: list[str] = field(default_factory=list)  # not separable from these
    advice: str = ""  # one line for a person: what to do next

    def to_json(self) -> dict[str, Any]:
        return {
            "id": self.id,
            "params": dict(self.params),
            "channel": self.channel,
            "uncertainty": dict(self.uncertainty),
            "units": dict(self.units),
            "label": self.label,
            "size": self.size,
            "not_separable_from": list(self.alternatives),
            "what_to_do_next": self.advice,
        }


@dataclass
class Ambiguity:
    """Two effects the data cannot tell apart, and the test that would."""

    channel: str
    chosen: str
    alternative: str
    delta_bic: float
    separating_test: str
    alternative_params: dict[str, float] = field(default_factory=dict)  # the alternative, fitted in its place


@dataclass
class Structure:
    """A structured residual that no candidate explains."""

    channel: str
    variable: str
    rms: float  # of the part explained by the variable, held-out (variable "time": within the bursts)
    fraction: float  # of the residual variance
    unit: str
    spans: list[tuple[float, float, float]] = field(default_factory=list)  # "time": (start s, end s, peak)


@dataclass
class DetectionLimit:
    """Smallest effect of one kind this recording could have revealed."""

    id: str
    channel: str
    size: float  # channel unit
    unit: str
    param: str
    value: float  # in the param's unit
    param_unit: str


@dataclass
class Gap:
    """Step 5: RMS gap on held-out contiguous segments (each predicted from a fit on the others)."""

    channel: str
    unit: str
    rms_before: float
    rms_after: float
    t_s: np.ndarray
    measured: np.ndarray  # residual of the nominal model (what the updated model must explain)
    predicted_heldout: np.ndarray  # the updated model's held-out prediction of it
    blocks: list[tuple[float, float]]  # time spans of the held-out blocks


@dataclass
class Resimulation:
    """The recorded command re-simulated with the nominal and the updated model, over the measurement."""

    t_s: np.ndarray
    torque_measured_nm: np.ndarray  # Kt x current (smoothed like the analysis)
    torque_nominal_nm: np.ndarray
    torque_updated_nm: np.ndarray
    pos_measured_deg: np.ndarray
    pos_nominal_deg: np.ndarray
    pos_updated_deg: np.ndarray
    rms_nominal_nm: float
    rms_updated_nm: float
    load_diff_measured_arcsec: np.ndarray | None = None
    load_diff_nominal_arcsec: np.ndarray | None = None
    load_diff_updated_arcsec: np.ndarray | None = None
    command: str = "cmd_pos"  # which column drove it ("cmd_pos", or "pos" when no command was recorded)


@dataclass
class ChannelReport:
    """Steps 3-5 of one channel."""

    channel: str
    unit: str
    floor: float
    steps: list[SelectionStep]
    ar_order: int
    n_samples: int


CHECKED = "checked"
TOO_LITTLE_SIGNAL = "too little signal"
ABSENT = "absent"


@dataclass(frozen=True)
class ChannelStatus:
    """Whether a channel was checked, and why not: "checked" | "too little signal" | "absent"."""

    channel: str
    status: str
    reason: str
    level: float = 0.0  # channel unit: what the channel shows at most (too little signal)
    unit: str = ""

    @property
    def checked(self) -> bool:
        return self.status == CHECKED

    def to_json(self) -> dict[str, Any]:
        return {"status": self.status, "reason": self.reason, "level": self.level, "unit": self.unit}


@dataclass
class ModelCheckResult:
    """Everything the model check found, per step, as arrays a GUI can plot."""

    source: str
    actuator: str
    window_samples: int
    window_s: float
    bandwidth_hz: float
    residual: dict[str, np.ndarray]  # step 1, analysis rate: t_s, torque_measured_nm, torque_nominal_nm, ...
    where: dict[str, ChannelWhere]  # step 2
    channels: dict[str, ChannelReport]  # step 3 (selection steps)
    effects: list[Effect]  # steps 3-4
    ambiguities: list[Ambiguity]
    structures: list[Structure]
    detection_limits: list[DetectionLimit]
    gap: dict[str, Gap]  # step 5
    nominal_model: AxisModel
    updated_model: AxisModel  # step 4
    resimulation: Resimulation | None
    notes: list[str]
    current_delay_ms: float = 0.0  # fitted time offset of the current against the position (recorder)
    channel_status: dict[str, ChannelStatus] = field(default_factory=dict)
    window_reason: str = ""  # why this analysis bandwidth
    bandwidth_profile: tuple[BandwidthPoint, ...] = ()  # the bandwidths tried and what each left unexplained

    @property
    def found(self) -> bool:
        return bool(self.effects)

    def summary_lines(self, manual_units: bool = False) -> list[str]:
        """The human summary (one finding per line). ``manual_units``: units as the FHA-C manual
        prints them (N·m, kg·m²) and "→" for a change, for a page and the register; the default
        keeps plain ASCII for a terminal and a log (:mod:`fha_studio.logic.wording`)."""
        unit = unit_words if manual_units else str
        to = " → " if manual_units else " -> "
        lines = self._status_lines()
        by_channel: dict[str, Effect] = {}
        for e in self.effects:
            by_channel.setdefault(e.channel, e)
        for e in self.effects:
            p = next(iter(e.params))
            main = _fmt_pm(e.params[p], e.uncertainty[p], unit(e.units[p]))
            others = ", ".join(
                f"{PARAM_WORDS.get(k, k)} {_fmt_pm(v, e.uncertainty[k], unit(e.units[k]))}"
                for k, v in e.params.items()
                if k != p
            )
            text = f"{e.label} missing: {main}" + (f" ({others})" if others else "")
            if e.alternatives:
                alts = " or ".join(label_of(a) for a in e.alternatives)
                text = f"{e.label} or {alts} — not separable from this data; as {e.label.lower()}: {main}"
            gap = self.gap.get(e.channel)
            if gap is not None and by_channel.get(e.channel) is e:
                text += (
                    f"; {e.channel} gap {_fmt(gap.rms_before)}{to}{_fmt(gap.rms_after)} {unit(gap.unit)} rms "
                    "on held-out data"
                )
            lines.append(text)
        for a in self.ambiguities:
            as_alt = ", ".join(f"{PARAM_WORDS.get(k, k)} {_fmt(v)}" for k, v in a.alternative_params.items())
            lines.append(
                f"  {label_of(a.chosen)} or {label_of(a.alternative)}"
                + (f" ({as_alt})" if as_alt else "")
                + " — not separable from this data; "
                f"to separate them: {a.separating_test}"
            )
        for s in self.structures:
            if s.variable == "time":
                where = ", ".join(f"{a:.2f}-{b:.2f} s" for a, b, _ in s.spans[:6])
                more = f" and {len(s.spans) - 6} more" if len(s.spans) > 6 else ""
                peak = max(p for _, _, p in s.spans)
                lines.append(
                    f"Structured residual in the {s.channel} channel that no candidate explains: "
                    f"{len(s.spans)} burst{'s' if len(s.spans) > 1 else ''} up to "
                    f"{_fmt(peak)} {unit(s.unit)} at t = {where}{more} ({100 * s.fraction:.0f} % of the "
                    "residual): a disturbance the recording does not measure; not forced onto a named effect"
                )
                continue
            lines.append(
                f"Structured residual in the {s.channel} channel that no candidate explains: "
                f"{_fmt(s.rms)} {unit(s.unit)} rms organised by {s.variable.replace('_', ' ')} "
                f"({100 * s.fraction:.0f} % of the residual); not forced onto a named effect"
            )
        if not self.effects and any(st.checked for st in self.channel_status.values()):
            lines.append("No missing effect found.")
            for ch, gap in self.gap.items():
                lines.append(
                    f"  {ch} gap {_fmt(gap.rms_before)}{to}{_fmt(gap.rms_after)} {unit(gap.unit)} rms "
                    "on held-out data"
                )
        if self.detection_limits:
            limits = ", ".join(
                f"{LABELS[d.id]} ±{100 * d.value:.2g} %"
                if d.param_unit == "1"  # a ratio's distance from 1
                else f"{LABELS[d.id]} {_fmt(d.value)} {unit(d.param_unit)}"
                for d in self.detection_limits
            )
            lines.append(f"Detection limit (smallest effect this recording could have revealed): {limits}")
        if self.resimulation is not None:
            r = self.resimulation
            lines.append(
                f"Re-simulation of the recorded {r.command}: torque {_fmt(r.rms_nominal_nm)}{to}"
                f"{_fmt(r.rms_updated_nm)} {unit('N m')} rms (nominal{to}updated model)"
            )
        lines.extend(self.notes)
        return lines

    def _status_lines(self) -> list[str]:
        """One line per channel that was not checked, and what was checked instead."""
        skipped = [st for st in self.channel_status.values() if not st.checked]
        if not skipped:
            return []
        checked = [ch for ch, st in self.channel_status.items() if st.checked]
        if checked:
            rest = f"only the {' and '.join(checked)} channel{'s are' if len(checked) > 1 else ' is'} checked"
        else:
            rest = "nothing is checked; record a move with more acceleration, speed or load"
        return [
            f"The {st.channel} channel {st.reason}: {rest}." for st in skipped if st.status != ABSENT
        ] or ([f"Nothing is checked: {'; '.join(st.reason for st in skipped)}."] if not checked else [])

    def to_json(self) -> dict[str, Any]:
        """The JSON report (``fha-modelcheck-report/1``: effects [{id, params, channel}], gap
        {channel: {...}}); other tools read it, so its keys change only with the format id."""
        return {
            "format": "fha-modelcheck-report/1",
            "recording": self.source,
            "actuator": self.actuator,
            "bandwidth_hz": self.bandwidth_hz,
            "bandwidth_reason": self.window_reason,
            "channels": {ch: st.to_json() for ch, st in self.channel_status.items()},
            "effects": [e.to_json() for e in self.effects],
            "gap": {
                ch: {"rms_before": g.rms_before, "rms_after": g.rms_after, "unit": g.unit}
                for ch, g in self.gap.items()
            },
            "not_separable": [
                {
                    "channel": a.channel,
                    "ids": [a.chosen, a.alternative],
                    "separating_test": a.separating_test,
                    "alternative_params": dict(a.alternative_params),
                }
                for a in self.ambiguities
            ],
            "structured_residual": [
                {
                    "channel": s.channel,
                    "variable": s.variable,
                    "rms": s.rms,
                    "fraction": s.fraction,
                    "unit": s.unit,
                    "spans_s": [[a, b] for a, b, _ in s.spans],
                    "peaks": [peak for _, _, peak in s.spans],
                }
                for s in self.structures
            ],
            "detection_limits": [
                {
                    "id": d.id,
                    "channel": d.channel,
                    "param": d.param,
                    "value": d.value,
                    "unit": d.param_unit,
                    "size": d.size,
                    "size_unit": d.unit,
                }
                for d in self.detection_limits
            ],
            "analysis": {
                "savgol_window_samples": self.window_samples,
                "savgol_window_s": self.window_s,
                "bandwidth_hz": self.bandwidth_hz,
                "floors": {ch: {"value": c.floor, "unit": c.unit} for ch, c in self.channels.items()},
                "criterion": f"AR-whitened BIC gain >= {BIC_MIN:g}, contiguous-block CV, floor",
                "current_delay_ms": self.current_delay_ms,
                "bandwidths_tried": [
                    {
                        "bandwidth_hz": b.bandwidth_hz,
                        "window_samples": b.window,
                        "unexplained_nm": b.unexplained_nm,
                    }
                    for b in self.bandwidth_profile
                ],
            },
            "resimulation": None
            if self.resimulation is None
            else {
                "command": self.resimulation.command,
                "torque_rms_nominal_nm": self.resimulation.rms_nominal_nm,
                "torque_rms_updated_nm": self.resimulation.rms_updated_nm,
            },
            "notes": list(self.notes),
        }

    def write_model(self, path: str | Path) -> None:
        """Write the updated model file (fha-axis-model/1 TOML, loadable by the sim and later checks)."""
        self.updated_model.save(path)


def _fmt(x: float) -> str:
    if x == 0 or not math.isfinite(x):
        return f"{x:g}"
    digits = max(0, 2 - math.floor(math.log10(abs(x))))
    return f"{x:.{min(digits, 6)}f}" if abs(x) < 1e5 else f"{x:.3g}"


def _fmt_pm(value: float, sigma: float, unit: str) -> str:
    unit = "" if unit in ("1", "1/rev") else unit  # a ratio, or cycles per motor turn (said in words)
    if not math.isfinite(sigma) or sigma <= 0:
        return f"{_fmt(value)} {unit}".rstrip()
    digits = max(0, -math.floor(math.log10(sigma)))
    if abs(value) >= 1e5:
        return f"{value:.4g} {unit} ± {sigma:.2g}".replace("  ", " ")
    return f"{value:.{min(digits, 8)}f} {unit} ± {sigma:.{min(digits, 8)}f}".replace("  ", " ")


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
    if sig.resampled:
        notes.append("Note: the sampling was not uniform; the signals were resampled onto a uniform grid.")
    n = len(sig.t_s)
    # decimate the smoothed signals for the selection: about TARGET_DECIMATED samples, never below
    # two per smoothing window half-width (the smoothed band stays below the new Nyquist frequency)
    step = max(1, min(n // TARGET_DECIMATED, (sig.filt.window - 2) // 2))
    index = np.arange(0, n, step)

    # ---- step 1: residuals
    torque_nominal = axis.nominal_inertia_kgm2 * sig.accel_rad_s2
    y_torque = sig.torque_f_nm - torque_nominal
    residual: dict[str, np.ndarray] = {
        "t_s": sig.t_s,
        "torque_measured_nm": sig.torque_f_nm,
        "torque_nominal_nm": torque_nominal,
        "torque_residual_nm": y_torque,
        "speed_rad_s": sig.speed_rad_s,
        "accel_rad_s2": sig.accel_rad_s2,
        "pos_rad": sig.pos_rad,
    }

    # ---- step 3 on the torque channel
    status: dict[str, ChannelStatus] = {TORQUE: _torque_status(sig, axis, torque_nominal, floor_t)}
    channels: dict[str, ChannelReport] = {}
    selectors: dict[str, tuple[ChannelSelector, list[Term], list[FittedTerm], np.ndarray]] = {}
    ctx_t = ChannelContext(sig, TORQUE, nominal_inertia_kgm2=axis.nominal_inertia_kgm2)
    fitted_t: list[FittedTerm] = []
    delay_ms = 0.0
    if status[TORQUE].checked:
        # Nuisance, always fitted: a time offset between the current monitor and the encoder (sampling
        # instants, monitor delay) shows as -delay x J x jerk. It belongs to the recorder, not the axis.
        jerk_col = (axis.nominal_inertia_kgm2 * sig.jerk_rad_s3)[index][:, None]
        sel_t = ChannelSelector(
            ctx_t, y_torque[index], TORQUE_CANDIDATES, index, floor_t, CHANNEL_UNITS[TORQUE], base=jerk_col
        )
        terms_t, steps_t = sel_t.select(nominal_first=tuple(c.id for c in TORQUE_CANDIDATES if c.nominal))
        fitted_t, fit_t, base_t, ar_t = sel_t.final_fit(terms_t)
        delay_ms = -1000.0 * float(base_t[0])
        if abs(delay_ms) > 0.05:
            notes.append(
                f"Note: the current is {'late' if delay_ms > 0 else 'early'} against the position by "
                f"{abs(delay_ms):.2f} ms (fitted as a recorder property, not an effect of the axis)."
            )
        channels[TORQUE] = ChannelReport(TORQUE, "N m", floor_t, steps_t, ar_t, len(index))
        selectors[TORQUE] = (sel_t, terms_t, fitted_t, fit_t)

    # ---- position channel (needs load_pos)
    if sig.load_diff_f_rad is None:
        status[POSITION] = ChannelStatus(
            POSITION,
            ABSENT,
            "is absent: the recording has no load-side encoder position (an external encoder on the load)",
        )
    else:
        motor_side = np.zeros(n)
        for ft in fitted_t:
            cand = CANDIDATES[ft.id]
            if cand.motor_side:  # friction and ripple act before the gear: it does not carry them
                motor_side += cand.build(ctx_t, ft.shape) @ ft.beta
        gear_torque = sig.torque_f_nm - model.motor_side_inertia_kgm2 * sig.accel_rad_s2 - motor_side
        residual["gear_torque_nm"] = gear_torque
        y_pos = sig.load_diff_f_rad * ARCSEC_PER_RAD
        residual["load_diff_arcsec"] = y_pos
        status[POSITION] = _position_status(sig, y_pos)
    if status[POSITION].checked:
        breaks: list[float] = []
        if model.stiffness is not None:
            for t_break in (model.stiffness.t1_nm, model.stiffness.t2_nm):
                if np.mean(np.abs(gear_torque) > t_break) < 0.05:
                    break  # too little data beyond it to see another region
                breaks.append(t_break)
        ctx_p = ChannelContext(sig, POSITION, gear_torque_nm=gear_torque, breakpoints_nm=tuple(breaks))
        base = np.ones((len(index), 1))  # the external encoder's zero is not an effect
        sel_p = ChannelSelector(
            ctx_p,
            y_pos[index],
            POSITION_CANDIDATES,
            index,
            POSITION_FLOOR_ARCSEC,
            CHANNEL_UNITS[POSITION],
            base=base,
        )
        terms_p, steps_p = sel_p.select()
        fitted_p, fit_p, _base_beta, ar_p = sel_p.final_fit(terms_p)
        channels[POSITION] = ChannelReport(
            POSITION, "arcsec", POSITION_FLOOR_ARCSEC, steps_p, ar_p, len(index)
        )
        selectors[POSITION] = (sel_p, terms_p, fitted_p, fit_p)

    # ---- name: effects, look-alikes, structure, detection limits
    effects: list[Effect] = []
    ambiguities: list[Ambiguity] = []
    structures: list[Structure] = []
    limits: list[DetectionLimit] = []
    gaps: dict[str, Gap] = {}
    where: dict[str, ChannelWhere] = {}
    for ch, (sel, terms, fitted, fit) in selectors.items():
        unit = CHANNEL_UNITS[ch]
        for a, b, dbic, alt_params in sel.substitutes(terms):
            ambiguities.append(Ambiguity(ch, a, b, dbic, separating_test(a, b), alt_params))
        for ft in fitted:
            alternatives = [amb.alternative for amb in ambiguities if ft.id in amb.chosen.split(" + ")]
            effects.append(_effect(ft, alternatives, ambiguities))
        chosen = {t.id for t in terms}
        for cand in sel.candidates:
            if cand.id in chosen or any(a.alternative == cand.id for a in ambiguities):
                continue
            size, _ = sel.detection_limit(terms, cand)
            limits.append(_limit(cand, ch, size, unit, sel))
        variables, var_units = _where_variables(sig, index, ch, residual)
        after = sel.y - fit
        # in the torque channel the measured torque contains the residual itself: not a cause
        candidates_vars = {k: v for k, v in variables.items() if not (ch == TORQUE and k == "torque")}
        block_len = max(30, 4 * sig.filt.window // step)
        s = _structure(after, candidates_vars, sel.floor, block_len)
        if s is not None:
            structures.append(Structure(ch, s[0], s[1], s[2], unit))
        # an unmeasured load acts on the torque; the position channel's model errors (a dead band's
        # transitions) sit at reversals and would read as bursts there
        bursts = (
            _bursts_in_time(
                after, sig.t_s[index], sel.floor, max(5, 4 * sig.filt.window // step), _breakaways(ctx_t)
            )
            if ch == TORQUE
            else None
        )
        if bursts is not None:
            structures.append(Structure(ch, "time", bursts[0], bursts[1], unit, bursts[2]))
        where[ch] = ChannelWhere(
            ch,
            unit,
            sig.t_s[index],
            sel.y if ch == TORQUE else sel.y - np.median(sel.y),
            after,
            variables,
            var_units,
            {
                k: _bin(v, sel.y - (np.median(sel.y) if ch == POSITION else 0.0), k, var_units[k])
                for k, v in variables.items()
            },
            {k: _bin(v, after, k, var_units[k]) for k, v in variables.items()},
        )
        gaps[ch] = _gap(sel, terms, ch, unit, sig.t_s[index])

    # ---- add: the updated model
    updated = _updated_model(model, effects)
    resim = None
    if resimulate:
        resim = _resimulate(sig, axis, model, updated, servo)
    filt = sig.filt
    return ModelCheckResult(
        source=rec.source,
        actuator=axis.code,
        window_samples=filt.window,
        window_s=filt.window * filt.dt_s,
        bandwidth_hz=filt.bandwidth_hz,
        residual=residual,
        where=where,
        channels=channels,
        effects=effects,
        ambiguities=ambiguities,
        structures=structures,
        detection_limits=limits,
        gap=gaps,
        nominal_model=model,
        updated_model=updated,
        resimulation=resim,
        notes=notes,
        current_delay_ms=delay_ms,
        channel_status=status,
        window_reason=sig.window_reason,
        bandwidth_profile=() if bandwidth is None else bandwidth.profile,
    )


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
        f"shows nothing above {_fmt(level)} N m (measured {_fmt(shown)} N m at most; the current "
        f"monitor's noise is {_fmt(sig.current_noise_a)} A per sample)",
        level,
        "N m",
    )


def _position_status(sig: Signals, y_arcsec: np.ndarray) -> ChannelStatus:
    """The position channel has too little signal when load_pos - pos stays within the practical
    floor and the smoothed noise of the two encoders."""
    raw = sig.raw_load_pos_rad - sig.raw_pos_rad if sig.raw_load_pos_rad is not None else np.zeros(1)
    from fha_studio.logic.modelcheck.signals import noise_sigma

    noise = noise_sigma(raw) * ARCSEC_PER_RAD * sig.filt.noise_gain
    level = max(POSITION_FLOOR_ARCSEC, SIGNAL_NOISE_FACTOR * noise)
    shown = _shows(y_arcsec)
    if shown >= level:
        return ChannelStatus(POSITION, CHECKED, "", shown, "arcsec")
    return ChannelStatus(
        POSITION,
        TOO_LITTLE_SIGNAL,
        f"shows nothing above {_fmt(level)} arcsec between the load and motor encoders "
        f"({_fmt(shown)} arcsec at most)",
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


def _where_variables(sig: Signals, index: np.ndarray, ch: str, residual: dict[str, np.ndarray]):
    variables = {
        "time": sig.t_s[index],
        "speed": sig.speed_rad_s[index] * 30.0 / math.pi,
        "position": np.degrees(sig.pos_rad[index]),
        "acceleration": sig.accel_rad_s2[index],
        "torque": (residual["gear_torque_nm"] if ch == POSITION else sig.torque_f_nm)[index],
    }
    units = {"time": "s", "speed": "r/min", "position": "deg", "acceleration": "rad/s^2", "torque": "N m"}
    if sig.ratio is not None:
        variables["motor_angle"] = np.degrees(np.mod(sig.ratio * sig.pos_rad[index], 2.0 * math.pi))
        units["motor_angle"] = "deg"
    return variables, units


def _bin(x: np.ndarray, y: np.ndarray, name: str, unit: str, bins: int = 24) -> Binned:
    lo, hi = np.percentile(x, [0.5, 99.5]) if name != "motor_angle" else (0.0, 360.0)
    if hi <= lo:
        hi = lo + 1e-9
    edges = np.linspace(lo, hi, bins + 1)
    which = np.clip(np.digitize(x, edges) - 1, 0, bins - 1)
    count = np.bincount(which, minlength=bins).astype(float)
    s = np.bincount(which, weights=y, minlength=bins)
    s2 = np.bincount(which, weights=y * y, minlength=bins)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0, s / np.maximum(count, 1), np.nan)
        var = np.where(count > 1, (s2 - count * mean**2) / np.maximum(count - 1, 1), np.nan)
        sem = np.sqrt(np.maximum(var, 0) / np.maximum(count, 1))
    return Binned(name, unit, 0.5 * (edges[:-1] + edges[1:]), mean, sem, count)


def _structure(
    e: np.ndarray, variables: dict[str, np.ndarray], floor: float, block_len: int = 50
) -> tuple[str, float, float] | None:
    """Residual organised by a state variable, confirmed on held-out blocks.

    Leave-one-block-out over contiguous blocks a few filter windows long (neighbours within a block
    are near copies): each block is predicted by the residual's bin means (against the variable)
    over all other blocks. The held-out prediction must explain at least STRUCTURE_MIN_FRACTION of
    the residual variance and reach the practical floor somewhere (the largest bin mean): a local
    bump matters even when its RMS over the whole record is small.
    """
    n = len(e)
    nbins = 32
    total = float(np.mean(e**2))
    if total <= 0:
        return None
    edges = block_edges(n, max(4, n // block_len))
    block_of = np.zeros(n, int)
    for k, (a, b) in enumerate(edges):
        block_of[a:b] = k
    best = None
    for name, x in variables.items():
        if name == "time":
            continue
        lo, hi = np.percentile(x, [1, 99])
        if hi <= lo:
            continue
        bin_edges = np.linspace(lo, hi, nbins + 1)
        centers = 0.5 * (bin_edges[:-1] + bin_edges[1:])
        which = np.clip(np.digitize(x, bin_edges) - 1, 0, nbins - 1)
        cell = block_of * nbins + which
        cnt_kb = np.bincount(cell, minlength=len(edges) * nbins).reshape(len(edges), nbins)
        sum_kb = np.bincount(cell, weights=e, minlength=len(edges) * nbins).reshape(len(edges), nbins)
        cnt_all, sum_all = cnt_kb.sum(axis=0), sum_kb.sum(axis=0)
        pred = np.zeros(n)
        for k, (a, b) in enumerate(edges):
            cnt_out = cnt_all - cnt_kb[k]  # every bin without block k
            ok = cnt_out >= 5
            if ok.sum() >= 2:  # piecewise linear between the bin means of the other blocks
                pred[a:b] = np.interp(x[a:b], centers[ok], (sum_all[ok] - sum_kb[k][ok]) / cnt_out[ok])
        frac = max(total - float(np.mean((e - pred) ** 2)), 0.0) / total
        means_all = sum_all / np.maximum(cnt_all, 1)
        peak = float(np.max(np.abs(means_all[cnt_all >= 10]), initial=0.0))
        explained = math.sqrt(frac * total)
        if frac >= STRUCTURE_MIN_FRACTION and peak >= floor and (best is None or frac > best[2]):
            best = (name, explained, frac)
    return best


def _breakaways(ctx: ChannelContext) -> np.ndarray:
    """Times (s) the axis starts to move from standstill: where a stuck axis breaks away."""
    d = ctx.full_sign_speed(memory=False)
    starts = np.flatnonzero((d[1:] != 0) & (d[:-1] == 0)) + 1
    return ctx.sig.raw_t_s[starts]


def _bursts_in_time(
    e: np.ndarray, t: np.ndarray, floor: float, length: int, breakaways: np.ndarray | None = None
) -> tuple[float, float, list[tuple[float, float, float]]] | None:
    """Bursts of residual at times no state variable explains (an unmeasured disturbance).

    The residual's local RMS over `length` samples (a few analysis windows) is compared with its
    median: a burst peaks above BURST_FACTOR x the median and BURST_FLOOR_FACTOR practical floors; it
    extends while the local RMS stays above BURST_EDGE_FACTOR x the median. A model's own errors sit
    at every acceleration change and stay within a few times the median; a disturbance at
    irregular times stands out by an order of magnitude. A burst peaking just after the axis breaks
    away from standstill is the rigid model's own limit (stick-slip), not a disturbance. Returns
    (rms within the bursts, their share of the residual variance, [(start s, end s, peak local RMS)])
    or None.
    """
    total = float(np.sum(e**2))
    if total <= 0 or len(e) < 4 * length:
        return None
    local = np.sqrt(np.convolve(e**2, np.ones(length) / length, mode="same"))
    median = float(np.median(local))
    threshold = max(BURST_FACTOR * median, BURST_FLOOR_FACTOR * floor)
    settle_s = BREAKAWAY_SETTLE_S + length * float(t[1] - t[0])
    if not np.any(local > threshold):
        return None
    inside = local > BURST_EDGE_FACTOR * median
    edges = np.flatnonzero(np.diff(np.concatenate([[0], inside.astype(np.int8), [0]])))
    spans = []
    mask = np.zeros(len(e), bool)
    for a, b in zip(edges[::2], edges[1::2], strict=True):
        peak = float(local[a:b].max())
        at = float(t[a + int(np.argmax(local[a:b]))])
        after_breakaway = breakaways is not None and np.any((breakaways <= at) & (at - breakaways < settle_s))
        if peak > threshold and not after_breakaway:
            spans.append((float(t[a]), float(t[b - 1]), peak))
            mask[a:b] = True
    fraction = float(np.sum(e[mask] ** 2)) / total
    if not spans or fraction < STRUCTURE_MIN_FRACTION:
        return None
    return float(np.sqrt(np.mean(e[mask] ** 2))), fraction, spans


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


def _updated_model(model: AxisModel, effects: list[Effect]) -> AxisModel:
    e = Effects()
    for eff in effects:
        params = CANDIDATES[eff.id].model_params(dict(eff.params), model)
        if params is not None:
            e = e.with_effect(eff.id, **params)
    return model.with_effects(e)


def _resimulate(
    sig: Signals, axis: DeclaredAxis, nominal: AxisModel, updated: AxisModel, servo: ServoSettings | None
) -> Resimulation:
    f = sig.filt
    h = f.half
    # the closed loop runs at the servo rate: its cost grows with the duration, not the samples, so
    # only the first RESIM_MAX_S seconds are re-simulated (the analysis itself uses all of them)
    n_raw = int(np.searchsorted(sig.raw_t_s, sig.raw_t_s[0] + RESIM_MAX_S, side="right"))
    n_raw = max(n_raw, min(len(sig.raw_t_s), 2 * h + 3))
    t = sig.raw_t_s[:n_raw]
    n_valid = n_raw - 2 * h
    if servo is not None and sig.cmd_pos_rad is not None:
        command, cmd = "cmd_pos", sig.cmd_pos_rad[:n_raw]
    else:
        command = "motion (the measured position, smoothed, through a stiff servo)"
        cmd = savgol_filter(sig.raw_pos_rad, f.window, POLYORDER)[:n_raw]
        servo = ServoSettings.tuned_for(nominal, speed_bandwidth_hz=RESIM_BANDWIDTH_HZ, feed_forward_gain=1.0)
    if n_raw < len(sig.raw_t_s):
        command += f", its first {RESIM_MAX_S:g} s"
    kt = axis.kt_nm_per_a
    out = {}
    for name, m in (("nominal", nominal), ("updated", updated)):
        try:
            r = simulate(m, servo, t, cmd)
        except ValueError as exc:
            raise ModelCheckError(f"re-simulation with the {name} model failed: {exc}") from None
        out[name] = r
    meas = sig.torque_f_nm[:n_valid]
    tn = kt * f.apply(out["nominal"]["current"])
    tu = kt * f.apply(out["updated"]["current"])
    res = Resimulation(
        t_s=sig.t_s[:n_valid],
        torque_measured_nm=meas,
        torque_nominal_nm=tn,
        torque_updated_nm=tu,
        pos_measured_deg=np.degrees(sig.pos_rad[:n_valid]),
        pos_nominal_deg=np.degrees(out["nominal"]["pos"][h:-h]),
        pos_updated_deg=np.degrees(out["updated"]["pos"][h:-h]),
        rms_nominal_nm=rms(meas - tn),
        rms_updated_nm=rms(meas - tu),
        command=command,
    )
    if sig.load_diff_f_rad is not None:
        res.load_diff_measured_arcsec = sig.load_diff_f_rad[:n_valid] * ARCSEC_PER_RAD
        for name in ("nominal", "updated"):
            d = f.apply(out[name]["load_pos"] - out[name]["pos"]) * ARCSEC_PER_RAD
            setattr(res, f"load_diff_{name}_arcsec", d)
    return res


__all__ = ["ModelCheckError", "ModelCheckResult", "Param", "run_modelcheck"]
