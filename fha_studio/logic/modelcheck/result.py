"""What the model check found, per step, as arrays a GUI can plot; the human summary and the JSON
report (``fha-modelcheck-report/1``). The workflow that fills them is workflow.py."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import Any

import numpy as np

from fha_studio.logic.modelcheck.bandwidth import BandwidthPoint
from fha_studio.logic.modelcheck.candidates import LABELS, PARAM_WORDS, label_of
from fha_studio.logic.modelcheck.consistency import Refused
from fha_studio.logic.modelcheck.selection import BIC_MIN, SelectionStep
from fha_studio.logic.wording import manual_units_in_text, unit_words
from fha_studio.physics import AxisModel


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
    basis: str = ""  # where it was read, when not from the whole recording (a coast after an alarm)

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
            **({"read_from": self.basis} if self.basis else {}),
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
    # effects the fit found that each exceed the residual but cancel each other (consistency.py):
    # their ids and RMS sizes, and where in ``variable`` their small sum is largest (a range)
    cancelled: tuple[str, ...] = ()
    sizes: tuple[float, ...] = ()
    at: tuple[float, float] | None = None
    at_unit: str = ""


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
class CoastGap:
    """A coast after an alarm (servo off): its speed from its start, recorded and as the nominal
    model (no friction) and the updated one give it, in output r/min."""

    alarm_s: float
    t_s: np.ndarray
    speed_measured_rpm: np.ndarray
    speed_nominal_rpm: np.ndarray
    speed_updated_rpm: np.ndarray
    rms_before_rpm: float
    rms_after_rpm: float

    def line(self, to: str) -> str:
        return (
            f"Coast after the alarm at {self.alarm_s:.2f} s ({self.t_s[-1] - self.t_s[0]:.2f} s from "
            f"{abs(self.speed_nominal_rpm[0]):.3g} r/min): speed against the recorded one "
            f"{fmt(self.rms_before_rpm)}{to}{fmt(self.rms_after_rpm)} r/min rms "
            f"(nominal model, no friction{to}updated model, from the coast's start)"
        )


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
    # without a current (closedloop.py): measured - re-simulated position, the following error's gap
    following_error_rms_nominal_arcsec: float | None = None
    following_error_rms_updated_arcsec: float | None = None


@dataclass
class ChannelReport:
    """Steps 3-5 of one channel."""

    channel: str
    unit: str
    floor: float
    steps: list[SelectionStep]
    ar_order: int
    n_samples: int


class ChannelCheck(StrEnum):
    """Whether a channel was checked, and if not, why (the text is the JSON report's)."""

    CHECKED = "checked"
    TOO_LITTLE_SIGNAL = "too little signal"
    ABSENT = "absent"


CHECKED = ChannelCheck.CHECKED
TOO_LITTLE_SIGNAL = ChannelCheck.TOO_LITTLE_SIGNAL
ABSENT = ChannelCheck.ABSENT


@dataclass(frozen=True)
class ChannelStatus:
    """Whether a channel was checked, and why not."""

    channel: str
    status: ChannelCheck
    reason: str
    level: float = 0.0  # channel unit: what the channel shows at most (too little signal)
    unit: str = ""

    @property
    def checked(self) -> bool:
        return self.status is ChannelCheck.CHECKED

    def to_json(self) -> dict[str, Any]:
        return {"status": str(self.status), "reason": self.reason, "level": self.level, "unit": self.unit}


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
    refused: list[Refused] = field(default_factory=list)  # fitted, not named, and why (consistency.py)
    not_seen: list[str] = field(default_factory=list)  # what this recording cannot show, and what would
    torque_basis: str = ""  # what the torques in N m rest on, when no torque was measured
    loop: Any = None  # the closed loop identified from a recording without current (closedloop.Loop)
    coasts: list[CoastGap] = field(default_factory=list)  # the coasts after alarms that told something

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
            if not e.basis:  # one read elsewhere (a coast) is not what the channel's gap measures
                by_channel.setdefault(e.channel, e)
        for e in self.effects:
            p = next(iter(e.params))
            main = fmt_pm(e.params[p], e.uncertainty[p], unit(e.units[p]))
            others = ", ".join(
                f"{PARAM_WORDS.get(k, k)} {fmt_pm(v, e.uncertainty[k], unit(e.units[k]))}"
                for k, v in e.params.items()
                if k != p
            )
            if e.basis:
                main += f" ({e.basis})"
            elif self.torque_basis and e.units.get(p) == "N m" and not e.label.endswith(" at the load"):
                main += f" ({self.torque_basis})"
            text = f"{e.label} missing: {main}" + (f" ({others})" if others else "")
            if e.alternatives:
                alts = " or ".join(label_of(a) for a in e.alternatives)
                text = f"{e.label} or {alts} — not separable from this data; as {e.label.lower()}: {main}"
            gap = self.gap.get(e.channel)
            if gap is not None and by_channel.get(e.channel) is e:
                text += (
                    f"; {e.channel} gap {fmt(gap.rms_before)}{to}{fmt(gap.rms_after)} {unit(gap.unit)} rms "
                    "on held-out data"
                )
            lines.append(text)
        for a in self.ambiguities:
            as_alt = ", ".join(f"{PARAM_WORDS.get(k, k)} {fmt(v)}" for k, v in a.alternative_params.items())
            lines.append(
                f"  {label_of(a.chosen)} or {label_of(a.alternative)}"
                + (f" ({as_alt})" if as_alt else "")
                + " — not separable from this data; "
                f"to separate them: {a.separating_test}"
            )
        for refused in self.refused:
            value = "".join(f" {fmt(v)}" for v in list(refused.params.values())[:1])
            lines.append(f"  Not named: {refused.label.lower()}{value} — {refused.reason}")
        for s in self.structures:
            if s.cancelled:
                lines.append(_cancelled_line(s, unit))
                continue
            if s.variable == "time":
                where = ", ".join(f"{a:.2f}-{b:.2f} s" for a, b, _ in s.spans[:6])
                more = f" and {len(s.spans) - 6} more" if len(s.spans) > 6 else ""
                peak = max(p for _, _, p in s.spans)
                lines.append(
                    f"Structured residual in the {s.channel} channel that no candidate explains: "
                    f"{len(s.spans)} burst{'s' if len(s.spans) > 1 else ''} up to "
                    f"{fmt(peak)} {unit(s.unit)} at t = {where}{more} ({100 * s.fraction:.0f} % of the "
                    "residual): a disturbance the recording does not measure; not forced onto a named effect"
                )
                continue
            lines.append(
                f"Structured residual in the {s.channel} channel that no candidate explains: "
                f"{fmt(s.rms)} {unit(s.unit)} rms organised by {s.variable.replace('_', ' ')} "
                f"({100 * s.fraction:.0f} % of the residual); not forced onto a named effect"
            )
        lines.extend(self.not_seen)
        if not self.effects and any(st.checked for st in self.channel_status.values()):
            lines.append("No missing effect found.")
            for ch, gap in self.gap.items():
                lines.append(
                    f"  {ch} gap {fmt(gap.rms_before)}{to}{fmt(gap.rms_after)} {unit(gap.unit)} rms "
                    "on held-out data"
                )
        if self.detection_limits:
            limits = ", ".join(
                f"{LABELS[d.id]} ±{100 * d.value:.2g} %"
                if d.param_unit == "1"  # a ratio's distance from 1
                else f"{LABELS[d.id]} {fmt(d.value)} {unit(d.param_unit)}"
                for d in self.detection_limits
            )
            lines.append(f"Detection limit (smallest effect this recording could have revealed): {limits}")
        resim = self.resimulation
        fe_nominal = None if resim is None else resim.following_error_rms_nominal_arcsec
        if self.resimulation is not None and fe_nominal is not None:
            r = self.resimulation
            lines.append(
                f"Re-simulation of the recorded {r.command}: position against the measured "
                f"{fmt(fe_nominal)}{to}"
                f"{fmt(r.following_error_rms_updated_arcsec or 0.0)} arcsec rms (nominal{to}updated model)"
            )
        elif self.resimulation is not None:
            r = self.resimulation
            lines.append(
                f"Re-simulation of the recorded {r.command}: torque {fmt(r.rms_nominal_nm)}{to}"
                f"{fmt(r.rms_updated_nm)} {unit('N m')} rms (nominal{to}updated model)"
            )
        lines.extend(c.line(to) for c in self.coasts)
        lines.extend(self.notes)
        # the notes and the lines above were written with the terminal's units
        return [manual_units_in_text(line) for line in lines] if manual_units else lines

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
            f"The {st.channel} channel {st.reason}: {rest}."
            for st in skipped
            if st.status is not ChannelCheck.ABSENT
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
                    "cancelling_effects": list(s.cancelled),
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
                "following_error_rms_nominal_arcsec": self.resimulation.following_error_rms_nominal_arcsec,
                "following_error_rms_updated_arcsec": self.resimulation.following_error_rms_updated_arcsec,
            },
            "loop": None if self.loop is None else {
                "position_gain_per_s": self.loop.position_gain_per_s,
                "speed_gain_a_s_per_rad": self.loop.speed_gain_a_s_per_rad,
                "integral_time_s": self.loop.integral_time_s,
                "feed_forward": self.loop.feed_forward,
            },
            "torque_basis": self.torque_basis,
            "coasts": [
                {"alarm_s": c.alarm_s, "speed_rms_nominal_rpm": c.rms_before_rpm,
                 "speed_rms_updated_rpm": c.rms_after_rpm}
                for c in self.coasts
            ],
            "not_named": [r.to_json() for r in self.refused],
            "not_seen": list(self.not_seen),
            "notes": list(self.notes),
        }

    def write_model(self, path: str | Path) -> None:
        """Write the updated model file (fha-axis-model/1 TOML, loadable by the sim and later checks)."""
        self.updated_model.save(path)


def _cancelled_line(s: Structure, unit: Any) -> str:
    """A cancelling set of effects as one structured residual: what it is, and where it sits."""
    sizes = zip(s.cancelled, s.sizes, strict=True)
    pair = " and ".join(f"{label_of(i).lower()} ({fmt(z)} {unit(s.unit)} rms)" for i, z in sizes)
    at = f", largest at {s.variable} {fmt(s.at[0])} to {fmt(s.at[1])} {unit(s.at_unit)}" if s.at else ""
    when = ", ".join(f"{a:.2f}-{b:.2f} s" for a, b, _ in s.spans[:4])
    more = f" and {len(s.spans) - 4} more" if len(s.spans) > 4 else ""
    return (
        f"Structured residual in the {s.channel} channel that no candidate explains: "
        f"{fmt(s.rms)} {unit(s.unit)} rms{at}" + (f", at t = {when}{more}" if when else "")
        + f"; the fit offered {pair}, which cancel each other: not named"
    )


def fmt(x: float) -> str:
    if x == 0 or not math.isfinite(x):
        return f"{x:g}"
    digits = max(0, 2 - math.floor(math.log10(abs(x))))
    return f"{x:.{min(digits, 6)}f}" if abs(x) < 1e5 else f"{x:.3g}"


def fmt_pm(value: float, sigma: float, unit: str) -> str:
    unit = "" if unit in ("1", "1/rev") else unit  # a ratio, or cycles per motor turn (said in words)
    if not math.isfinite(sigma) or sigma <= 0:
        return f"{fmt(value)} {unit}".rstrip()
    digits = max(0, -math.floor(math.log10(sigma)))
    if abs(value) >= 1e5:
        return f"{value:.4g} {unit} ± {sigma:.2g}".replace("  ", " ")
    return f"{value:.{min(digits, 8)}f} {unit} ± {sigma:.{min(digits, 8)}f}".replace("  ", " ")
