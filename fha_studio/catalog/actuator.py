"""The resolved catalogue entry of one FHA-C actuator: :func:`get_actuator` -> :class:`Actuator`.

All quantities are SI (or r/min, arc-sec, mH where the name says so) and refer to the output flange.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cache, lru_cache
from types import MappingProxyType
from typing import Any

from fha_studio.catalog.model_code import OPTION_ORDER, ModelCode, ModelCodeError, parse_model_code
from fha_studio.catalog.tables import (
    FRAMES,
    RATIOS,
    Lead,
    allowable_inertia_table,
    brake_table,
    cable_tables,
    combination_table,
    continuous_table,
    discrepancies,
    encoder_codes,
    load_toml,
    option_table,
    spec_table,
    torsional_stiffness_table,
)

ARCSEC_PER_REV = 1_296_000


@dataclass(frozen=True)
class TorsionalStiffness:
    """1-9-2 torsional stiffness, output flange with the motor locked.

    K1 holds for 0..T1, K2 for T1..T2, K3 above T2; theta1/theta2 are the printed wind-ups at T1/T2.
    They equal T1/K1 and theta1 + (T2 - T1)/K2 only within the printed rounding, so the 1-9-2
    formula jumps slightly at T1 and T2 (a model that needs continuity derives them itself).
    """

    t1_nm: float
    t2_nm: float
    k1_nm_per_rad: float
    k2_nm_per_rad: float
    k3_nm_per_rad: float
    theta1_rad: float
    theta2_rad: float

    def windup_rad(self, torque_nm: float) -> float:
        """Wind-up (rad) at a torque (N·m) by the 1-9-2 formula, odd in the torque."""
        t = abs(torque_nm)
        if t <= self.t1_nm:
            phi = t / self.k1_nm_per_rad
        elif t <= self.t2_nm:
            phi = self.theta1_rad + (t - self.t1_nm) / self.k2_nm_per_rad
        else:
            phi = self.theta2_rad + (t - self.t2_nm) / self.k3_nm_per_rad
        return math.copysign(phi, torque_nm)

    def torque_nm(self, windup_rad: float) -> float:
        """Torque (N·m) at a wind-up (rad): the 1-9-2 formula solved for T, regions split at theta1/theta2."""
        phi = abs(windup_rad)
        if phi <= self.theta1_rad:
            t = self.k1_nm_per_rad * phi
        elif phi <= self.theta2_rad:
            t = self.t1_nm + self.k2_nm_per_rad * (phi - self.theta1_rad)
        else:
            t = self.t2_nm + self.k3_nm_per_rad * (phi - self.theta2_rad)
        return math.copysign(t, windup_rad)


@dataclass(frozen=True)
class Bearing:
    """2-3 Table 1: the cross roller bearing (dp, offset R, ratings C/Co, allowable Fr, Fa, Mc)."""

    circular_pitch_of_roller_m: float
    offset_m: float
    basic_dynamic_load_rating_n: float
    basic_static_load_rating_n: float
    allowable_radial_load_n: float
    allowable_axial_load_n: float
    allowable_torsional_moment_nm: float


@dataclass(frozen=True)
class Brake:
    """4-2-1 brake for motor (option B). Torque and inertia are converted to the output flange.

    ``inertia_kgm2`` and ``mass_kg`` are those of the whole actuator with brake. The manual gives
    4-2-1 for the incremental system only; for an absolute actuator they are estimated as the
    absolute values plus the brake's increase over the incremental ones (``estimated`` is True).
    """

    holding_torque_nm: float
    activating_current_a: float
    holding_current_a: float
    supply_voltage_v: float
    supply_tolerance_percent: float
    activating_time_max_s: float
    inertia_kgm2: float
    mass_kg: float
    normal_holding_cycles: int
    normal_holding_max_motor_speed_rpm: float
    emergency_stop_cycles: int
    emergency_stop_max_motor_speed_rpm: float
    estimated: bool


@dataclass(frozen=True)
class MechanicalAccuracy:
    """1-6 machined accuracy of the output flange, T.I.R., in metres."""

    axial_runout_m: float
    radial_runout_m: float
    parallelism_m: float
    concentricity_m: float


@dataclass(frozen=True)
class ScrewTightening:
    """3-3-2 recommended tightening of one flange: screws and torque."""

    screw_count: int
    screw_size: str
    screw_hole_depth_m: float | None
    torque_nm: float


@dataclass(frozen=True)
class TighteningTorques:
    """3-3-2 for the output flange and the mounting flange."""

    output_flange: ScrewTightening
    mounting_flange: ScrewTightening


@dataclass(frozen=True)
class CableLeads:
    """1-14 / 4-2-2 lead colours of this actuator's cables.

    ``motor``: the motor cable (with the brake leads when option B is fitted). ``encoder``: the
    encoder lead tables that apply, by name: the incremental system has a 14-wire and a 4-wire
    (serial) variant in 1-14 and the manual does not say which one a given unit has; the absolute
    system has one. ``connectors``: the 4-3 cable-end connectors (option C), else empty.
    """

    motor: tuple[Lead, ...]
    # Read-only mappings, left out of the hash so that an Actuator stays hashable.
    encoder: Mapping[str, tuple[Lead, ...]] = field(hash=False)
    connectors: Mapping[str, str] = field(hash=False)


@dataclass(frozen=True)
class Actuator:
    """One FHA-C actuator resolved from the catalogue (1-3, 1-4, 1-6..1-9, 1-14, 2-1, 2-3, 2-4-6, 3-3-2, 4-2).

    Output-referred SI quantities with units in the names. With option B, ``inertia_kgm2`` and
    ``mass_kg`` are the brake table's (4-2-1), i.e. of the actuator with its brake. With option A the
    electrical values are the 100 V rows of 1-4; the continuous ratings stay the 200 V ones (4-1 note 4
    says the 100 V range differs and is unpublished; a note says so). ``friction_torque_nm`` is
    TF = KT x Im - TM (2-4-4). ``notes`` lists the contradictions of the manual that touch this actuator.
    """

    code: ModelCode
    model_code: str
    frame: str
    ratio: int
    encoder: str
    encoder_code: str
    options: frozenset[str]
    supply_voltage: int
    max_torque_nm: float
    max_speed_rpm: float
    torque_constant_nm_per_a: float
    max_current_a: float
    emf_constant_v_per_rpm: float
    phase_resistance_ohm: float
    phase_inductance_mh: float
    inertia_kgm2: float
    motor_encoder_ppr: int
    output_resolution_ppr: int
    resolvable_angle_arcsec: float
    continuous_torque_nm: float
    continuous_speed_rpm: float
    allowable_inertia_kgm2: float
    friction_torque_nm: float
    stiffness: TorsionalStiffness
    moment_stiffness_nm_per_rad: float
    one_way_accuracy_arcsec: float
    allowable_radial_load_n: float
    allowable_axial_load_n: float
    allowable_torsional_moment_nm: float
    mass_kg: float
    bearing: Bearing
    brake: Brake | None
    mechanical_accuracy: MechanicalAccuracy
    tightening: TighteningTorques
    compatible_drivers: tuple[str, ...]
    cables: CableLeads
    notes: tuple[str, ...] = field(default=())

    @property
    def motor_max_speed_rpm(self) -> float:
        """Maximum motor speed (r/min): output maximum speed x ratio."""
        return self.max_speed_rpm * self.ratio

    def as_dict(self) -> dict[str, Any]:
        """A JSON-ready dict: SI keys with units in the names, sub-objects as nested dicts."""
        out: dict[str, Any] = {}
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if name == "code":
                continue
            out[name] = _plain(value)
        return out


def _plain(value: Any) -> Any:
    if isinstance(value, frozenset):
        return [o for o in OPTION_ORDER if o in value]
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    if hasattr(value, "__dataclass_fields__"):
        return {k: _plain(getattr(value, k)) for k in value.__dataclass_fields__}
    return value


def _per_frame(table: dict[str, Any], key: str, frame: str) -> Any:
    return table[key][frame]


@cache
def _bearing(frame: str) -> Bearing:
    b = load_toml("mechanical")["bearing"]
    return Bearing(
        circular_pitch_of_roller_m=b["circular_pitch_of_roller_mm"][frame] / 1000.0,
        offset_m=b["offset_mm"][frame] / 1000.0,
        basic_dynamic_load_rating_n=float(b["basic_dynamic_load_rating_n"][frame]),
        basic_static_load_rating_n=float(b["basic_static_load_rating_n"][frame]),
        allowable_radial_load_n=float(b["allowable_radial_load_n"][frame]),
        allowable_axial_load_n=float(b["allowable_axial_load_n"][frame]),
        allowable_torsional_moment_nm=float(b["allowable_torsional_moment_nm"][frame]),
    )


@cache
def _mechanical_accuracy(frame: str) -> MechanicalAccuracy:
    m = load_toml("mechanical")["mechanical_accuracy"]
    return MechanicalAccuracy(
        axial_runout_m=m["axial_runout_of_output_flange_mm"][frame] / 1000.0,
        radial_runout_m=m["radial_runout_of_output_flange_mm"][frame] / 1000.0,
        parallelism_m=m["parallelism_output_to_mounting_flange_mm"][frame] / 1000.0,
        concentricity_m=m["concentricity_output_flange_to_fitting_face_mm"][frame] / 1000.0,
    )


@cache
def _tightening(frame: str) -> TighteningTorques:
    t = load_toml("mechanical")["tightening"]

    def one(part: str) -> ScrewTightening:
        p = t[part]
        depth = p.get("screw_hole_depth_mm", {}).get(frame)
        return ScrewTightening(
            screw_count=int(p["screw_count"][frame]),
            screw_size=p["screw_size"][frame],
            screw_hole_depth_m=None if depth is None else depth / 1000.0,
            torque_nm=float(p["torque_nm"][frame]),
        )

    return TighteningTorques(output_flange=one("output_flange"), mounting_flange=one("mounting_flange"))


def _brake(code: ModelCode, index: int) -> Brake:
    data = load_toml("brake")
    row = brake_table(code.frame)
    inertia = row.inertia_kgm2[index]
    mass = row.mass_kg
    estimated = code.encoder == "absolute"
    if estimated:
        inc = spec_table("incremental", code.frame)
        absolute = spec_table("absolute", code.frame)
        inertia = absolute.inertia_kgm2[index] + (row.inertia_kgm2[index] - inc.inertia_kgm2[index])
        mass = absolute.mass_kg + (row.mass_kg - inc.mass_kg)
    return Brake(
        holding_torque_nm=row.holding_torque_nm[index],
        activating_current_a=row.activating_current_a,
        holding_current_a=row.holding_current_a,
        supply_voltage_v=float(data["supply_voltage_v"]),
        supply_tolerance_percent=float(data["supply_tolerance_percent"]),
        activating_time_max_s=float(data["activating_time_max_s"]),
        inertia_kgm2=round(inertia, 6),
        mass_kg=round(mass, 6),
        normal_holding_cycles=int(data["normal_holding_cycles"]),
        normal_holding_max_motor_speed_rpm=float(data["normal_holding_max_motor_speed_rpm"]),
        emergency_stop_cycles=int(data["emergency_stop_cycles"]),
        emergency_stop_max_motor_speed_rpm=float(data["emergency_stop_max_motor_speed_rpm"]),
        estimated=estimated,
    )


def _checked(mc: ModelCode) -> ModelCode:
    """A ModelCode built by hand passes the parser's rules too (frame, ratio, encoder, options)."""
    parsed = parse_model_code(mc.code)
    if parsed != mc:
        raise ModelCodeError(
            mc,
            f"encoder {mc.encoder!r} does not match encoder code {mc.encoder_code!r}",
            "build it with parse_model_code",
        )
    return parsed


def _cables(mc: ModelCode) -> CableLeads:
    c = cable_tables()
    if mc.encoder == "incremental":
        encoder = {"14-wire": c.incremental_14_wire, "4-wire": c.incremental_4_wire}
        connector_keys = ("motor", "incremental_encoder")
    else:
        encoder = {"absolute": c.absolute}
        connector_keys = ("motor", "absolute_encoder")
    connectors = {k: c.connectors[k] for k in connector_keys} if "C" in mc.options else {}
    return CableLeads(
        motor=c.motor_brake_option if mc.has_brake else c.motor_standard,
        encoder=MappingProxyType(encoder),
        connectors=MappingProxyType(connectors),
    )


def compatible_drivers(code: str | ModelCode, supply_voltage: int | None = None) -> list[str]:
    """Driver models that 1-3 pairs with this actuator, e.g. ``["HA-655-2-200", "HA-675-2-200"]``.

    ``supply_voltage`` (V) defaults to the code's (100 with option A, else 200); giving the other one
    is a mistake (the winding differs) and raises ValueError. Empty list: no driver exists.
    """
    mc = _checked(code) if isinstance(code, ModelCode) else parse_model_code(code)
    if supply_voltage is None:
        supply_voltage = mc.supply_voltage
    if supply_voltage not in (100, 200):
        raise ValueError(f"supply voltage {supply_voltage!r} V: allowed 200 or 100 (option A)")
    if supply_voltage != mc.supply_voltage:
        raise ValueError(
            f"{mc.code} is wound for {mc.supply_voltage} V, not {supply_voltage} V "
            f"(option A selects AC100V, 1-2 / 4-1)"
        )
    return list(combination_table()[(mc.frame, mc.encoder_code, supply_voltage)])


@cache
def _get_actuator(mc: ModelCode) -> Actuator:
    i = RATIOS.index(mc.ratio)
    volt = mc.supply_voltage
    spec = spec_table(mc.encoder, mc.frame)
    tors = torsional_stiffness_table(mc.frame)
    cont = continuous_table(mc.frame)
    allow = allowable_inertia_table(mc.frame)
    kt = spec.torque_constant_nm_per_a_by_voltage[volt][i]
    im = spec.max_current_a_by_voltage[volt][i]
    tm = spec.max_torque_nm[i]
    brake = _brake(mc, i) if mc.has_brake else None
    notes = [d.note() for d in discrepancies() if d.applies_to(mc.frame, mc.ratio, mc.encoder, volt)]
    option_notes = load_toml("options")["notes"]
    if volt == 100:
        notes.append(option_notes["ac100v_continuous"])
    if len(mc.options) >= 2:
        notes.append(option_notes["several_options"])
    if brake is not None and brake.estimated:
        notes.append(
            "4-2-1 gives the brake table for the incremental system only: inertia and mass with brake "
            "are the absolute values plus the brake's increase in 4-2-1 (estimate)."
        )
    return Actuator(
        code=mc,
        model_code=mc.code,
        frame=mc.frame,
        ratio=mc.ratio,
        encoder=mc.encoder,
        encoder_code=mc.encoder_code,
        options=mc.options,
        supply_voltage=volt,
        max_torque_nm=tm,
        max_speed_rpm=spec.max_speed_rpm[i],
        torque_constant_nm_per_a=kt,
        max_current_a=im,
        emf_constant_v_per_rpm=spec.emf_constant_v_per_rpm_by_voltage[volt][i],
        phase_resistance_ohm=spec.phase_resistance_ohm_by_voltage[volt],
        phase_inductance_mh=spec.phase_inductance_mh_by_voltage[volt],
        inertia_kgm2=brake.inertia_kgm2 if brake else spec.inertia_kgm2[i],
        motor_encoder_ppr=spec.motor_encoder_ppr,
        output_resolution_ppr=spec.output_resolution_ppr[i],
        resolvable_angle_arcsec=ARCSEC_PER_REV / spec.output_resolution_ppr[i],
        continuous_torque_nm=cont.continuous_torque_nm[i],
        continuous_speed_rpm=cont.continuous_speed_rpm[i],
        allowable_inertia_kgm2=allow.allowable_inertia_kgm2[i],
        # Rounded to the table's precision: 22 x 7.3 - 150 is 10.6 (2-4-4 Example 1), not 10.599999...
        friction_torque_nm=round(kt * im - tm, 6),
        stiffness=TorsionalStiffness(
            t1_nm=tors.t1_nm,
            t2_nm=tors.t2_nm,
            k1_nm_per_rad=tors.k1_nm_per_rad[i],
            k2_nm_per_rad=tors.k2_nm_per_rad[i],
            k3_nm_per_rad=tors.k3_nm_per_rad[i],
            theta1_rad=tors.theta1_rad[i],
            theta2_rad=tors.theta2_rad[i],
        ),
        moment_stiffness_nm_per_rad=spec.moment_stiffness_nm_per_rad,
        one_way_accuracy_arcsec=spec.one_way_accuracy_arcsec[i],
        allowable_radial_load_n=spec.allowable_radial_load_kn * 1000.0,
        allowable_axial_load_n=spec.allowable_axial_load_kn * 1000.0,
        allowable_torsional_moment_nm=spec.allowable_torsional_moment_nm,
        mass_kg=brake.mass_kg if brake else spec.mass_kg,
        bearing=_bearing(mc.frame),
        brake=brake,
        mechanical_accuracy=_mechanical_accuracy(mc.frame),
        tightening=_tightening(mc.frame),
        compatible_drivers=tuple(compatible_drivers(mc)),
        cables=_cables(mc),
        notes=tuple(notes),
    )


def get_actuator(code: str | ModelCode) -> Actuator:
    """The catalogue entry of a model code (string or :class:`ModelCode`); cached.

    Raises :class:`ModelCodeError` (a ValueError) for a code the manual does not allow.
    """
    if isinstance(code, ModelCode):
        return _get_actuator(_checked(code))
    if not isinstance(code, str):
        raise ModelCodeError(
            code, f"expected a string or ModelCode, got {type(code).__name__}", "e.g. FHA-25C-50-US250"
        )
    return _get_actuator_by_text(code)


@lru_cache(maxsize=512)
def _get_actuator_by_text(code: str) -> Actuator:
    return _get_actuator(parse_model_code(code))


def frames() -> tuple[str, ...]:
    """Frame sizes of the series: ("17C", "25C", "32C", "40C")."""
    return FRAMES


def ratios() -> tuple[int, ...]:
    """Reduction ratios: (50, 100, 160)."""
    return RATIOS


def options_allowed(frame: str) -> list[str]:
    """Option codes (1-2 order) allowed on a frame, e.g. all but A for "40C"."""
    return [o.code for o in option_table() if frame in o.frames]


def all_model_codes(include_ac100v: bool = True) -> list[str]:
    """Every base model code (frame x ratio x encoder), plus the ``-A`` (AC100V) variants where allowed."""
    out = []
    allowed_a = {f for o in option_table() if o.code == "A" for f in o.frames}
    for encoder_code in encoder_codes():
        for frame in FRAMES:
            for ratio in RATIOS:
                base = f"FHA-{frame}-{ratio}-{encoder_code}"
                out.append(base)
                if include_ac100v and frame in allowed_a:
                    out.append(base + "-A")
    return out
