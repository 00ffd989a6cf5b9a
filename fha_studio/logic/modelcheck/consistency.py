"""Self-consistency of a selected effect set, before anything is named.

Selection (selection.py) adds effects one at a time by the evidence each brings; the final fit
then refines all of them together. That joint fit can turn a chosen set into something no axis
does, and nothing in the selection gates looks at it again. Here every effect of the final fit is
judged once more, in every re-fit, until the set is stable:

1. **Its own floor.** An effect whose size in the joint fit falls below the channel's practical
   floor, or within MIN_SIGMAS jackknife sigmas of zero, is not named (the nominal inertia re-fit
   is chosen first, when the other effects are not in the model yet, and can shrink below its floor
   once they are).
2. **Its shape within the recording.** A searched shape that ran away from what the recording
   spans (a Stribeck fading speed far above every recorded speed is just Coulomb friction) is not
   named: :attr:`Candidate.shape_check` says why.
3. **What the actuator can produce.** A torque effect larger than the actuator's maximum torque
   (its peak torque, Kt x Imax, for a custom axis) is refused with that reason.
4. **Cancelling pairs.** Two effects that each exceed the residual they were fitted to but
   nearly cancel each other explain only their small sum: they are one unexplained structure,
   reported with where it sits in time and in the state space, never as two findings.

The weakest offender goes first and the rest is re-fitted, so that one bad term does not take
its neighbours with it. The re-simulation and held-out gates (the whole set must not make the
closed-loop re-simulation worse, and must shrink the held-out gap) are :func:`set_verdict`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from fha_studio.logic.modelcheck.candidates import PARAM_WORDS
from fha_studio.logic.modelcheck.selection import MIN_SIGMAS, ChannelSelector, FittedTerm, Term

#: two effects cancel when their sum is this many times smaller than the smaller of the two ...
CANCEL_FACTOR = 4.0
#: ... and each alone is larger than the residual the set was fitted to (RMS)
CANCEL_EXCEEDS_RESIDUAL = 1.0
#: a set's re-simulation is "worse" beyond this share of the practical floor (numerical noise)
RESIM_TOLERANCE_OF_FLOOR = 0.1
MAX_SETTLE_ROUNDS = 8


@dataclass(frozen=True)
class Refused:
    """An effect the fit found and the check does not name, and why (one line for a person)."""

    id: str
    channel: str
    label: str
    params: dict[str, float]
    size: float
    unit: str
    reason: str

    def to_json(self) -> dict[str, object]:
        return {"id": self.id, "channel": self.channel, "params": dict(self.params), "size": self.size,
                "unit": self.unit, "reason": self.reason}


@dataclass(frozen=True)
class Cancelling:
    """Effects that each exceed the residual but cancel each other: one unexplained structure."""

    channel: str
    ids: tuple[str, ...]
    labels: tuple[str, ...]
    sizes: tuple[float, ...]  # each one's RMS in the channel unit
    net_rms: float  # RMS of their sum: what they explain together
    net_peak: float  # largest |sum|
    unit: str
    variable: str  # the state variable that orders the sum best ("position", "speed")
    variable_unit: str
    at: tuple[float, float]  # where in that variable the sum is largest (a range)
    spans: list[tuple[float, float, float]] = field(default_factory=list)  # time (start, end, peak)

    def to_json(self) -> dict[str, object]:
        return {
            "channel": self.channel, "effects": list(self.ids), "sizes": list(self.sizes),
            "net_rms": self.net_rms, "net_peak": self.net_peak, "unit": self.unit,
            "variable": self.variable, "variable_unit": self.variable_unit, "at": list(self.at),
            "time_spans_s": [[a, b] for a, b, _ in self.spans],
        }


@dataclass
class Settled:
    """A channel's final fit after the consistency gates."""

    terms: list[Term]
    fitted: list[FittedTerm]
    fit: np.ndarray
    base_beta: np.ndarray
    ar_order: int
    refused: list[Refused]
    cancelling: list[Cancelling]


def settle(
    sel: ChannelSelector,
    terms: list[Term],
    *,
    max_torque_nm: float | None = None,
    actuator: str = "the actuator",
    t_s: np.ndarray | None = None,
) -> Settled:
    """The final fit of ``terms`` on ``sel``, with every effect held to the gates above, re-fitted
    after each removal. ``t_s``: the selection's (decimated) times, for where a structure sits."""
    terms = list(terms)
    if t_s is None:
        t_s = sel.ctx.sig.t_s[sel.index]
    refused: list[Refused] = []
    cancelling: list[Cancelling] = []
    residual_rms = _rms(sel.y)
    for _ in range(MAX_SETTLE_ROUNDS):
        fitted, fit, base, ar = sel.final_fit(terms)
        own = [(ft, t, _own_reason(ft, t, sel, max_torque_nm, actuator))
               for ft, t in zip(fitted, terms, strict=True)]
        bad = [(ft, t, why) for ft, t, why in own if why]
        if bad:
            # the weakest first (relative to the floor): a bad term must not take its neighbours along
            ft, term, why = min(bad, key=lambda b: b[0].size / max(sel.floor, 1e-300))
            refused.append(_refused(ft, sel.unit, why))
            terms = [x for x in terms if x is not term]
            continue
        pair = _cancelling_pair(fitted, residual_rms)
        if pair is not None:
            i, j = pair
            cancelling.append(_where(sel, fitted[i], fitted[j], t_s))
            drop = {id(terms[i]), id(terms[j])}
            terms = [x for x in terms if id(x) not in drop]
            continue
        return Settled(terms, fitted, fit, base, ar, refused, cancelling)
    fitted, fit, base, ar = sel.final_fit(terms)  # pragma: no cover - a set that never settles
    return Settled(terms, fitted, fit, base, ar, refused, cancelling)


def _own_reason(
    ft: FittedTerm, term: Term, sel: ChannelSelector, max_torque_nm: float | None, actuator: str
) -> str:
    """Why one effect of the joint fit cannot be named on its own ("" when it can)."""
    unit = sel.unit
    if ft.size < sel.floor:
        return (f"its size in the joint fit, {_fmt(ft.size)} {unit}, is below the practical floor "
                f"{_fmt(sel.floor)} {unit}")
    main = ft.params[0] if ft.params else None
    if main is not None and math.isfinite(main.std) and abs(main.value) < MIN_SIGMAS * main.std:
        words = PARAM_WORDS.get(main.name, main.name)
        return (f"the joint fit does not pin it down ({words} {_fmt(main.value)} ± {_fmt(main.std)} "
                f"{main.unit}, within {MIN_SIGMAS:g} sigma of zero)")
    check = term.cand.shape_check
    if check is not None:
        why = check(term.shape, sel.ctx)
        if why:
            return why
    if max_torque_nm is not None and unit == "N m":
        torques = [abs(p.value) for p in ft.params if p.unit == "N m"]
        peak = max([float(np.max(np.abs(ft.contribution))) if len(ft.contribution) else 0.0, *torques])
        if peak > max_torque_nm:
            return (f"{_fmt(peak)} N m is beyond {actuator}'s maximum torque {_fmt(max_torque_nm)} N m: "
                    "the actuator could not produce it")
    return ""


def _refused(ft: FittedTerm, unit: str, reason: str) -> Refused:
    return Refused(ft.id, ft.channel, ft.label, {p.name: p.value for p in ft.params}, ft.size, unit, reason)


def _cancelling_pair(fitted: Sequence[FittedTerm], residual_rms: float) -> tuple[int, int] | None:
    """The pair whose members cancel most (each above the residual, their sum CANCEL_FACTOR smaller)."""
    best: tuple[float, int, int] | None = None
    for i in range(len(fitted)):
        for j in range(i + 1, len(fitted)):
            a, b = fitted[i].contribution, fitted[j].contribution
            ra, rb = _rms(a), _rms(b)
            small = min(ra, rb)
            net = _rms(a + b)
            if small > CANCEL_EXCEEDS_RESIDUAL * residual_rms and small > CANCEL_FACTOR * net:
                score = net / small
                if best is None or score < best[0]:
                    best = (score, i, j)
    return None if best is None else (best[1], best[2])


def _where(sel: ChannelSelector, a: FittedTerm, b: FittedTerm, t_s: np.ndarray | None) -> Cancelling:
    """Where the sum of a cancelling pair sits: the state variable that orders it best, the range
    of that variable where it is largest, and the time spans it is above half its peak."""
    net = a.contribution + b.contribution
    sig = sel.ctx.sig
    idx = sel.index
    variables = {
        "position": (np.degrees(sig.pos_rad[idx]), "deg"),
        "speed": (sig.speed_rad_s[idx] * 30.0 / math.pi, "r/min"),
    }
    best = ("position", 0.0, (0.0, 0.0))
    for name, (x, _unit) in variables.items():
        explained, at = _ordered_by(x, net)
        if explained > best[1]:
            best = (name, explained, at)
    name, _, at = best
    spans: list[tuple[float, float, float]] = []
    if t_s is not None and len(net):
        peak = float(np.max(np.abs(net)))
        above = np.abs(net) >= 0.5 * peak
        edges = np.flatnonzero(np.diff(np.concatenate([[0], above.astype(np.int8), [0]])))
        for s, e in zip(edges[::2], edges[1::2], strict=True):
            spans.append((float(t_s[s]), float(t_s[e - 1]), float(np.max(np.abs(net[s:e])))))
    return Cancelling(
        a.channel,
        (a.id, b.id),
        (a.label, b.label),
        (_rms(a.contribution), _rms(b.contribution)),
        _rms(net),
        float(np.max(np.abs(net))) if len(net) else 0.0,
        sel.unit,
        name,
        variables[name][1],
        at,
        spans,
    )


def _ordered_by(x: np.ndarray, y: np.ndarray, bins: int = 16) -> tuple[float, tuple[float, float]]:
    """Share of y's variance its bin means against x explain, and the bin of the largest |mean|."""
    lo, hi = np.percentile(x, [1, 99]) if len(x) else (0.0, 0.0)
    total = float(np.mean(y**2)) if len(y) else 0.0
    if hi <= lo or total <= 0:
        return 0.0, (float(lo), float(hi))
    edges = np.linspace(lo, hi, bins + 1)
    which = np.clip(np.digitize(x, edges) - 1, 0, bins - 1)
    cnt = np.bincount(which, minlength=bins)
    mean = np.bincount(which, weights=y, minlength=bins) / np.maximum(cnt, 1)
    explained = 1.0 - float(np.mean((y - mean[which]) ** 2)) / total
    k = int(np.argmax(np.where(cnt > 0, np.abs(mean), -1.0)))
    return explained, (float(edges[k]), float(edges[k + 1]))


def set_verdict(
    *,
    resim_nominal: float | None,
    resim_updated: float | None,
    floor: float,
    gaps: Sequence[tuple[str, float, float, str]],
) -> str:
    """Why a named set is not reported as found ("" when it is): its closed-loop re-simulation is
    worse than the nominal model's, or its held-out gap (channel, before, after, unit) does not shrink."""
    if resim_nominal is not None and resim_updated is not None and (
        resim_updated > resim_nominal + RESIM_TOLERANCE_OF_FLOOR * floor
    ):
        return (f"its re-simulation is worse than the nominal model's ({_fmt(resim_nominal)} -> "
                f"{_fmt(resim_updated)} N m rms)")
    for channel, before, after, unit in gaps:
        if not after < before:
            return (f"it does not shrink the {channel} gap on held-out data ({_fmt(before)} -> "
                    f"{_fmt(after)} {unit} rms)")
    return ""


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if len(x) else 0.0


def _fmt(x: float) -> str:
    if x == 0 or not math.isfinite(x):
        return f"{x:g}"
    digits = max(0, 2 - math.floor(math.log10(abs(x))))
    return f"{x:.{min(digits, 6)}f}" if abs(x) < 1e5 else f"{x:.3g}"
