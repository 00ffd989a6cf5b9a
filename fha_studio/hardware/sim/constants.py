"""Typed loader for resources/drive/sim-drive.toml: the simulated drive's constants."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, fields
from functools import cache
from typing import Any

from fha_studio.paths import resource


@dataclass(frozen=True)
class SimConstants:
    """Constants of the simulated drive; units in the names. See the TOML for each source."""

    jog_watchdog_s: float
    jog_watchdog_stop_s: float
    jog_watchdog_torque_share: float
    standstill_speed_rpm: float
    standstill_s: float
    oww_clear_s: float
    regeneration_resistor_w: float
    regeneration_energy_capacity_j: float
    overload_time_at_max_current_s: float
    over_speed_factor: float
    alarm_history_length: int
    origin_angle_deg: float
    origin_slit_width_deg: float
    limit_switch_1_angle_deg: float
    limit_switch_2_angle_deg: float
    limit_dog_arc_deg: float
    wiring_fault_trip_s: float
    wiring_fault_lurch_deg: float
    lost_multi_turn_turns: int


@cache
def load_sim_constants() -> SimConstants:
    """Read resources/drive/sim-drive.toml; raises ValueError naming the file and the item."""
    path = resource("drive", "sim-drive.toml")
    with path.open("rb") as f:
        data = tomllib.load(f)
    values: dict[str, Any] = {}
    for field in fields(SimConstants):
        entry = data.get(field.name)
        if not isinstance(entry, dict) or "value" not in entry:
            raise ValueError(f"{path}: [{field.name}] with a value is missing")
        kind = int if field.type in (int, "int") else float
        values[field.name] = kind(entry["value"])
    return SimConstants(**values)
