"""Proposed tune items for an aim (stiff / standard / soft), from the linearised loops.

The tune items are the HA-655's (resources/drive/ha655-parameters.toml): speed loop gain (Kv,
Hz), speed loop integral compensation (Tv, ms), position loop gain (Kp, 1/s), feed-forward gain
(%). Their meaning in SI is the one the simulated drive has too (``physics.servo_settings``,
``physics.PanelGains``: the speed loop gain on the actuator's own inertia).

A proposal is aimed at what it is verified with: the verification move (``move.verification_move``,
90 deg at half the maximum speed), predicted on the linear two-mass model, which holds the gear's
resonance and the load swinging on the gear's spring after the deceleration. It searches integer
panel values:

1. the speed loop (Kv, Tv): for each Tv of a geometric series (and the present one), the highest
   Kv whose loop meets the aim's gain and phase margin and whose current from the encoder's
   quantisation stays within ``NOISE_SHARE`` (the stiffest speed loop for that Tv), and a softer
   one at ``SOFTER_KV`` of it;
2. the position loop (Kp, feed-forward): for each speed loop, Kp up to the highest whose position
   loop (broken at the position error) meets the aim's margins too and for which one pulse of
   position error asks at most ``PULSE_CURRENT_SHARE`` of the current, and feed-forward of 0 ...
   100 %;
3. of these, the one whose predicted verification move settles soonest into ``SETTLE_WINDOW_SHARE``
   of the in-position range (room for the encoder's noise), overshooting at most
   ``MAX_OVERSHOOT_PCT`` and asking at most ``MOVE_CURRENT_SHARE`` of the maximum current (the
   linear model holds only below the current limit).

The search screens with numpy (``LoopPolynomials``: margins on a frequency grid, a move in a few
milliseconds); the figures shown and the final check are python-control's (``loop_figures``).

Beyond FHA-C manual 2-1's allowance (a load inertia of more than ``ALLOWED_LOAD_RATIO`` times the
actuator's own) the proposal tunes softer than the stiff or standard aim would, and says so: it
follows the soft aim's margins whatever aim was asked (gain margin >= 12 dB, phase margin >= 60
deg on both loops), and its speed loop crosses over no higher than the standard aim's proposal for
the same axis does (``Proposal.reference``: what the standard aim gives; ``tune propose``'s JSON
holds it as ``reference``). It may still be stiffer than the present items: tune 0 is set on the
actuator's own inertia (``physics.PanelGains``), so on such a load the factory's speed loop gain
crosses over at a few Hz, near or below the position loop's, and the axis settles slowly or is
unstable until it is raised.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import control
import numpy as np

from fha_studio.hardware.parameters import Mode, ParameterModel
from fha_studio.logic.tuning.linear import LoopModel, LoopPolynomials
from fha_studio.logic.tuning.move import MoveFigures, MoveProfile, move_figures, verification_move
from fha_studio.logic.tuning.response import LoopFigures, loop_figures
from fha_studio.physics import AxisModel, servo_settings

#: the tune items a proposal sets, by key (tune mode, HA-655 manual p.24-28)
TUNE_KEYS = ("speed_loop_gain", "speed_loop_integral_compensation", "position_loop_gain", "feed_forward_gain")
#: FHA-C manual 2-1: the load inertia allowed, as a multiple of the actuator's own (about 3 x)
ALLOWED_LOAD_RATIO = 3.0
#: beyond 2-1 the proposal follows this aim, whatever aim was asked, and crosses over no higher
#: than REFERENCE_AIM's proposal would
BEYOND_ALLOWANCE_AIM = "soft"
REFERENCE_AIM = "standard"
#: gain margin (dB), phase margin (deg) by aim; "standard" are common targets of servo tuning
AIMS: dict[str, tuple[float, float]] = {"stiff": (6.0, 35.0), "standard": (8.0, 45.0), "soft": (12.0, 60.0)}
#: the encoder's quantisation may make a current of at most this share of the maximum (standard
#: deviation): a speed loop gain above it turns the encoder's steps into a current that saturates
NOISE_SHARE = 0.25
#: one encoder pulse of position error may ask for at most this share of the maximum current
#: (Kv x Kp x pulse): above it the axis dithers between pulses instead of settling
PULSE_CURRENT_SHARE = 0.05
#: the most a proposed move may overshoot (%, predicted; the verification allows 10 %)
MAX_OVERSHOOT_PCT = 5.0
#: the predicted move's current stays within this share of the maximum current
MOVE_CURRENT_SHARE = 0.9
#: a proposal is chosen for settling into this share of the in-position range
SETTLE_WINDOW_SHARE = 0.8
#: the softer speed loop tried beside the stiffest one for each Tv
SOFTER_KV = 0.7
#: feed-forward gains tried (%)
FEED_FORWARD_PCT = (0, 25, 50, 75, 100)
#: Tv tried (ms), with the present one; Kv and Kp are searched over the items' ranges
TV_SERIES_MS = (2, 3, 5, 8, 12, 20, 30, 45, 70, 100, 150, 250, 400, 700, 1000)
#: speed loops whose position loops are searched in full (the best at their stiffest Kp)
SPEED_LOOPS_SEARCHED = 6
#: position loop gains tried below the highest allowed, as its fractions
KP_FRACTIONS = (1.0, 0.77, 0.6, 0.46, 0.36, 0.28, 0.22, 0.17, 0.13, 0.1)
#: the screening's frequency grid (Hz), as ``loop_figures``' own
GRID_POINTS = 400


@dataclass(frozen=True)
class Figures:
    """One set of tune items and what the linear model predicts of it: the speed loop's margins,
    crossover and bandwidth, and the verification move's overshoot and settling."""

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
    #: beyond 2-1: what the standard aim would propose for this axis (the proposal is softer)
    reference: Figures | None = None


def screen_margins(open_loop: np.ndarray, freq_hz: np.ndarray | None = None) -> tuple[float, float, float]:
    """Gain margin (dB) and phase margin (deg) of an open loop's frequency response on a grid, as
    python-control's ``stability_margins`` picks them among several crossings (the one closest to
    the critical point: the smallest |log GM|, the smallest |PM|), inf without a crossing; and the
    highest frequency where the gain crosses 1 (Hz, 0 without one or without ``freq_hz``). A fast
    screen, interpolated between the grid's points, before python-control's own figures."""
    log_mag = np.log(np.abs(open_loop))
    angle = np.angle(open_loop, deg=True)
    pms = []
    crossover = 0.0
    for i in np.nonzero(np.signbit(log_mag[:-1]) != np.signbit(log_mag[1:]))[0]:
        share = log_mag[i] / (log_mag[i] - log_mag[i + 1])
        at = open_loop[i] + share * (open_loop[i + 1] - open_loop[i])
        pms.append(float(np.remainder(np.angle(at, deg=True), 360.0) - 180.0))
        if freq_hz is not None:
            crossover = max(crossover, float(freq_hz[i] + share * (freq_hz[i + 1] - freq_hz[i])))
    gms = []
    imag = open_loop.imag
    for i in np.nonzero((np.signbit(imag[:-1]) != np.signbit(imag[1:]))
                        & (np.abs(angle[:-1]) > 90.0))[0]:  # through the negative real axis
        share = imag[i] / (imag[i] - imag[i + 1])
        real = open_loop.real[i] + share * (open_loop.real[i + 1] - open_loop.real[i])
        if real < 0.0:
            gms.append(-20.0 * math.log10(-real))
    gm = min(gms, key=abs) if gms else math.inf
    pm = min(pms, key=abs) if pms else math.inf
    return gm, pm, crossover


@dataclass(frozen=True)
class _Candidate:
    tune: dict[str, int]
    settling_ms: float
    overshoot_pct: float


class Tuner:
    """Evaluates tune items on one axis model (the declared load) with the drive's other items."""

    def __init__(self, model: AxisModel, items: Mapping[str, int], parameters: ParameterModel,
                 servo_rate_hz: float, quantised_feedback: bool = True) -> None:
        self.model = model
        self.items = dict(items)
        self.parameters = parameters
        self.servo_rate_hz = servo_rate_hz
        self.quantised_feedback = quantised_feedback
        self._grid_hz = np.logspace(-1.0, math.log10(0.49 * servo_rate_hz), GRID_POINTS)
        # beyond 2-1: the standard aim's speed loop crossover and position loop gain
        self._crossover_cap_hz = math.inf
        self._kp_cap = math.inf

    def loop(self, tune: Mapping[str, int]) -> LoopModel:
        values = {**self.items, **tune}
        settings = servo_settings(self.model, values, self.servo_rate_hz, self.quantised_feedback)
        return LoopModel(self.model, settings)

    def _range(self, key: str) -> tuple[int, int]:
        item = self.parameters.by_key(key)
        return item.minimum, item.maximum

    # ----- the verification move ---------------------------------------------------------------
    def move_profile(self) -> MoveProfile:
        """The verification move with the drive's JOG acceleration (its default when unknown)."""
        item = self.parameters.by_key("jog_acceleration")
        present = self.items.get("jog_acceleration", item.default if item.default is not None else 1)
        return verification_move(self.model, float(present), float(item.minimum))

    def _window_pulses(self) -> float:
        return float(max(1, self.items.get("in_position_range", 1)))

    def predict_move(self, tune: Mapping[str, int]) -> MoveFigures:
        """The verification move with ``tune`` as the linear model predicts it (in pulses)."""
        poly = self.loop(tune).polynomials()
        command = self.move_profile().command_rad(self.servo_rate_hz)
        pos, _current = poly.move(command)
        return self._figures_of(command, pos, self._window_pulses())

    def _figures_of(self, command: np.ndarray, position: np.ndarray, window: float) -> MoveFigures:
        per_rad = self.model.output_resolution_ppr / (2.0 * math.pi)
        t = np.arange(len(command)) / self.servo_rate_hz
        return move_figures(t, command * per_rad, position * per_rad, float(command[-1]) * per_rad, window)

    # ----- figures -----------------------------------------------------------------------------
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
        _lm, figs, stable = self.speed_figures(full)
        overshoot = settling = None
        if stable:
            move = self.predict_move(full)
            overshoot, settling = move.overshoot_pct, move.settling_ms
        return Figures(
            items=full,
            gain_margin_db=figs.gain_margin_db if figs else None,
            phase_margin_deg=figs.phase_margin_deg if figs else None,
            crossover_hz=figs.crossover_hz if figs else None,
            bandwidth_hz=figs.bandwidth_hz if figs else None,
            overshoot_pct=overshoot, settling_ms=settling, stable=stable,
        )

    # ----- the proposal -----------------------------------------------------------------------
    def propose(self, aim: str = "standard") -> Proposal:
        if aim not in AIMS:
            raise ValueError(f"tuning aim {aim!r}: use one of {', '.join(AIMS)}")
        present = self.figures({})
        ratio = self.model.total_inertia_kgm2 / self.model.actuator_inertia_kgm2 - 1.0
        self._crossover_cap_hz, self._kp_cap = math.inf, math.inf
        if ratio <= ALLOWED_LOAD_RATIO + 1e-9:
            return self._proposal(aim, aim, present, None, None)
        # beyond 2-1: softer than the standard aim would tune this axis (see the module docstring)
        reference = self._proposal(REFERENCE_AIM, REFERENCE_AIM, present, None, None).proposed
        if reference is not present and reference.stable:
            self._crossover_cap_hz = self._crossover_hz(reference.items)
            self._kp_cap = reference.items["position_loop_gain"]
        try:
            gm, pm = AIMS[BEYOND_ALLOWANCE_AIM]
            warning = (f"the load inertia is {ratio:.1f} x the actuator's own, beyond the about "
                       f"{ALLOWED_LOAD_RATIO:g} x that FHA-C manual 2-1 allows: tuned softer than the "
                       f"{REFERENCE_AIM} aim would (the {BEYOND_ALLOWANCE_AIM} aim's margins, gain margin "
                       f"{gm:g} dB and phase margin {pm:g} deg, the speed loop crossing over and the "
                       f"position loop gain no higher than the {REFERENCE_AIM} aim's); a lighter load or a "
                       "larger actuator is the real remedy")
            return self._proposal(aim, BEYOND_ALLOWANCE_AIM, present, warning, reference)
        finally:
            self._crossover_cap_hz, self._kp_cap = math.inf, math.inf

    def _proposal(self, aim: str, used: str, present: Figures, warning: str | None,
                  reference: Figures | None) -> Proposal:
        """The best candidate for the ``used`` aim that python-control's margins confirm, or the
        present items with why."""
        gm, pm = AIMS[used]
        for candidate in self._search(gm, pm):
            proposed = self.figures(candidate.tune)
            if proposed.meets(gm, pm):  # python-control's margins confirm the screen's
                return Proposal(aim, used, present, proposed, warning, reference)
        why = (f"no tune items meet the {used} aim's margins (gain margin {gm:g} dB, phase margin "
               f"{pm:g} deg) with a move that settles: the present ones are kept")
        return Proposal(aim, used, present, present, f"{warning}; {why}" if warning else why, reference)

    def _crossover_hz(self, tune: Mapping[str, int]) -> float:
        """Where the speed loop's gain with ``tune`` crosses 1, the highest such frequency (Hz)."""
        poly = self.loop(tune).polynomials()
        return screen_margins(poly.speed_open_loop_at(self._grid_hz), self._grid_hz)[2]

    def _search(self, gm: float, pm: float) -> list[_Candidate]:
        """The candidates that pass the screen, best first (see the module docstring)."""
        speed_loops = self._speed_loops(gm, pm)
        command = self.move_profile().command_rad(self.servo_rate_hz)
        window = SETTLE_WINDOW_SHARE * self._window_pulses()
        first: list[tuple[float, dict[str, int], int]] = []
        for speed in speed_loops:
            kp_top = self._highest_kp(speed, gm, pm)
            if kp_top is None:
                continue
            best = self._best_move(speed, [kp_top], command, window)
            first.append((best[0].settling_ms if best else math.inf, speed, kp_top))
        first.sort(key=lambda entry: entry[0])
        found: list[_Candidate] = []
        kp_min = self._range("position_loop_gain")[0]
        for _settling, speed, kp_top in first[:SPEED_LOOPS_SEARCHED]:
            kps = sorted({max(kp_min, round(f * kp_top)) for f in KP_FRACTIONS}, reverse=True)
            found.extend(self._best_move(speed, kps, command, window))
        found.sort(key=lambda c: (c.settling_ms, c.overshoot_pct))
        return found

    def _speed_loops(self, gm: float, pm: float) -> list[dict[str, int]]:
        """(Kv, Tv) pairs that pass the screen: for each Tv the highest Kv, and one softer."""
        kv_min, kv_max = self._range("speed_loop_gain")
        tv_min, tv_max = self._range("speed_loop_integral_compensation")
        tvs = sorted({min(max(tv, tv_min), tv_max) for tv in TV_SERIES_MS}
                     | {self.items["speed_loop_integral_compensation"]})
        noise = self.loop({"speed_loop_gain": kv_max}).quantisation_current_noise_a()  # in proportion to Kv
        if noise > NOISE_SHARE * self.model.max_current_a:
            kv_max = max(kv_min, math.floor(kv_max * NOISE_SHARE * self.model.max_current_a / noise))
        kv_grid = sorted({round(v) for v in np.geomspace(kv_min, kv_max, 24)} | {kv_min, kv_max})
        loops: list[dict[str, int]] = []
        for tv in tvs:
            def ok(kv: int, tv: int = tv) -> bool:
                return self._speed_ok({"speed_loop_gain": kv, "speed_loop_integral_compensation": tv}, gm, pm)

            top = _highest_on_grid(ok, kv_grid)
            if top is None:
                continue
            loops.append({"speed_loop_gain": top, "speed_loop_integral_compensation": tv})
            softer = round(SOFTER_KV * top)
            if kv_min <= softer < top and ok(softer):
                loops.append({"speed_loop_gain": softer, "speed_loop_integral_compensation": tv})
        return loops

    def _speed_ok(self, speed: Mapping[str, int], gm: float, pm: float) -> bool:
        lm = self.loop(speed)
        if lm.quantisation_current_noise_a() > NOISE_SHARE * self.model.max_current_a:
            return False
        poly = lm.polynomials()
        if not poly.speed_stable():
            return False
        g, p, crossover = screen_margins(poly.speed_open_loop_at(self._grid_hz), self._grid_hz)
        return g >= gm and p >= pm and crossover <= self._crossover_cap_hz

    def _position_ok(self, tune: Mapping[str, int], gm: float, pm: float) -> LoopPolynomials | None:
        lm = self.loop(tune)
        if lm.current_per_position_pulse_a() > PULSE_CURRENT_SHARE * self.model.max_current_a:
            return None
        poly = lm.polynomials()
        if not poly.stable():
            return None
        g, p, _ = screen_margins(poly.position_open_loop_at(self._grid_hz))
        return poly if g >= gm and p >= pm else None

    def _highest_kp(self, speed: Mapping[str, int], gm: float, pm: float) -> int | None:
        kp_min, kp_max = self._range("position_loop_gain")
        kp_max = int(max(kp_min, min(kp_max, self._kp_cap)))
        grid = sorted({round(v) for v in np.geomspace(kp_min, kp_max, 24)} | {kp_min, kp_max})
        return _highest_on_grid(
            lambda kp: self._position_ok({**speed, "position_loop_gain": kp}, gm, pm) is not None, grid)

    def _best_move(self, speed: Mapping[str, int], kps: list[int], command: np.ndarray,
                   window: float) -> list[_Candidate]:
        """For each Kp, the feed-forward whose predicted move settles soonest (within the
        overshoot and current shares)."""
        out = []
        per_rad = self.model.output_resolution_ppr / (2.0 * math.pi)
        target = float(command[-1]) * per_rad
        t = np.arange(len(command)) / self.servo_rate_hz
        limit = MOVE_CURRENT_SHARE * self.model.max_current_a
        for kp in kps:
            tune = {**speed, "position_loop_gain": kp}
            poly = self.loop(tune).polynomials()
            unit = poly.unit_move(command)
            best: _Candidate | None = None
            for ff in FEED_FORWARD_PCT:
                pos, current = poly.move(command, unit, ff / 100.0)
                if float(np.max(np.abs(current))) > limit:
                    continue
                figs = move_figures(t, command * per_rad, pos * per_rad, target, window)
                if figs.settling_ms is None or figs.overshoot_pct > MAX_OVERSHOOT_PCT:
                    continue
                if best is None or figs.settling_ms < best.settling_ms - 1e-9:
                    best = _Candidate({**tune, "feed_forward_gain": ff}, figs.settling_ms, figs.overshoot_pct)
            if best is not None:
                out.append(best)
        return out


def _highest_on_grid(ok: Callable[[int], bool], grid: list[int]) -> int | None:
    """The highest integer for which ``ok`` holds: down the grid to the first that passes, then
    bisection between it and the grid point above (``ok`` need not hold below the top: the
    speed loop of a two-mass axis can pass again below a band that fails)."""
    for i in range(len(grid) - 1, -1, -1):
        if ok(grid[i]):
            low = grid[i]
            if i == len(grid) - 1:
                return low
            high = grid[i + 1]
            while high - low > 1:
                mid = (low + high) // 2
                if ok(mid):
                    low = mid
                else:
                    high = mid
            return low
    return None


def step_figures(lm: LoopModel, duration_s: float = 0.6,
                 band: float = 0.02) -> tuple[float | None, float | None]:
    """Overshoot (%) and 2 % settling time (ms) of the position loop's step response."""
    dt = lm.servo_period_s
    t = np.arange(0.0, duration_s, dt)
    resp = control.step_response(lm.position_closed_loop(), T=t)
    y = np.asarray(resp.outputs).reshape(-1)
    final = 1.0
    overshoot = max(0.0, (float(np.max(y)) - final) * 100.0)
    outside = np.nonzero(np.abs(y - final) > band)[0]
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
