"""Typed loader of the FHA-C manual's tables in ``resources/catalog/*.toml``.

Each table is read once (cached) into frozen dataclasses. Values are the values used; where the
manual contradicts itself, :func:`discrepancies` gives the printed values and the reason.
Units are in the names; per-ratio values are tuples in the order of ``RATIOS``.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

from fha_studio.paths import resource

FRAMES: tuple[str, ...] = ("17C", "25C", "32C", "40C")
RATIOS: tuple[int, ...] = (50, 100, 160)
ENCODERS: tuple[str, ...] = ("incremental", "absolute")
VOLTAGES: tuple[int, ...] = (200, 100)


class CatalogDataError(RuntimeError):
    """A catalogue file is missing a value or has the wrong shape (a bug in resources/, not user input)."""


@cache
def load_toml(name: str) -> dict[str, Any]:
    """The parsed ``resources/catalog/<name>.toml`` (cached; do not mutate)."""
    path: Path = resource("catalog", f"{name}.toml")
    with path.open("rb") as fh:
        return tomllib.load(fh)


def _per_ratio(values: Any, where: str) -> tuple[Any, ...]:
    """One value per ratio: a number, or a list of numbers (a row per ratio)."""
    if not isinstance(values, list) or len(values) != len(RATIOS):
        raise CatalogDataError(f"{where}: expected {len(RATIOS)} values (ratios {RATIOS}), got {values!r}")
    return tuple(v if isinstance(v, list) else float(v) for v in values)


def _per_voltage(table: Any, where: str, per_ratio: bool) -> dict[int, Any]:
    if not isinstance(table, dict) or sorted(table) != sorted(str(v) for v in VOLTAGES):
        raise CatalogDataError(f"{where}: expected values for {VOLTAGES} V, got {table!r}")
    return {int(k): (_per_ratio(v, f"{where}[{k}]") if per_ratio else float(v)) for k, v in table.items()}


# --- 1-4-1 / 1-4-2 ------------------------------------------------------------------------------


@dataclass(frozen=True)
class FrameSpecs:
    """One frame of the 1-4-1 (incremental) or 1-4-2 (absolute) specification table.

    Per-ratio tuples follow RATIOS; ``*_by_voltage`` map the supply voltage (200, 100) to the row.
    """

    encoder: str
    frame: str
    section: str
    encoder_code: str
    motor_encoder_ppr: int
    quadrature_factor: int
    max_torque_nm: tuple[float, ...]
    max_speed_rpm: tuple[float, ...]
    torque_constant_nm_per_a_by_voltage: dict[int, tuple[float, ...]]
    max_current_a_by_voltage: dict[int, tuple[float, ...]]
    emf_constant_v_per_rpm_by_voltage: dict[int, tuple[float, ...]]
    phase_resistance_ohm_by_voltage: dict[int, float]
    phase_inductance_mh_by_voltage: dict[int, float]
    inertia_kgm2: tuple[float, ...]
    inertia_kgf_cm_s2: tuple[float, ...]
    allowable_radial_load_kn: float
    allowable_axial_load_kn: float
    allowable_torsional_moment_nm: float
    moment_stiffness_nm_per_rad: float
    one_way_accuracy_arcsec: tuple[float, ...]
    output_resolution_ppr: tuple[int, ...]
    mass_kg: float


@cache
def spec_table(encoder: str, frame: str) -> FrameSpecs:
    """The 1-4-1 (``encoder="incremental"``) or 1-4-2 (``"absolute"``) column group of one frame."""
    data = load_toml("specs")
    head = data[encoder]
    row = head[frame]
    where = f"specs.toml [{encoder}.{frame}]"
    return FrameSpecs(
        encoder=encoder,
        frame=frame,
        section=head["section"],
        encoder_code=head["encoder_code"],
        motor_encoder_ppr=int(head["motor_encoder_ppr"]),
        quadrature_factor=int(head["quadrature_factor"]),
        max_torque_nm=_per_ratio(row["max_torque_nm"], where),
        max_speed_rpm=_per_ratio(row["max_speed_rpm"], where),
        torque_constant_nm_per_a_by_voltage=_per_voltage(row["torque_constant_nm_per_a"], where, True),
        max_current_a_by_voltage=_per_voltage(row["max_current_a"], where, True),
        emf_constant_v_per_rpm_by_voltage=_per_voltage(row["emf_constant_v_per_rpm"], where, True),
        phase_resistance_ohm_by_voltage=_per_voltage(row["phase_resistance_ohm"], where, False),
        phase_inductance_mh_by_voltage=_per_voltage(row["phase_inductance_mh"], where, False),
        inertia_kgm2=_per_ratio(row["inertia_kgm2"], where),
        inertia_kgf_cm_s2=_per_ratio(row["inertia_kgf_cm_s2"], where),
        allowable_radial_load_kn=float(row["allowable_radial_load_kn"]),
        allowable_axial_load_kn=float(row["allowable_axial_load_kn"]),
        allowable_torsional_moment_nm=float(row["allowable_torsional_moment_nm"]),
        moment_stiffness_nm_per_rad=float(row["moment_stiffness_nm_per_rad"]),
        one_way_accuracy_arcsec=_per_ratio(row["one_way_accuracy_arcsec"], where),
        output_resolution_ppr=tuple(int(v) for v in _per_ratio(row["output_resolution_ppr"], where)),
        mass_kg=float(row["mass_kg"]),
    )


# --- 1-9-2 / 1-9-1 ------------------------------------------------------------------------------


@dataclass(frozen=True)
class TorsionalStiffnessRow:
    """1-9-2 for one frame: T1, T2 per frame; K1..K3, theta1, theta2 per ratio (SI used, kgf as printed)."""

    frame: str
    t1_nm: float
    t1_kgf_m: float
    t2_nm: float
    t2_kgf_m: float
    k1_nm_per_rad: tuple[float, ...]
    k1_kgf_m_per_arcmin: tuple[float, ...]
    k2_nm_per_rad: tuple[float, ...]
    k2_kgf_m_per_arcmin: tuple[float, ...]
    k3_nm_per_rad: tuple[float, ...]
    k3_kgf_m_per_arcmin: tuple[float, ...]
    theta1_rad: tuple[float, ...]
    theta1_arcmin: tuple[float, ...]
    theta2_rad: tuple[float, ...]
    theta2_arcmin: tuple[float, ...]


@cache
def torsional_stiffness_table(frame: str) -> TorsionalStiffnessRow:
    """The 1-9-2 torsional stiffness values of one frame."""
    row = load_toml("stiffness")["torsional"][frame]
    where = f"stiffness.toml [torsional.{frame}]"
    per = {
        k: _per_ratio(row[k], where)
        for k in (
            "k1_nm_per_rad",
            "k1_kgf_m_per_arcmin",
            "k2_nm_per_rad",
            "k2_kgf_m_per_arcmin",
            "k3_nm_per_rad",
            "k3_kgf_m_per_arcmin",
            "theta1_rad",
            "theta1_arcmin",
            "theta2_rad",
            "theta2_arcmin",
        )
    }
    return TorsionalStiffnessRow(
        frame=frame,
        t1_nm=float(row["t1_nm"]),
        t1_kgf_m=float(row["t1_kgf_m"]),
        t2_nm=float(row["t2_nm"]),
        t2_kgf_m=float(row["t2_kgf_m"]),
        **per,
    )


@dataclass(frozen=True)
class WindupTable:
    """1-9-2 "torque-wind-up relation for reference": torque (N·m) at ``windup_arcmin`` per frame/ratio."""

    windup_arcmin: tuple[float, ...]
    torque_nm: dict[tuple[str, int], tuple[float, ...]]


@cache
def windup_table() -> WindupTable:
    """The reference table of torque at 2, 4 and 6 arc-min wind-up (1-9-2)."""
    t = load_toml("stiffness")["windup_torque"]
    arcmin = tuple(float(v) for v in t["windup_arcmin"])
    torque: dict[tuple[str, int], tuple[float, ...]] = {}
    for frame in FRAMES:
        for ratio, row in zip(
            RATIOS, _per_ratio(t[frame], f"stiffness.toml windup_torque.{frame}"), strict=True
        ):
            torque[(frame, ratio)] = tuple(float(v) for v in row)
    return WindupTable(windup_arcmin=arcmin, torque_nm=torque)


@dataclass(frozen=True)
class MomentStiffnessRow:
    """1-9-1 moment stiffness of one frame (SI used; kgf columns as printed)."""

    frame: str
    nm_per_rad: float
    kgf_m_per_rad: float
    kgf_m_per_arcmin: float


@cache
def moment_stiffness_table(frame: str) -> MomentStiffnessRow:
    m = load_toml("stiffness")["moment"]
    return MomentStiffnessRow(
        frame=frame,
        nm_per_rad=float(m["moment_stiffness_nm_per_rad"][frame]),
        kgf_m_per_rad=float(m["moment_stiffness_kgf_m_per_rad"][frame]),
        kgf_m_per_arcmin=float(m["moment_stiffness_kgf_m_per_arcmin"][frame]),
    )


# --- Chapter 2 ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class AllowableInertiaRow:
    """2-1 allowable load inertia of one frame, per ratio (reference values)."""

    frame: str
    max_speed_rpm: tuple[float, ...]
    actuator_inertia_kgm2: tuple[float, ...]
    actuator_inertia_kgf_cm_s2: tuple[float, ...]
    allowable_inertia_kgm2: tuple[float, ...]
    allowable_inertia_kgf_cm_s2: tuple[float, ...]


@cache
def allowable_inertia_table(frame: str) -> AllowableInertiaRow:
    t = load_toml("selection")["allowable_inertia"]
    where = f"selection.toml [allowable_inertia] {frame}"
    return AllowableInertiaRow(
        frame=frame,
        **{
            k: _per_ratio(t[k][frame], where)
            for k in (
                "max_speed_rpm",
                "actuator_inertia_kgm2",
                "actuator_inertia_kgf_cm_s2",
                "allowable_inertia_kgm2",
                "allowable_inertia_kgf_cm_s2",
            )
        },
    )


@dataclass(frozen=True)
class ContinuousRow:
    """2-4-6 allowable continuous torque (N·m) and speed (r/min) of one frame, per ratio (200 V)."""

    frame: str
    continuous_torque_nm: tuple[float, ...]
    continuous_speed_rpm: tuple[float, ...]


@cache
def continuous_table(frame: str) -> ContinuousRow:
    t = load_toml("selection")["continuous"]
    where = f"selection.toml [continuous] {frame}"
    return ContinuousRow(
        frame=frame,
        continuous_torque_nm=_per_ratio(t["continuous_torque_nm"][frame], where),
        continuous_speed_rpm=_per_ratio(t["continuous_speed_rpm"][frame], where),
    )


# --- 4-2-1 brake --------------------------------------------------------------------------------


@dataclass(frozen=True)
class BrakeRow:
    """4-2-1 brake option of one frame (incremental system table), per ratio where the manual varies."""

    frame: str
    activating_current_a: float
    holding_current_a: float
    holding_torque_nm: tuple[float, ...]
    holding_torque_kgf_m: tuple[float, ...]
    inertia_kgm2: tuple[float, ...]
    inertia_kgf_cm_s2: tuple[float, ...]
    mass_kg: float


@cache
def brake_table(frame: str) -> BrakeRow:
    row = load_toml("brake")["frame"][frame]
    where = f"brake.toml [frame.{frame}]"
    return BrakeRow(
        frame=frame,
        activating_current_a=float(row["activating_current_a"]),
        holding_current_a=float(row["holding_current_a"]),
        holding_torque_nm=_per_ratio(row["holding_torque_nm"], where),
        holding_torque_kgf_m=_per_ratio(row["holding_torque_kgf_m"], where),
        inertia_kgm2=_per_ratio(row["inertia_kgm2"], where),
        inertia_kgf_cm_s2=_per_ratio(row["inertia_kgf_cm_s2"], where),
        mass_kg=float(row["mass_kg"]),
    )


# --- 1-2 / 1-3 ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class OptionSpec:
    """One option code of 1-2 with the frames it is allowed on."""

    code: str
    name: str
    details: str
    frames: tuple[str, ...]
    section: str


@cache
def option_table() -> tuple[OptionSpec, ...]:
    """The option codes of 1-2, in the manual's order (A B L C K W D F5 E)."""
    return tuple(
        OptionSpec(
            code=o["code"],
            name=o["name"],
            details=o["details"],
            frames=tuple(o["frames"]),
            section=o["section"],
        )
        for o in load_toml("options")["option"]
    )


@cache
def encoder_codes() -> dict[str, str]:
    """Encoder code of the model code -> encoder system: ``{"US250": "incremental", "S248": "absolute"}``."""
    return dict(load_toml("options")["encoders"])


@cache
def combination_table() -> dict[tuple[str, str, int], tuple[str, ...]]:
    """1-3: (frame, encoder code, supply voltage) -> driver models (empty: none exists)."""
    table = load_toml("options")["combinations"]
    out: dict[tuple[str, str, int], tuple[str, ...]] = {}
    for key, per_voltage in table.items():
        if key == "section":
            continue
        frame, encoder_code = key.split("-")
        for volt, drivers in per_voltage.items():
            out[(frame, encoder_code, int(volt))] = tuple(drivers)
    return out


# --- discrepancies ------------------------------------------------------------------------------


@dataclass(frozen=True)
class Discrepancy:
    """A place where the manual contradicts itself: value used, values printed (by place), reason."""

    id: str
    section: str
    quantity: str
    used: Any = field(hash=False)
    printed: dict[str, Any] = field(hash=False)
    reason: str = ""
    frame: str | None = None
    ratios: tuple[int, ...] | None = None
    encoder: str | None = None
    supply_voltage: int | None = None

    def applies_to(self, frame: str, ratio: int, encoder: str, supply_voltage: int) -> bool:
        """True when this entry concerns an actuator with these properties."""
        return (
            (self.frame is None or self.frame == frame)
            and (self.ratios is None or ratio in self.ratios)
            and (self.encoder is None or self.encoder == encoder)
            and (self.supply_voltage is None or self.supply_voltage == supply_voltage)
        )

    def used_for(self, ratio: int) -> Any:
        """The value used for this ratio (``used`` itself when the entry is not per ratio)."""
        if self.ratios is None:
            return self.used
        return self.used[self.ratios.index(ratio)]

    def note(self) -> str:
        """One line: where, what is used, what is printed, why."""
        printed = "; ".join(f"{where}: {value}" for where, value in self.printed.items())
        return f"{self.section} {self.quantity}: used {self.used!r} (printed {printed}). {self.reason}"


@cache
def discrepancies() -> tuple[Discrepancy, ...]:
    """Every recorded contradiction of the manual (``resources/catalog/discrepancies.toml``)."""
    out = []
    for d in load_toml("discrepancies")["discrepancy"]:
        out.append(
            Discrepancy(
                id=d["id"],
                section=d["section"],
                quantity=d["quantity"],
                used=d["used"],
                printed=dict(d["printed"]),
                reason=d["reason"],
                frame=d.get("frame"),
                ratios=tuple(d["ratios"]) if "ratios" in d else None,
                encoder=d.get("encoder"),
                supply_voltage=d.get("supply_voltage"),
            )
        )
    return tuple(out)


# --- 4-1 AC100V, as printed ---------------------------------------------------------------------


@dataclass(frozen=True)
class Ac100vRow:
    """4-1 AC100V table of one frame, as printed (option A uses the 1-4 100 V rows instead)."""

    frame: str
    max_torque_nm: tuple[float, ...]
    max_torque_kgf_m: tuple[float, ...]
    max_speed_rpm: tuple[float, ...]
    torque_constant_nm_per_a: tuple[float, ...]
    torque_constant_kgf_m_per_a: tuple[float, ...]
    max_current_a: tuple[float, ...]
    inertia_kgm2: tuple[float, ...]
    inertia_kgf_cm_s2: tuple[float, ...]
    emf_constant_v_per_rpm: tuple[float, ...]
    phase_resistance_ohm: float
    phase_inductance_mh: float
    allowable_radial_load_kn: float
    allowable_radial_load_kgf: float
    allowable_axial_load_kn: float
    allowable_axial_load_kgf: float
    allowable_torsional_moment_nm: float
    allowable_torsional_moment_kgf_m: float
    moment_stiffness_nm_per_rad: float
    moment_stiffness_kgf_m_per_rad: float
    one_way_accuracy_arcsec: tuple[float, ...]
    output_resolution_ppr: tuple[int, ...]
    mass_kg: float


def ac100v_frames() -> tuple[str, ...]:
    """Frames the 4-1 table covers (FHA-40C is not available for AC100V)."""
    return tuple(load_toml("ac100v")["frames"])


@cache
def ac100v_table(frame: str) -> Ac100vRow:
    """The 4-1 AC100V table of one frame (17C, 25C or 32C), as printed."""
    row = load_toml("ac100v")["frame"][frame]
    where = f"ac100v.toml [frame.{frame}]"
    values: dict[str, Any] = {}
    for name, fld in Ac100vRow.__dataclass_fields__.items():
        if name == "frame":
            continue
        if "tuple" in str(fld.type):
            values[name] = _per_ratio(row[name], where)
        else:
            values[name] = float(row[name])
    values["output_resolution_ppr"] = tuple(int(v) for v in values["output_resolution_ppr"])
    return Ac100vRow(frame=frame, **values)


# --- 1-7 / 1-8 ----------------------------------------------------------------------------------


@cache
def one_way_accuracy_table(frame: str) -> tuple[float, ...]:
    """1-7 uni-directional positioning accuracy (arc-sec) of one frame, per ratio."""
    t = load_toml("accuracy")["one_way_positioning_accuracy"]
    return _per_ratio(t["arcsec"][frame], f"accuracy.toml one_way_positioning_accuracy {frame}")


@dataclass(frozen=True)
class EncoderResolutionRow:
    """1-8 encoder resolution of one encoder system."""

    encoder: str
    encoder_ppr: int
    counts_per_motor_rev: int
    output_resolution_ppr: tuple[int, ...]
    resolvable_angle_arcsec: tuple[float, ...]


@cache
def encoder_resolution_table(encoder: str) -> EncoderResolutionRow:
    """1-8 for ``"incremental"`` or ``"absolute"``."""
    t = load_toml("accuracy")["encoder_resolution"][encoder]
    where = f"accuracy.toml encoder_resolution.{encoder}"
    return EncoderResolutionRow(
        encoder=encoder,
        encoder_ppr=int(t["encoder_ppr"]),
        counts_per_motor_rev=int(t["counts_per_motor_rev"]),
        output_resolution_ppr=tuple(int(v) for v in _per_ratio(t["output_resolution_ppr"], where)),
        resolvable_angle_arcsec=_per_ratio(t["resolvable_angle_arcsec"], where),
    )


# --- 1-14 cables, 4-2-2 brake leads -------------------------------------------------------------


@dataclass(frozen=True)
class Lead:
    """One lead of a cable: its colour, its signal, and the manual's reference text (may be empty)."""

    colour: str
    signal: str
    reference: str = ""


@dataclass(frozen=True)
class CableTables:
    """1-14 lead colours (motor standard / with brake, 14-wire and 4-wire incremental, absolute) and 4-2-2."""

    motor_standard: tuple[Lead, ...]
    motor_brake_option: tuple[Lead, ...]
    incremental_14_wire: tuple[Lead, ...]
    incremental_4_wire: tuple[Lead, ...]
    absolute: tuple[Lead, ...]
    brake_leads: tuple[Lead, ...]
    connectors: dict[str, str]
    extension_cables: dict[str, Any]


@cache
def cable_tables() -> CableTables:
    """All lead-colour tables of 1-14 and 4-2-2, with the 4-3 connectors and 4-8 extension cables."""
    c = load_toml("cables")

    def leads(rows: list[dict[str, str]]) -> tuple[Lead, ...]:
        return tuple(Lead(r["colour"], r["signal"], r.get("reference", "")) for r in rows)

    return CableTables(
        motor_standard=tuple(Lead(r["colour"], r["standard"]) for r in c["motor"]),
        motor_brake_option=tuple(Lead(r["colour"], r["brake_option"]) for r in c["motor"]),
        incremental_14_wire=leads(c["incremental_14_wire"]),
        incremental_4_wire=leads(c["incremental_4_wire"]),
        absolute=leads(c["absolute"]),
        brake_leads=tuple(Lead(r["colour"], r["lead"]) for r in load_toml("brake")["leads"]),
        connectors={k: v for k, v in c["connectors"].items() if k != "section"},
        extension_cables={k: v for k, v in c["extension_cables"].items() if k != "section"},
    )


# --- 3-3-1 environment --------------------------------------------------------------------------


@dataclass(frozen=True)
class Environment:
    """3-3-1 environment of location (with 1-4, 1-11, 1-12): limits for service and storage."""

    service_temperature_min_c: float
    service_temperature_max_c: float
    storage_temperature_min_c: float
    storage_temperature_max_c: float
    humidity_min_percent_rh: float
    humidity_max_percent_rh: float
    vibration_max_m_per_s2: float
    vibration_frequency_min_hz: float
    vibration_frequency_max_hz: float
    impact_max_m_per_s2: float
    altitude_max_m: float
    protection: str
    min_cable_bending_radius_m: float


@cache
def environment() -> Environment:
    """The environment limits of 3-3-1 (same for every FHA-C actuator)."""
    e = dict(load_toml("mechanical")["environment"])
    e.pop("section")
    e["min_cable_bending_radius_m"] = e.pop("min_cable_bending_radius_mm") / 1000.0
    return Environment(**e)


# --- 4-7-1 position sensors, 1-10 rotary direction ----------------------------------------------


@dataclass(frozen=True)
class OriginSensor:
    """4-7-1 (1) origin sensor of option L (OMRON EE-SX672), SI."""

    model: str
    maker: str
    output_status: str
    supply_voltage_min_v: float
    supply_voltage_max_v: float
    supply_tolerance_percent: float
    current_consumption_max_a: float
    control_output_max_v: float
    load_current_max_a: float
    residual_voltage_max_v: float
    ttl_load_current_max_a: float
    ttl_residual_voltage_max_v: float


@dataclass(frozen=True)
class LimitSwitch:
    """4-7-1 (2) stroke-end limit switches of option L (OMRON D2JW-01K21), SI."""

    model: str
    maker: str
    count: int
    rating_voltage_v: float
    rating_current_a: float
    mechanical_operations_per_min: float
    electrical_operations_per_min: float
    mechanical_life_operations: int
    electrical_life_operations: int


@dataclass(frozen=True)
class PositionSensors:
    """4-7-1: the option-L sensor set."""

    origin_sensor: OriginSensor
    limit_switch: LimitSwitch


@cache
def position_sensors() -> PositionSensors:
    """The 4-7-1 specifications of the rotary position sensor set (option L)."""
    s = load_toml("sensors")
    return PositionSensors(
        origin_sensor=OriginSensor(**s["origin_sensor"]), limit_switch=LimitSwitch(**s["limit_switch"])
    )


@dataclass(frozen=True)
class RotaryDirectionSetting:
    """1-10: one value of [parameter mode] -> [8: rotary direction] and what FWD/REV commands do.

    ``fwd_command`` is the rotation a FWD command gives: "FWD rotation" is the manual's forward
    direction (CW seen from the output flange), "REV rotation" the other one.
    """

    value: int
    fwd_command: str
    rev_command: str
    default: bool

    @property
    def fwd_turns_cw(self) -> bool:
        """True when a FWD command turns the output flange clockwise, seen from the flange."""
        return self.fwd_command == "FWD rotation"

    @property
    def fwd_direction(self) -> str:
        """ "CW" or "CCW": where a FWD command turns the output flange, seen from the flange."""
        return "CW" if self.fwd_turns_cw else "CCW"


@cache
def rotary_direction() -> tuple[RotaryDirectionSetting, ...]:
    """1-10 rotary direction table (value 0, the default, turns CW on a FWD command, seen from the flange)."""
    r = load_toml("sensors")["rotary_direction"]
    return tuple(
        RotaryDirectionSetting(v["value"], v["fwd_command"], v["rev_command"], v["setting"] == "Default")
        for v in r["values"]
    )


def rotary_direction_setting(value: int) -> RotaryDirectionSetting:
    """The row of the 1-10 table for ``value``; ValueError naming the allowed values otherwise."""
    for setting in rotary_direction():
        if setting.value == value:
            return setting
    allowed = " or ".join(str(s.value) for s in rotary_direction())
    raise ValueError(f"rotary direction {value!r}: the manual (1-10) allows {allowed}")


def default_rotary_direction() -> RotaryDirectionSetting:
    """The row of the 1-10 table marked Default."""
    return next(s for s in rotary_direction() if s.default)
