"""What a procedure may refer to for one actuator: ``build_context(code)`` (a plain nested dict).

Values come from the catalogue (:func:`fha_studio.catalog.get_actuator`): identity, the
combination table, tightening torques, the brake table, the cable colour tables of 1-14, the
environment limits of 3-3-1; the movable range of the sensor set (4-7-3) from
``resources/procedures/sensor-set.toml``. Keys (see the procedure
files for their use):

- ``actuator``: ``model_code, frame, frame_name, ratio, encoder, encoder_code, options,
  supply_voltage, output_resolution_ppr``
- ``flags``: ``brake, absolute, incremental, sensor_set`` and ``option_X`` for every option letter
- ``drivers`` (list), ``drivers_text``
- ``tightening.output_flange`` / ``tightening.flange``: ``screws, torque_nm, torque_kgf_cm,
  torque_min_nm, torque_max_nm`` (the accepted band of the torque wrench setting)
- ``brake`` (option B): ``supply_v, supply_tolerance_pct, supply_min_v, supply_max_v,
  activating_current_a, holding_current_a, holding_torque_nm``
- ``cables``: ``motor`` (the standard or the brake column), ``motor_column``,
  ``encoder_incremental_14``, ``encoder_incremental_4``, ``encoder_absolute`` (rows
  ``color, signal, reference``; empty when the encoder system has no such cable)
- ``environment``: ``temperature_min_c, temperature_max_c, humidity_min_pct, humidity_max_pct,
  vibration_max_m_s2, altitude_max_m, cable_bending_radius_min_mm, protection``
- ``sensor_set`` (every actuator, used with option L): ``ccw_limit_deg, cw_limit_deg,
  test_tolerance_deg, certain, section``
"""

from __future__ import annotations

import tomllib
from functools import cache
from typing import Any

from fha_studio.catalog import environment, get_actuator
from fha_studio.catalog.tables import load_toml
from fha_studio.paths import resource

# Accepted band around the recommended tightening torque when the wrench setting is entered:
# the manual gives one recommended value (3-3-2); +/-10 % is this tool's choice, said in the text.
TIGHTENING_BAND = 0.10
NM_PER_KGF_CM = 0.0980665


@cache
def _toml(name: str) -> dict[str, Any]:
    with resource("procedures", name).open("rb") as fh:
        return tomllib.load(fh)


def _screws(part: Any) -> str:
    text = f"{part.screw_count}-{part.screw_size}"
    if getattr(part, "screw_hole_depth_m", None):
        text += f" depth: {part.screw_hole_depth_m * 1000:g}"
    return text


def _printed_kgf_cm(part_name: str, frame: str) -> float | None:
    # The catalogue's Actuator carries N m only; the manual's own kgf cm column is in its table.
    try:
        return float(load_toml("mechanical")["tightening"][part_name]["torque_kgf_cm"][frame])
    except (KeyError, TypeError, ValueError, FileNotFoundError):
        return None


def _tightening(part: Any, part_name: str, frame: str) -> dict[str, Any]:
    torque = float(part.torque_nm)
    kgf_cm = getattr(part, "torque_kgf_cm", None) or _printed_kgf_cm(part_name, frame)
    if kgf_cm is None:
        kgf_cm = round(torque / NM_PER_KGF_CM)
    return {
        "screws": _screws(part),
        "torque_nm": f"{torque:g}",
        "torque_kgf_cm": f"{float(kgf_cm):g}",
        "torque_min_nm": round(torque * (1 - TIGHTENING_BAND), 3),
        "torque_max_nm": round(torque * (1 + TIGHTENING_BAND), 3),
    }


def _rows(leads: Any) -> list[dict[str, str]]:
    return [
        {"color": lead.colour, "signal": lead.signal, "reference": lead.reference or "-"} for lead in leads
    ]


def build_context(code: str) -> dict[str, Any]:
    """The context of the actuator with model code ``code`` (ModelCodeError if the code is wrong)."""
    actuator = get_actuator(code)
    options = sorted(actuator.options)
    absolute = actuator.encoder == "absolute"
    brake = actuator.brake is not None
    drivers = list(actuator.compatible_drivers)
    leads = actuator.cables
    env = environment()
    sensor_set = _toml("sensor-set.toml")
    movable = sensor_set["movable_range"][actuator.frame]
    context: dict[str, Any] = {
        "actuator": {
            "model_code": actuator.model_code,
            "frame": actuator.frame,
            "frame_name": f"FHA-{actuator.frame}",
            "ratio": actuator.ratio,
            "encoder": actuator.encoder,
            "encoder_code": actuator.encoder_code,
            "options": options,
            "supply_voltage": actuator.supply_voltage,
            "output_resolution_ppr": actuator.output_resolution_ppr,
        },
        "flags": {
            "brake": brake,
            "absolute": absolute,
            "incremental": not absolute,
            "sensor_set": "L" in actuator.options,
            **{f"option_{o}": True for o in options},
        },
        "drivers": drivers,
        "drivers_text": ", ".join(drivers) or "none (the manual lists no driver for this combination)",
        "tightening": {
            "output_flange": _tightening(actuator.tightening.output_flange, "output_flange", actuator.frame),
            "flange": _tightening(actuator.tightening.mounting_flange, "mounting_flange", actuator.frame),
        },
        "cables": {
            "motor_column": "brake option" if brake else "standard",
            "motor": _rows(leads.motor),
            "encoder_incremental_14": _rows(leads.encoder.get("14-wire", ())),
            "encoder_incremental_4": _rows(leads.encoder.get("4-wire", ())),
            "encoder_absolute": _rows(leads.encoder.get("absolute", ())),
        },
        "environment": {
            "temperature_min_c": env.service_temperature_min_c,
            "temperature_max_c": env.service_temperature_max_c,
            "humidity_min_pct": env.humidity_min_percent_rh,
            "humidity_max_pct": env.humidity_max_percent_rh,
            "vibration_max_m_s2": env.vibration_max_m_per_s2,
            "altitude_max_m": env.altitude_max_m,
            "cable_bending_radius_min_mm": round(env.min_cable_bending_radius_m * 1000, 3),
            "protection": env.protection,
        },
        "sensor_set": {
            "ccw_limit_deg": float(movable["ccw_limit_deg"]),
            "cw_limit_deg": float(movable["cw_limit_deg"]),
            "certain": bool(movable.get("certain", True)),
            "section": movable.get("section", "4-7-3"),
            "test_tolerance_deg": float(sensor_set["sensor_set"]["test_tolerance_deg"]),
        },
    }
    b = actuator.brake
    if brake and b is not None:
        volts, pct = float(b.supply_voltage_v), float(b.supply_tolerance_percent)
        context["brake"] = {
            "supply_v": f"{volts:g}",
            "supply_tolerance_pct": f"{pct:g}",
            "supply_min_v": round(volts * (1 - pct / 100), 3),
            "supply_max_v": round(volts * (1 + pct / 100), 3),
            "activating_current_a": float(b.activating_current_a),
            "holding_current_a": float(b.holding_current_a),
            "holding_torque_nm": f"{float(b.holding_torque_nm):g}",
        }
    return context
