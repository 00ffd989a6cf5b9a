"""Step 2 of the model check, where the residual lies: binned against the state variables, and the
structure no candidate explains (organised by a variable, or bursts in time)."""

from __future__ import annotations

import math

import numpy as np

from fha_studio.logic.modelcheck.candidates import ChannelContext
from fha_studio.logic.modelcheck.linalg import block_edges
from fha_studio.logic.modelcheck.result import Binned
from fha_studio.logic.modelcheck.signals import Signals

STRUCTURE_MIN_FRACTION = 0.15  # a structured residual explains >= 15 % of the residual's variance
BURST_FACTOR = 6.0  # a burst in time: local RMS this many times the residual's median local RMS
BURST_FLOOR_FACTOR = 3.0  # ... and above this many practical floors
BREAKAWAY_SETTLE_S = 0.1  # a burst peaking this soon after a breakaway from standstill is stick-slip
BURST_EDGE_FACTOR = 3.0  # ... and it lasts while the local RMS stays above this many times the median


def where_variables(
    sig: Signals, index: np.ndarray, torque_nm: np.ndarray
) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """The state variables a residual is set against (decimated) and their units; ``torque_nm`` is
    the torque that acts on the channel (analysis rate)."""
    variables = {
        "time": sig.t_s[index],
        "speed": sig.speed_rad_s[index] * 30.0 / math.pi,
        "position": np.degrees(sig.pos_rad[index]),
        "acceleration": sig.accel_rad_s2[index],
        "torque": torque_nm[index],
    }
    units = {"time": "s", "speed": "r/min", "position": "deg", "acceleration": "rad/s^2", "torque": "N m"}
    if sig.ratio is not None:
        variables["motor_angle"] = np.degrees(np.mod(sig.ratio * sig.pos_rad[index], 2.0 * math.pi))
        units["motor_angle"] = "deg"
    return variables, units


def binned(x: np.ndarray, y: np.ndarray, name: str, unit: str, bins: int = 24) -> Binned:
    """The residual y binned against the variable x (mean and its standard error per bin)."""
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


def structure_by_variable(
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


def breakaways(ctx: ChannelContext) -> np.ndarray:
    """Times (s) the axis starts to move from standstill: where a stuck axis breaks away."""
    d = ctx.full_sign_speed(memory=False)
    starts = np.flatnonzero((d[1:] != 0) & (d[:-1] == 0)) + 1
    return ctx.sig.raw_t_s[starts]


def bursts_in_time(
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
