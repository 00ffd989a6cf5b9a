"""The loop fitted from moves captured on the bench, where no analog output can drive SPD-CMD: a
real HA-655 in position mode moved by its controller's command pulses, recorded on CN2 (the
command pulses, the encoder outputs, SPD-MON) and imported (``bench import``: a recording with
``t``, ``cmd_pos``, ``pos``, ``vel``).

The drive's own parts are its items (Kp, Kv, Tv, feed-forward, in SI as ``physics.PanelGains``
reads them: the speed loop gain on the actuator's own inertia, so the gains do not depend on the
load, as on a real drive); the axis's inertia is what is fitted: a heavier load slows the loop the
same gains close around it. The linearised position loop of the one physics model (the gear's
spring at the catalogue's K1; ``LoopModel.polynomials``, its numpy form, evaluated for every
inertia the fit tries) is driven by the captured command, and the load inertia is the one whose
predicted encoder
position and speed match the captured ones best (scipy.optimize.least_squares on its logarithm,
each signal weighted by its own residual; the model's delay against the capture searched in whole
servo periods first). Its uncertainty is the least-squares one from the residuals, with the
samples counted as independent only as far as the residuals' correlation allows.

From the fitted axis follow the loop's figures (margins, crossover, bandwidth, the two-mass
resonance and anti-resonance: predicted from the fitted inertia and the catalogue's stiffness,
not measured) and the move's figures predicted beside the captured ones (overshoot, settling,
in-position time, following error: ``bench_move_figures``). What a capture without current cannot
tell is said with them (:data:`CANNOT_TELL`).

``verify_move`` predicts a capture for other tune items (a proposal typed on the front panel)
and compares: the verification after a worksheet.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy import optimize

from fha_studio.logic.bench.move import BenchMoveFigures, bench_move_figures
from fha_studio.logic.tuning.linear import LoopModel, two_mass_prediction
from fha_studio.logic.tuning.propose import TUNE_KEYS, Tuner, step_figures
from fha_studio.logic.tuning.response import loop_figures
from fha_studio.physics import AxisModel, servo_settings
from fha_studio.recording import Recording

TWO_PI = 2.0 * math.pi
RPM = TWO_PI / 60.0
#: the load inertia searched over, as multiples of the actuator's own
SEARCH_RATIOS = (0.0, 0.25, 0.5, 1.0, 2.0, 3.0, 5.0, 10.0, 20.0, 40.0)
#: a fit whose position residual (rms) is above this share of the peak following error does not hold
MAX_RESIDUAL_SHARE = 0.03
#: the window over which the command's acceleration is taken [s]
ACCEL_WINDOW_S = 0.01
#: a command asking for more than this share of the peak torque is shaped by the current limit
TORQUE_SHARE = 0.9
#: the model's delay against the capture, searched in whole servo periods
SHIFTS = range(-3, 4)
#: what a capture of command pulses, encoder outputs and SPD-MON cannot tell
CANNOT_TELL = (
    "a constant load torque and the direction-dependent part of friction: the speed loop's integral "
    "holds them, so neither position nor speed shows them (a current probe or the CN3 trace does)",
    "the inertia apart from the speed loop gain's scale: the fit takes the speed loop gain (tune 0) as "
    "the speed loop's crossover with the actuator's own inertia alone; the HA-655 manual gives it no "
    "unit, and a drive that means another scale by it moves the estimate in proportion",
    "the current and how close the move came to the current limit: a fit of a move that reached it "
    "is not linear",
    "the gear's resonance, unless the move excites it: the resonance given is the catalogue "
    "stiffness's with the fitted inertia, not measured (the SPD-CMD excitation measures it)",
    "the gain margin as a measurement: the margins are the fitted model's",
)


class MoveFitError(ValueError):
    """A recording that gives no fit: one line saying what is missing."""


@dataclass(frozen=True)
class MoveSamples:
    """A captured move at the servo rate: command and encoder position (rad), speed (rad/s or None)."""

    t_s: np.ndarray
    command_rad: np.ndarray
    position_rad: np.ndarray
    speed_rad_s: np.ndarray | None
    in_position: np.ndarray | None
    pulse_rad: float

    @classmethod
    def from_recording(cls, recording: Recording, servo_rate_hz: float, pulse_rad: float) -> MoveSamples:
        cmd = recording.cmd_pos_deg
        if cmd is None:
            raise MoveFitError("the recording has no command position: map the command pulses "
                               "(command_a, command_b) when importing the capture")
        t = recording.t_s
        if "pos" not in recording.channels or len(t) < 10:
            raise MoveFitError("the recording has no encoder position (encoder_a, encoder_b) or too few rows")
        grid = np.arange(t[0], t[-1], 1.0 / servo_rate_hz)
        vel = recording.vel_rpm
        in_pos = recording.in_pos
        command = np.radians(np.interp(grid, t, cmd))
        if np.ptp(command) < 10 * pulse_rad:
            raise MoveFitError("the command does not move in this recording: capture a move or a step")
        return cls(grid, command, np.radians(np.interp(grid, t, recording.pos_deg)),
                   None if vel is None else np.interp(grid, t, vel) * RPM,
                   None if in_pos is None else np.interp(grid, t, in_pos), pulse_rad)


def _model_with_load(declared: AxisModel, load_kgm2: float) -> AxisModel:
    return declared.replace(load_inertia_kgm2=max(0.0, float(load_kgm2)))


def predict(lm: LoopModel, samples: MoveSamples, shift: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Encoder position (rad) and mean speed (rad/s) the loop predicts for the captured command,
    ``shift`` servo periods later (the loop's numpy form, ``LoopModel.polynomials``: the fit
    evaluates it for every inertia it tries)."""
    pos = lm.polynomials().move(samples.command_rad)[0] - samples.command_rad[0] + samples.position_rad[0]
    if shift > 0:
        pos = np.concatenate([np.full(shift, pos[0]), pos[:-shift]])
    elif shift < 0:
        pos = np.concatenate([pos[-shift:], np.full(-shift, pos[-1])])
    speed = np.gradient(pos, lm.servo_period_s)
    return pos, speed


@dataclass(frozen=True)
class MoveFit:
    load_inertia_kgm2: float
    uncertainty_kgm2: float | None  # one standard deviation; None: not determined
    shift_periods: int
    position_rms_counts: float
    speed_rms_rpm: float | None
    model: AxisModel
    weights: tuple[float, float] = (1.0, 1.0)  # position (rad), speed (rad/s)


def _residuals(tuner: Tuner, samples: MoveSamples, load: float, shift: int,
               weights: tuple[float, float]) -> np.ndarray:
    """Captured minus predicted position (and speed), each over its weight."""
    lm = LoopModel(_model_with_load(tuner.model, load), tuner.loop({}).settings)
    pos, speed = predict(lm, samples, shift)
    parts = [(samples.position_rad - pos) / weights[0]]
    if samples.speed_rad_s is not None:
        parts.append((samples.speed_rad_s - speed) / weights[1])
    return np.concatenate(parts)


def _cost(tuner: Tuner, samples: MoveSamples, load: float, shift: int, weights: tuple[float, float]) -> float:
    try:
        r = _residuals(tuner, samples, load, shift, weights)
    except (ValueError, np.linalg.LinAlgError):
        return math.inf
    return float(np.dot(r, r)) if np.all(np.isfinite(r)) else math.inf


def _start(tuner: Tuner, samples: MoveSamples) -> tuple[float, int, tuple[float, float]]:
    """Where the fit starts: each signal weighted by its own size first (scale-free), the delay
    found with the declared load, the load searched over a grid, then each signal weighted by its
    own residual there and the delay searched again."""
    own = tuner.model.actuator_inertia_kgm2
    q = samples.pulse_rad
    speed = samples.speed_rad_s
    size = (max(float(np.std(samples.position_rad - samples.command_rad)), q),
            max(float(np.std(speed)), 1e-9) if speed is not None else 1.0)
    shift = min(SHIFTS, key=lambda s: _cost(tuner, samples, tuner.model.load_inertia_kgm2, s, size))
    load = min((_cost(tuner, samples, r * own, shift, size), r * own) for r in SEARCH_RATIOS)[1]
    r0 = _residuals(tuner, samples, load, shift, (q, 1.0))
    n = len(samples.position_rad)
    weights = (max(float(np.sqrt(np.mean(r0[:n] ** 2))) * q, q / math.sqrt(12.0)),
               max(float(np.sqrt(np.mean(r0[n:] ** 2))), 1e-9) if speed is not None else 1.0)
    load = min((_cost(tuner, samples, r * own, shift, weights), r * own) for r in SEARCH_RATIOS)[1]
    shift = min(SHIFTS, key=lambda s: _cost(tuner, samples, load, s, weights))
    return load, shift, weights


def fit_load(tuner: Tuner, samples: MoveSamples,
             start: tuple[float, int, tuple[float, float]] | None = None) -> MoveFit:
    """The load inertia whose linearised loop best predicts the captured move (see the module
    docstring); the drive's gains as ``tuner``'s items give them for its declared axis. ``start``:
    (load, delay, weights) to refine from instead of searching."""
    declared = tuner.model
    flange = declared.load_side_inertia_kgm2 - declared.load_inertia_kgm2
    own = declared.actuator_inertia_kgm2
    q = samples.pulse_rad
    nearest, best_shift, weights = start or _start(tuner, samples)

    def fun(x: np.ndarray) -> np.ndarray:
        return _residuals(tuner, samples, math.exp(float(x[0])) - flange, best_shift, weights)

    lower, upper = math.log(flange), math.log(flange + 100.0 * own + 1e-9)
    x0 = min(max(math.log(nearest + flange), lower + 1e-9), upper - 1e-9)
    fit = optimize.least_squares(fun, [x0], bounds=([lower], [upper]), x_scale=[0.3], diff_step=[1e-3])
    j_side = math.exp(float(fit.x[0]))
    load = j_side - flange
    r = fit.fun
    m = len(r)
    uncertainty = None
    jac = np.asarray(fit.jac, float)
    if m > 2 and np.any(jac):
        s2 = float(np.dot(r, r)) / (m - 1)
        # the residuals are correlated (a model's error is smooth): count samples per correlation length
        rho = float(np.corrcoef(r[:-1], r[1:])[0, 1])
        inflate = (1.0 + rho) / (1.0 - rho) if -1.0 < rho < 1.0 else float(m)
        uncertainty = j_side * math.sqrt(s2 / float(jac[:, 0] @ jac[:, 0]) * max(1.0, inflate))
    n = len(samples.position_rad)
    final = _residuals(tuner, samples, load, best_shift, (q, RPM))
    return MoveFit(
        load_inertia_kgm2=load, uncertainty_kgm2=uncertainty, shift_periods=best_shift,
        position_rms_counts=float(np.sqrt(np.mean(final[:n] ** 2))),
        speed_rms_rpm=float(np.sqrt(np.mean(final[n:] ** 2))) if samples.speed_rad_s is not None else None,
        model=_model_with_load(declared, load), weights=weights,
    )


def _part(samples: MoveSamples, part: slice) -> MoveSamples:
    def cut(a: np.ndarray | None) -> np.ndarray | None:
        return None if a is None else a[part]

    return MoveSamples(samples.t_s[part], samples.command_rad[part], samples.position_rad[part],
                       cut(samples.speed_rad_s), cut(samples.in_position), samples.pulse_rad)


def fit_with_spread(tuner: Tuner, samples: MoveSamples) -> MoveFit:
    """``fit_load``, its uncertainty widened by the spread between the capture's moves fitted one
    by one (a model's error the residuals do not show: the moves disagree by it)."""
    fit = fit_load(tuner, samples)
    first = _first_move(samples.command_rad, samples.pulse_rad)
    rest = slice(first.stop, len(samples.t_s))
    if rest.stop - rest.start < 50 or np.ptp(samples.command_rad[rest]) < 10 * samples.pulse_rad:
        return fit
    start = (fit.load_inertia_kgm2, fit.shift_periods, fit.weights)
    loads = [fit_load(tuner, _part(samples, part), start).load_inertia_kgm2 for part in (first, rest)]
    spread = abs(loads[0] - loads[1]) / 2.0
    return replace(fit, uncertainty_kgm2=math.hypot(fit.uncertainty_kgm2 or 0.0, spread))


def _first_move(command: np.ndarray, pulse_rad: float) -> slice:
    """The samples of the capture's first move: until the command starts moving again."""
    moving = np.abs(np.diff(command)) > 0.5 * pulse_rad
    changes = np.flatnonzero(moving)
    if not len(changes):
        return slice(0, len(command))
    gaps = np.flatnonzero(np.diff(changes) > 1)  # still periods between moving ones
    end = len(command) if not len(gaps) else int(changes[gaps[0] + 1])
    # a pause of under 10 periods is the same move (a command's steps)
    for g in gaps:
        if changes[g + 1] - changes[g] > 10:
            end = int(changes[g + 1])
            break
    else:
        end = len(command)
    return slice(0, end)


def _figures(samples: MoveSamples, position: np.ndarray) -> BenchMoveFigures:
    counts_per_deg = math.radians(1.0) / samples.pulse_rad
    part = _first_move(samples.command_rad, samples.pulse_rad)
    return bench_move_figures(samples.t_s[part], samples.command_rad[part] / samples.pulse_rad,
                              position[part] / samples.pulse_rad, None, counts_per_deg)


def _move_dict(f: BenchMoveFigures) -> dict[str, Any]:
    m = f.metrics
    return {"overshoot_pct": m.overshoot_percent,
            "settling_ms": None if m.settling_time_s is None else 1000.0 * (m.settling_time_s - 0.0),
            "following_error_peak_counts": f.following_error_peak_counts,
            "following_error_end_counts": f.following_error_end_counts}


def fit_quality(fit: MoveFit, samples: MoveSamples, declared: AxisModel) -> list[str]:
    """Why the fit does not hold, in words (empty: it does): a capture the linear loop does not
    follow (its residual more than ``MAX_RESIDUAL_SHARE`` of the following error), or a command
    that asks for more torque than the actuator has (then the current limit made the move)."""
    why = []
    error = samples.command_rad - samples.position_rad
    peak = max(float(np.max(np.abs(error))) / samples.pulse_rad, 1.0)
    residual = fit.position_rms_counts
    if residual > MAX_RESIDUAL_SHARE * peak:
        why.append(f"the loop model does not follow the capture (its position off by {residual:.3g} counts "
                   f"rms, {100 * residual / peak:.2g} % of the following error's {peak:.4g} counts)")
    # the command's acceleration over ACCEL_WINDOW_S (the command pulses' steps smoothed out)
    dt = float(samples.t_s[1] - samples.t_s[0])
    w = max(1, round(ACCEL_WINDOW_S / dt))
    speed = np.convolve(np.diff(samples.command_rad) / dt, np.ones(w) / w, mode="valid")
    accel = (speed[w:] - speed[:-w]) / (w * dt) if len(speed) > w else np.zeros(1)
    peak_accel = float(np.max(np.abs(accel)))
    for model in (fit.model, declared):
        torque = model.total_inertia_kgm2 * peak_accel
        if torque > TORQUE_SHARE * model.peak_torque_nm:
            why.append(f"the command accelerates at {peak_accel:.3g} rad/s², which asks {torque:.3g} N·m of "
                       f"the actuator's {model.peak_torque_nm:.4g} N·m with {model.total_inertia_kgm2:.3g} "
                       "kg·m²: the current limit shaped the move, not the loop (a gentler move)")
            break
    return why


def move_fit_report(tuner: Tuner, samples: MoveSamples) -> dict[str, Any]:
    """``tune analyse``'s JSON for a move: the fitted load inertia and the loop's figures with it
    (the keys of ``tune measure``; the frequency response is the fitted loop's, its coherence
    empty: nothing was measured in frequency), the move's figures captured and predicted. A fit
    that does not hold (:func:`fit_quality`) gives no inertia and says why."""
    fit = fit_with_spread(tuner, samples)
    problems = fit_quality(fit, samples, tuner.model)
    lm = LoopModel(fit.model, tuner.loop({}).settings)
    rate = tuner.servo_rate_hz
    figures = loop_figures(lm.speed_open_loop(), lm.speed_closed_loop(), 0.49 * rate)
    pair = two_mass_prediction(fit.model)
    freq = np.geomspace(0.5, 0.4 * rate, 200)
    mag, phase = lm.response("closed", freq)
    predicted_pos, _speed = predict(lm, samples, fit.shift_periods)
    measured = _figures(samples, samples.position_rad)
    predicted = _figures(samples, predicted_pos)
    overshoot, settling = step_figures(lm)
    return {
        "resonance_hz": pair.resonance_hz,
        "antiresonance_hz": pair.antiresonance_hz,
        "predicted_resonance_hz": two_mass_prediction(tuner.model).resonance_hz,
        "predicted_antiresonance_hz": two_mass_prediction(tuner.model).antiresonance_hz,
        "load_inertia_estimate_kgm2": None if problems else fit.load_inertia_kgm2,
        "load_inertia_uncertainty_kgm2": None if problems else fit.uncertainty_kgm2,
        "gain_margin_db": figures.gain_margin_db,
        "phase_margin_deg": figures.phase_margin_deg,
        "crossover_hz": figures.crossover_hz,
        "bandwidth_hz": figures.bandwidth_hz,
        "step": {"overshoot_pct": overshoot, "settling_ms": settling},
        "items": {k: v for k, v in tuner.items.items() if k in TUNE_KEYS},
        "frequency_response": {"freq_hz": [round(float(v), 4) for v in freq],
                               "magnitude_db": [round(float(v), 3) for v in mag],
                               "phase_deg": [round(float(v), 2) for v in phase], "coherence": []},
        "move": {"measured": _move_dict(measured), "predicted": _move_dict(predicted)},
        "fit": {"position_rms_counts": fit.position_rms_counts, "speed_rms_rpm": fit.speed_rms_rpm,
                "shift_periods": fit.shift_periods, "samples": len(samples.t_s)},
        "kind": "fitted from a move",
        "notes": [*(f"no load inertia: {why}" for why in problems),
                  *(f"cannot be told from a move without current: {what}" for what in CANNOT_TELL)],
    }


def verify_move(tuner: Tuner, items: Mapping[str, int], samples: MoveSamples,
                model: AxisModel | None = None) -> dict[str, Any]:
    """A move captured after typing ``items`` compared with what the loop predicts for them (the
    declared axis, or ``model``, e.g. the fitted one): the move's figures both ways and the RMS of
    the difference of the following error (counts)."""
    values = {**tuner.items, **items}
    axis = model or tuner.model
    lm = LoopModel(axis, servo_settings(tuner.model, values, tuner.servo_rate_hz, tuner.quantised_feedback))
    best = min(SHIFTS, key=lambda s: float(np.sum((samples.position_rad - predict(lm, samples, s)[0]) ** 2)))
    predicted_pos, _speed = predict(lm, samples, best)
    measured = _figures(samples, samples.position_rad)
    predicted = _figures(samples, predicted_pos)
    diff = (samples.position_rad - predicted_pos) / samples.pulse_rad
    return {"items": {k: int(v) for k, v in values.items() if k in TUNE_KEYS},
            "measured": _move_dict(measured), "predicted": _move_dict(predicted),
            "difference_rms_counts": float(np.sqrt(np.mean(diff**2))),
            "following_error_peak_counts": {"measured": measured.following_error_peak_counts,
                                            "predicted": predicted.following_error_peak_counts}}
