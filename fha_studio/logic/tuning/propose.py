"""Proposed tune items for an aim (stiff / standard / soft), from the linearised loops.

The tune items are the HA-655's (resources/drive/ha655-parameters.toml): speed loop gain (Kv,
Hz), speed loop integral compensation (Tv, ms), position loop gain (Kp, 1/s), feed-forward gain
(%). Their meaning in SI is the simulated drive's mapping (``hardware.sim.axis.servo_settings``);
the proposal searches integer panel values:

1. Kv and Tv: the highest speed loop gain whose loop meets the aim's gain and phase margin and
   whose current from the encoder's quantisation stays within ``NOISE_SHARE``, for
   Tv at 1, 2 or 4 x the conventional 4 / (2 pi f) (the present Tv is tried as well);
2. Kp: of a few position loop gains from a quarter of the present one up to the item's maximum,
   the one whose position step settles soonest while overshooting at most ``MAX_OVERSHOOT_PCT``
   and asking at most ``PULSE_CURRENT_SHARE`` of the current for one pulse of position error;
3. feed-forward stays as it is.

Beyond FHA-C manual 2-1's allowance (a load inertia of more than ``ALLOWED_LOAD_RATIO`` times the
actuator's own) the proposal takes the soft aim's margins whatever was asked, and says so.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import control
import numpy as np

from fha_studio.hardware.parameters import Mode, ParameterModel
from fha_studio.hardware.sim.axis import servo_settings
from fha_studio.logic.tuning.linear import LoopModel
from fha_studio.logic.tuning.response import LoopFigures, loop_figures
from fha_studio.physics import AxisModel

#: the tune items a proposal sets, by key (tune mode, HA-655 manual p.24-28)
TUNE_KEYS = ("speed_loop_gain", "speed_loop_integral_compensation", "position_loop_gain", "feed_forward_gain")
#: FHA-C manual 2-1: the load inertia allowed, as a multiple of the actuator's own (about 3 x)
ALLOWED_LOAD_RATIO = 3.0
#: gain margin (dB), phase margin (deg) by aim; "standard" are common targets of servo tuning
AIMS: dict[str, tuple[float, float]] = {"stiff": (6.0, 35.0), "standard": (8.0, 45.0), "soft": (12.0, 60.0)}
#: the encoder's quantisation may make a current of at most this share of the maximum (standard
#: deviation): a speed loop gain above it turns the encoder's steps into a current that saturates
NOISE_SHARE = 0.25
#: one encoder pulse of position error may ask for at most this share of the maximum current
#: (Kv x Kp x pulse): above it the axis dithers between pulses instead of settling
PULSE_CURRENT_SHARE = 0.05
#: the most a proposed position step may overshoot (%)
MAX_OVERSHOOT_PCT = 5.0
#: 2 % band for the settling time
SETTLING_BAND = 0.02
STEP_DURATION_S = 0.6


@dataclass(frozen=True)
class Figures:
    """One set of tune items and what the linear model predicts of it."""

    items: dict[str, int]
    gain_margin_db: float | None
    phase_margin_deg: float | None
    crossover_hz: float | None
    bandwidth_hz: float | None
    overshoot_pct: float | None
    settling_ms: float | None
    stable: bool

    def to_dict(self) -> dict[str, object]:
        def r(v: float | None, n: int = 2) -> float | None:
            return None if v is None else round(v, n)

        return {
            **self.items,
            "gain_margin_db": r(self.gain_margin_db),
            "phase_margin_deg": r(self.phase_margin_deg),
            "crossover_hz": r(self.crossover_hz),
            "bandwidth_hz": r(self.bandwidth_hz),
            "overshoot_pct": r(self.overshoot_pct),
            "settling_ms": r(self.settling_ms, 1),
        }

    def meets(self, gm_db: float, pm_deg: float) -> bool:
        return (self.stable and (self.gain_margin_db is None or self.gain_margin_db >= gm_db)
                and self.phase_margin_deg is not None and self.phase_margin_deg >= pm_deg)


@dataclass(frozen=True)
class Proposal:
    aim: str
    used_aim: str
    present: Figures
    proposed: Figures
    warning: str | None


class Tuner:
    """Evaluates tune items on one axis model (the declared load) with the drive's other items."""

    def __init__(self, model: AxisModel, items: Mapping[str, int], parameters: ParameterModel,
                 servo_rate_hz: float, quantised_feedback: bool = True) -> None:
        self.model = model
        self.items = dict(items)
        self.parameters = parameters
        self.servo_rate_hz = servo_rate_hz
        self.quantised_feedback = quantised_feedback

    def loop(self, tune: Mapping[str, int]) -> LoopModel:
        values = {**self.items, **tune}
        settings = servo_settings(self.model, values, self.servo_rate_hz, self.quantised_feedback)
        return LoopModel(self.model, settings)

    def _range(self, key: str) -> tuple[int, int]:
        item = self.parameters.by_key(key)
        return item.minimum, item.maximum

    def speed_figures(self, tune: Mapping[str, int]) -> tuple[LoopModel, LoopFigures | None, bool]:
        lm = self.loop(tune)
        try:
            stable = lm.stable()
        except (ValueError, np.linalg.LinAlgError):
            return lm, None, False
        figs = loop_figures(lm.speed_open_loop(), lm.speed_closed_loop(), 0.49 * self.servo_rate_hz)
        return lm, figs, stable

    def figures(self, tune: Mapping[str, int]) -> Figures:
        full = {k: int(v) for k, v in {**self.items, **tune}.items() if k in TUNE_KEYS}
        lm, figs, stable = self.speed_figures(full)
        overshoot = settling = None
        if stable:
            overshoot, settling = step_figures(lm)
        return Figures(
            items=full,
            gain_margin_db=figs.gain_margin_db if figs else None,
            phase_margin_deg=figs.phase_margin_deg if figs else None,
            crossover_hz=figs.crossover_hz if figs else None,
            bandwidth_hz=figs.bandwidth_hz if figs else None,
            overshoot_pct=overshoot, settling_ms=settling, stable=stable,
        )

    def propose(self, aim: str = "standard") -> Proposal:
        if aim not in AIMS:
            raise ValueError(f"tuning aim {aim!r}: use one of {', '.join(AIMS)}")
        present = self.figures({})
        ratio = (self.model.load_side_inertia_kgm2 + self.model.motor_side_inertia_kgm2) / \
            self.model.actuator_inertia_kgm2 - 1.0
        used, warning = aim, None
        if ratio > ALLOWED_LOAD_RATIO + 1e-9:
            used = "soft"
            warning = (f"the load inertia is {ratio:.1f} x the actuator's own, beyond the about "
                       f"{ALLOWED_LOAD_RATIO:g} x that FHA-C manual 2-1 allows: tuned soft; a lighter load "
                       "or a larger actuator is the real remedy")
        gm, pm = AIMS[used]
        kv_min, kv_max = self._range("speed_loop_gain")
        tv_min, tv_max = self._range("speed_loop_integral_compensation")
        best: tuple[int, int] | None = None
        present_tv = self.items["speed_loop_integral_compensation"]
        for factor in (1.0, 2.0, None):
            def tv_for(f: int, factor: float | None = factor) -> int:
                if factor is None:
                    return present_tv
                return min(max(round(factor * 4000.0 / (2.0 * math.pi * f)), tv_min), tv_max)

            def ok(f: int, tv_for: object = tv_for) -> bool:
                tv = tv_for(f)  # type: ignore[operator]
                lm, figs, stable = self.speed_figures({"speed_loop_gain": f,
                                                       "speed_loop_integral_compensation": tv})
                noise = lm.quantisation_current_noise_a() <= NOISE_SHARE * self.model.max_current_a
                return bool(stable and figs is not None and noise and figs.phase_margin_deg is not None
                            and figs.phase_margin_deg >= pm
                            and (figs.gain_margin_db is None or figs.gain_margin_db >= gm))

            f = _highest(ok, kv_min, kv_max)
            if f is not None and (best is None or f > best[0]):
                best = (f, tv_for(f))
        if best is None:
            best = (kv_min, tv_max)
        speed = {"speed_loop_gain": best[0], "speed_loop_integral_compensation": best[1]}
        kp_min, kp_max = self._range("position_loop_gain")

        present_kp = self.items["position_loop_gain"]
        grid = np.geomspace(max(kp_min, present_kp / 4), kp_max, 9)
        candidates = sorted({present_kp, *(round(v) for v in grid)})
        kp, best_settling = present_kp, math.inf
        for candidate in candidates:
            lm = self.loop({**speed, "position_loop_gain": candidate})
            if lm.current_per_position_pulse_a() > PULSE_CURRENT_SHARE * self.model.max_current_a:
                continue
            try:
                if not lm.stable():
                    continue
            except (ValueError, np.linalg.LinAlgError):
                continue
            overshoot, settling = step_figures(lm)
            if overshoot is not None and overshoot <= MAX_OVERSHOOT_PCT and settling is not None \
                    and settling < best_settling - 1e-6:
                kp, best_settling = candidate, settling
        proposed = self.figures({**speed, "position_loop_gain": kp})
        return Proposal(aim, used, present, proposed, warning)


def _highest(ok: object, low: int, high: int) -> int | None:
    """The highest integer in [low, high] for which ok() holds, by bisection (ok assumed to hold
    below some value and fail above it)."""
    test = ok  # callable
    if not test(low):  # type: ignore[operator]
        return None
    if test(high):  # type: ignore[operator]
        return high
    while high - low > 1:
        mid = (low + high) // 2
        if test(mid):  # type: ignore[operator]
            low = mid
        else:
            high = mid
    return low


def step_figures(lm: LoopModel) -> tuple[float | None, float | None]:
    """Overshoot (%) and 2 % settling time (ms) of the position loop's step response."""
    dt = lm.servo_period_s
    t = np.arange(0.0, STEP_DURATION_S, dt)
    resp = control.step_response(lm.position_closed_loop(), T=t)
    y = np.asarray(resp.outputs).reshape(-1)
    final = 1.0
    overshoot = max(0.0, (float(np.max(y)) - final) * 100.0)
    outside = np.nonzero(np.abs(y - final) > SETTLING_BAND)[0]
    if len(outside) and outside[-1] >= len(y) - 1:
        return overshoot, None
    settling = float(t[outside[-1] + 1]) * 1000.0 if len(outside) else 0.0
    return overshoot, settling


def present_items(parameters: ParameterModel, values: Mapping[tuple[Mode, int], int]) -> dict[str, int]:
    """Every tune and system item by key from a drive's values keyed by (mode, number)."""
    out: dict[str, int] = {}
    for (mode, number), value in values.items():
        try:
            out[parameters.item(mode, number).key] = int(value)
        except KeyError:
            continue
    return out
