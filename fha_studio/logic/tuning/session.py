"""One tuning measurement or proposal on a connected drive, as the command line's JSON."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from fha_studio.hardware.parameters import Mode, ParameterModel
from fha_studio.hardware.sim.axis import DEFAULT_SERVO_RATE_HZ
from fha_studio.logic.tuning.excitation import plan_excitation
from fha_studio.logic.tuning.linear import LoopModel, two_mass_prediction
from fha_studio.logic.tuning.measure import measure
from fha_studio.logic.tuning.propose import TUNE_KEYS, Tuner
from fha_studio.logic.tuning.response import (
    estimate_response,
    fit_two_mass,
    loop_figures,
)
from fha_studio.physics import AxisModel, Effects


def declared_model(actuator: str, load_inertia_kgm2: float) -> AxisModel:
    """The axis as declared: the catalogue actuator, the load inertia, the gear's spring (1-9-2)."""
    return AxisModel.from_code(actuator, load_inertia_kgm2=load_inertia_kgm2,
                               effects=Effects().with_effect("torsional_compliance"))


def drive_items(client: Any, parameters: ParameterModel) -> dict[str, int]:
    """The tune and parameter-mode items the loops depend on, read from the drive."""
    keys = (*TUNE_KEYS, "electronic_gear_numerator", "electronic_gear_denominator", "rotary_direction",
            "in_position_range", "control_mode")
    out = {}
    for key in keys:
        item = parameters.by_key(key)
        out[key] = int(client.read_parameter(item.mode, item.number))
    return out


def tuner_for(client: Any, parameters: ParameterModel, model: AxisModel,
              quantised_feedback: bool = True) -> Tuner:
    items = drive_items(client, parameters)
    return Tuner(model, items, parameters, DEFAULT_SERVO_RATE_HZ, quantised_feedback)


def measure_report(client: Any, tuner: Tuner, wait: Callable[[float], None], now: Callable[[], float],
                   amplitude_rpm: float | None = None, announce: Callable[[str], None] = lambda _s: None,
                   should_stop: Callable[[], bool] = lambda: False) -> dict[str, Any]:
    """Excite, measure and analyse; the JSON of ``tune measure``."""
    lm: LoopModel = tuner.loop({})
    plan = plan_excitation(lm, amplitude_rpm)
    announce(plan.describe())
    records = measure(client, plan, tuner.servo_rate_hz, wait, now, should_stop,
                      output_ppr=tuner.model.output_resolution_ppr)
    closed = estimate_response(records.closed_loop(), records.sample_rate_hz, f_max_hz=plan.f_max_hz)
    plant = estimate_response(records.plant(), records.sample_rate_hz, f_max_hz=plan.f_max_hz)
    fit = fit_two_mass(plant, records.sample_rate_hz)
    figures = loop_figures(lm.speed_open_loop(), lm.speed_closed_loop(), 0.49 * tuner.servo_rate_hz)
    predicted = two_mass_prediction(tuner.model)
    own = tuner.model.actuator_inertia_kgm2
    return {
        "resonance_hz": fit.resonance_hz if fit else None,
        "antiresonance_hz": fit.antiresonance_hz if fit else None,
        "predicted_resonance_hz": predicted.resonance_hz,
        "predicted_antiresonance_hz": predicted.antiresonance_hz,
        "load_inertia_estimate_kgm2": None if fit is None else fit.total_inertia_kgm2 - own,
        "gain_margin_db": figures.gain_margin_db,
        "phase_margin_deg": figures.phase_margin_deg,
        "crossover_hz": figures.crossover_hz,
        "bandwidth_hz": figures.bandwidth_hz,
        "excitation": {"amplitude_rpm": plan.amplitude_rpm, "travel_bound_deg": plan.travel_bound_deg,
                       "travel_limit_deg": plan.travel_limit_deg, "hold_periods": plan.hold_periods,
                       "records": plan.records},
        "items": {k: v for k, v in tuner.items.items() if k in TUNE_KEYS},
        "frequency_response": closed.to_dict(),
        "plant_response": plant.to_dict(),
    }


def write_items(client: Any, parameters: ParameterModel, items: dict[str, int]) -> None:
    """Write tune items and read each back (a verified write)."""
    for key, value in items.items():
        item = parameters.by_key(key)
        if item.mode is not Mode.TUNE:
            continue
        client.write_parameter(item.mode, item.number, int(value))
        back = int(client.read_parameter(item.mode, item.number))
        if back != int(value):
            raise ValueError(f"tune item {key}: wrote {value}, the drive reads back {back}")
