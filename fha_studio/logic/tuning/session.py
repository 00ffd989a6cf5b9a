"""One tuning measurement or proposal on a connected drive, as the command line's JSON."""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from fha_studio.hardware.parameters import Mode, ParameterModel
from fha_studio.hardware.sim.axis import DEFAULT_SERVO_RATE_HZ
from fha_studio.logic.drive_session import WriteEntry, read_parameters, write_parameters
from fha_studio.logic.paramfile import dump_parameter_file
from fha_studio.logic.procedures.live import output_angle_deg
from fha_studio.logic.tuning.excitation import BiasDirection, ExcitationPlan, plan_excitation
from fha_studio.logic.tuning.linear import LoopModel, two_mass_prediction
from fha_studio.logic.tuning.measure import measure
from fha_studio.logic.tuning.move import VERIFY_MOVE_DEG, MoveFigures, measure_move
from fha_studio.logic.tuning.propose import TUNE_KEYS, Tuner
from fha_studio.logic.tuning.response import (
    FrequencyResponse,
    bandwidth_hz,
    estimate_response,
    fit_two_mass,
    loop_figures,
    measured_loop_figures,
)
from fha_studio.logic.tuning.travel import MovableRange, check_travel
from fha_studio.physics import AxisModel, Effects

__all__ = ["VERIFY_MOVE_DEG", "backup_parameters", "declared_model", "drive_clock", "drive_items",
           "fwd_is_cw", "measure_report", "planned_travel", "response_figures", "tuner_for", "verify_move",
           "write_tune_items"]


def drive_clock(client: Any) -> tuple[Callable[[float], None], Callable[[], float]]:
    """How to wait on the drive behind ``client``: (pace between two looks at it, the longest its
    time can have run since a moment). A stepped simulated drive's own advance and clock; for a
    drive that runs by itself nothing between looks (the link paces them) and the computer's
    clock, which a drive's time never outruns."""
    from fha_studio.hardware.sim import stepped_clock

    return stepped_clock(client) or (_no_pace, time.monotonic)


def _no_pace(_seconds: float) -> None:
    """The link's own round trips pace the looks at a drive that runs by itself."""


def declared_model(actuator: str, load_inertia_kgm2: float) -> AxisModel:
    """The axis as declared: the catalogue actuator, the load inertia, the gear's spring (1-9-2)."""
    return AxisModel.from_code(actuator, load_inertia_kgm2=load_inertia_kgm2,
                               effects=Effects().with_effect("torsional_compliance"))


def drive_items(client: Any, parameters: ParameterModel) -> dict[str, int]:
    """The tune and parameter-mode items the loops depend on, and the JOG acceleration the
    verification move is made with, read from the drive."""
    keys = (*TUNE_KEYS, "electronic_gear_numerator", "electronic_gear_denominator", "rotary_direction",
            "in_position_range", "control_mode", "jog_acceleration")
    out = {}
    for key in keys:
        item = parameters.by_key(key)
        out[key] = int(client.read_parameter(item.mode, item.number))
    return out


def tuner_for(client: Any, parameters: ParameterModel, model: AxisModel,
              quantised_feedback: bool = True) -> Tuner:
    items = drive_items(client, parameters)
    return Tuner(model, items, parameters, DEFAULT_SERVO_RATE_HZ, quantised_feedback)


def fwd_is_cw(tuner: Tuner) -> bool | None:
    """What a FWD command turns the output, seen from the flange (1-10: CW with rotary direction 0),
    from the drive's rotary direction item; None where it was not read."""
    value = tuner.items.get("rotary_direction")
    return None if value is None else int(value) == 0


def planned_travel(client: Any, tuner: Tuner, plan: ExcitationPlan,
                   switch_angles_deg: Mapping[str, float] | None = None, manual_units: bool = False) -> str:
    """The plan in words with the room it has: the limit switches' switching angles (as the
    procedures record them) against the present position read from the drive, or that the
    movable range is not known. Raises ``travel.TravelRefused`` (one line) where it does not fit."""
    movable = None
    if switch_angles_deg:
        position_deg = output_angle_deg(client, tuner.model.output_resolution_ppr)[0]
        movable = MovableRange.from_switch_angles(switch_angles_deg, position_deg)
    room = check_travel(plan, movable, fwd_is_cw(tuner), manual_units)
    warning = f"; {IN_PLACE_WARNING}" if plan.bias_direction is BiasDirection.NONE else ""
    return f"{plan.describe(manual_units, fwd_is_cw(tuner))}; {room}{warning}"


def measure_report(client: Any, tuner: Tuner, pace: Callable[[float], None],
                   now: Callable[[], float] = time.monotonic, amplitude_rpm: float | None = None,
                   announce: Callable[[str], None] = lambda _s: None,
                   should_stop: Callable[[], bool] = lambda: False,
                   bias: BiasDirection | bool | str = BiasDirection.FWD,
                   switch_angles_deg: Mapping[str, float] | None = None,
                   manual_units: bool = False) -> dict[str, Any]:
    """Excite, measure and analyse; the JSON of ``tune measure``. ``pace`` and ``now``: as
    ``measure.measure`` takes them (the drive's own time); ``bias``: the bias speed's direction,
    FWD or REV (NONE or False: about standstill, for an axis that may not turn that far; the
    friction then shows, and is warned of); ``switch_angles_deg``: the limit switches' angles,
    where known: a plan that does not fit the room to them is refused before anything moves
    (``travel.TravelRefused``, in the manual's units with ``manual_units``, as a page says it)."""
    lm: LoopModel = tuner.loop({})
    plan = plan_excitation(lm, amplitude_rpm, bias)
    announce(planned_travel(client, tuner, plan, switch_angles_deg, manual_units))
    records = measure(client, plan, tuner.servo_rate_hz, pace, now, should_stop,
                      output_ppr=tuner.model.output_resolution_ppr,
                      jog_accel_rpm_s=float(tuner.items.get("jog_acceleration", 1)))
    closed = estimate_response(records.closed_loop(), records.sample_rate_hz, f_max_hz=plan.f_max_hz)
    plant = estimate_response(records.plant(), records.sample_rate_hz, f_max_hz=plan.f_max_hz)
    return {
        **response_figures(tuner, lm, closed, plant, records.sample_rate_hz),
        "stick_slip_warning": stick_slip_warning(records.reversal_share()),
        "excitation": {"amplitude_rpm": plan.amplitude_rpm, "travel_bound_deg": plan.travel_bound_deg,
                       "travel_limit_deg": plan.travel_limit_deg, "hold_periods": plan.hold_periods,
                       "records": plan.records, "travelled_deg": records.travel_deg(),
                       "bias_rpm": plan.bias_rpm, "bias_direction": str(plan.bias_direction),
                       "bias_travel_deg": plan.bias_travel_deg},
    }


#: what the plan says of a measurement about standstill, before it starts
IN_PLACE_WARNING = ("in place the axis sticks on its friction at every reversal: the low frequencies and the "
                    "inertia estimate are not to be trusted")

#: speed reversals at more than this share of the samples: the friction spoils the response
REVERSALS_SHARE = 0.001


def stick_slip_warning(reversal_share: float) -> str | None:
    """Why a measurement whose speed reversed is not to be trusted at low frequency, or None. The
    coherence does not show it: the stick-slip repeats with the periodic excitation."""
    if reversal_share <= REVERSALS_SHARE:
        return None
    return (f"the output speed reversed or stood still at {reversal_share:.1%} of the samples: the axis "
            "sticks on its friction at each reversal, so the response loses gain at low frequency and the "
            "load inertia estimate is not to be trusted; measure on a bias speed (the default)")


def response_figures(tuner: Tuner, lm: LoopModel, closed: FrequencyResponse, plant: FrequencyResponse,
                     sample_rate_hz: float) -> dict[str, Any]:
    """The figures of a measured closed loop and plant (torque -> speed, as ``lm.plant()``), as
    ``tune measure``'s JSON: the two-mass fit (resonance, anti-resonance, inertia), the margins
    with the plant as measured, the bandwidth, and what the declared model predicts. One path for
    every measurement: over CN3 and from the bench."""
    fit = fit_two_mass(plant, sample_rate_hz)
    figures = loop_figures(lm.speed_open_loop(), lm.speed_closed_loop(), 0.49 * tuner.servo_rate_hz)
    measured = measured_loop_figures(lm.speed_open_loop(), lm.plant(), plant)
    predicted = two_mass_prediction(tuner.model)
    own = tuner.model.actuator_inertia_kgm2
    trusted = plant.freq_hz[plant.trusted()]
    return {
        "resonance_hz": fit.resonance_hz if fit else None,
        "antiresonance_hz": fit.antiresonance_hz if fit else None,
        "predicted_resonance_hz": predicted.resonance_hz,
        "predicted_antiresonance_hz": predicted.antiresonance_hz,
        "load_inertia_estimate_kgm2": None if fit is None else fit.total_inertia_kgm2 - own,
        # the viscous friction fitted apart from the inertia (on a bias speed; about standstill the
        # stick-slip passes for it too)
        "viscous_friction_estimate_nm_s_per_rad": None if fit is None else fit.viscous_nm_s_per_rad,
        "gain_margin_db": measured.gain_margin_db,
        "phase_margin_deg": measured.phase_margin_deg,
        "crossover_hz": measured.crossover_hz,
        # the band the measured margins cover: a phase crossing above it is the model's alone
        "measured_to_hz": float(trusted.max()) if len(trusted) else None,
        "predicted": {"gain_margin_db": figures.gain_margin_db, "phase_margin_deg": figures.phase_margin_deg,
                      "crossover_hz": figures.crossover_hz, "bandwidth_hz": figures.bandwidth_hz},
        "bandwidth_hz": bandwidth_hz(closed),
        "items": {k: v for k, v in tuner.items.items() if k in TUNE_KEYS},
        "frequency_response": closed.to_dict(),
        "plant_response": plant.to_dict(),
    }


def backup_parameters(client: Any, parameters: ParameterModel, actuator: str, path: Path) -> Path:
    """Read every writable tune and parameter-mode item and save them as a parameter file (the
    backup every write is preceded by). Raises ValueError when an item cannot be read."""
    keys = [(item.mode, item.number) for item in parameters
            if item.mode in (Mode.TUNE, Mode.SYSTEM) and item.writable]
    readout = read_parameters(client, keys)
    if readout.errors:
        (mode, number), why = next(iter(readout.errors.items()))
        raise ValueError(f"backup: {mode} item {number} could not be read ({why}): nothing written")
    identity = client.identify()
    driver = identity.driver_model if identity is not None else parameters.driver
    text = dump_parameter_file(parameters, dict(readout.values.items()), actuator, driver)
    path.write_text(text, encoding="utf-8")
    return path


def write_tune_items(client: Any, parameters: ParameterModel, items: dict[str, int]) -> list[WriteEntry]:
    """Write the tune items, each verified by read-back (the parameter write path); ValueError
    naming the first that did not verify."""
    writes = []
    for key in TUNE_KEYS:
        item = parameters.by_key(key)
        writes.append((item.mode, item.number, int(items[key])))
    entries = write_parameters(client, writes)
    for entry in entries:
        if not entry.get("verified"):
            item = parameters.item(entry["mode"], entry["number"])
            raise ValueError(f"tune item {item.key}: {entry.get('error') or 'not verified'}")
    return entries


def verify_move(client: Any, parameters: ParameterModel, tuner: Tuner,
                pace: Callable[[float], None]) -> MoveFigures:
    """The verification move (``move.verification_move``: 90 deg at half the maximum speed, at an
    acceleration the axis can follow), measured through the trace: the test item "JOG
    acceleration" is lowered for the move when the axis could not follow it, and put back after."""
    profile = tuner.move_profile()
    accel_item = parameters.by_key("jog_acceleration")
    present = int(client.read_parameter(accel_item.mode, accel_item.number))
    lowered = profile.accel_rpm_s < present
    if lowered:
        client.write_parameter(accel_item.mode, accel_item.number, int(profile.accel_rpm_s))
    try:
        return measure_move(client, profile, tuner.servo_rate_hz, tuner.model.output_resolution_ppr,
                            tuner.items["in_position_range"], pace)
    finally:
        if lowered:
            client.write_parameter(accel_item.mode, accel_item.number, present)
