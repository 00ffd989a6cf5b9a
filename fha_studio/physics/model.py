"""`AxisModel`: the plant parameters of one FHA-C axis, output-referred, SI, and its TOML model file.

The axis is a two-mass system (when torsional compliance is on; else one rigid mass):

    motor side  J_motor = J_A - J_flange   (rotor, wave generator: the rotor inertia reflected
                                            through ratio^2, which is what the catalogue's
                                            "inertia of actuator" J_A is)
    load side   J_flange + J_L (+ inertia_error)   (output flange with its bearing, plus the load)

coupled by the gear's torsional spring (manual 1-9-2). The catalogue gives only J_A; the flange
share is an assumption: FLANGE_INERTIA_FRACTION of J_A by default (override flange_inertia_kgm2).
It matters only for the resonance of an unloaded axis; the rigid-body totals always equal
J_A + J_L, as in the manual's sizing formulas (2-4-4).

Signs: positive angle, speed and torque = CW seen from the output flange (manual 1-10: the
forward direction with rotary direction 0). Twist = motor side - load side; a positive twist
means the gear carries positive torque from motor to load.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fha_studio import plausible
from fha_studio.physics.effects import (
    CoulombFriction,
    Effects,
    TorsionalCompliance,
    ViscousFriction,
)
from fha_studio.physics.stiffness import GearStiffness

MODEL_FORMAT = "fha-axis-model/1"
# what a model file may say about the plant (the reasons are in fha_studio.plausible)
_PLANT_RANGES = {
    "load_inertia_kgm2": plausible.LOAD_INERTIA_KGM2,
    "actuator_inertia_kgm2": plausible.ACTUATOR_INERTIA_KGM2,
    "torque_constant_nm_per_a": plausible.TORQUE_CONSTANT_NM_PER_A,
    "ratio": plausible.MOTOR_TURNS_PER_OUTPUT_REV,
}

# Assumption (the catalogue gives only the total J_A): share of J_A on the output flange side.
FLANGE_INERTIA_FRACTION = 0.02
# Assumption: structural damping of the gear, as a damping ratio of the two-mass mode at K1.
GEAR_DAMPING_RATIO = 0.05
# Assumption for the catalogue friction default: share of TF (friction at max speed, 2-4-4) that
# is Coulomb; the rest is viscous, reaching the remainder of TF at max speed.
COULOMB_SHARE_OF_TF = 0.5


@dataclass(frozen=True)
class AxisModel:
    """Plant parameters of one axis (output-referred, SI). Build with from_actuator() or directly.

    ratio: motor turns per output turn (None for a custom axis without it: effects tied to the
    motor turn are then refused). output_resolution_ppr: encoder pulses per output turn.
    max_current_a may be math.inf for an axis whose current limit is unknown (no saturation).
    max_torque_nm / friction_torque_nm (TM, TF of manual 2-4-4) are informative (defaults, checks).
    """

    torque_constant_nm_per_a: float
    max_current_a: float
    actuator_inertia_kgm2: float
    load_inertia_kgm2: float = 0.0
    ratio: float | None = None
    output_resolution_ppr: int = 500_000
    max_speed_rpm: float | None = None
    max_torque_nm: float | None = None
    phase_resistance_ohm: float = 0.0
    stiffness: GearStiffness | None = None
    flange_inertia_kgm2: float | None = None
    gear_damping_ratio: float = GEAR_DAMPING_RATIO
    actuator_code: str = "custom"
    effects: Effects = field(default_factory=Effects)

    def __post_init__(self) -> None:
        def positive(name: str, allow_zero: bool = False, allow_inf: bool = False) -> None:
            v = getattr(self, name)
            ok = isinstance(v, int | float) and not isinstance(v, bool) and not math.isnan(v) \
                and (allow_inf or math.isfinite(v))
            if not ok or v < 0 or (v == 0 and not allow_zero):
                kind = "non-negative" if allow_zero else "positive"
                raise ValueError(f"axis model: {name} must be a {kind} number, got {v!r}")

        positive("torque_constant_nm_per_a")
        positive("max_current_a", allow_inf=True)
        positive("actuator_inertia_kgm2")
        positive("load_inertia_kgm2", allow_zero=True)
        positive("phase_resistance_ohm", allow_zero=True)
        positive("gear_damping_ratio", allow_zero=True)
        if self.ratio is not None:
            positive("ratio")
        for name in ("max_speed_rpm", "max_torque_nm"):
            if getattr(self, name) is not None:
                positive(name)
        if not isinstance(self.output_resolution_ppr, int) or self.output_resolution_ppr <= 0:
            raise ValueError(f"axis model: output_resolution_ppr must be a positive integer, "
                             f"got {self.output_resolution_ppr!r}")
        flange = self.flange_inertia_kgm2
        if flange is None:
            flange = FLANGE_INERTIA_FRACTION * self.actuator_inertia_kgm2
            object.__setattr__(self, "flange_inertia_kgm2", flange)
        positive("flange_inertia_kgm2")
        if flange >= self.actuator_inertia_kgm2:
            raise ValueError("axis model: flange_inertia_kgm2 must be a part of actuator_inertia_kgm2")
        if not isinstance(self.effects, Effects):
            raise TypeError("axis model: effects must be an Effects")
        e = self.effects
        if self.ratio is None:
            for tied in ("torque_ripple", "kinematic_error"):
                if getattr(e, tied) is not None:
                    raise ValueError(f"axis model: {tied} is tied to the motor turn, but ratio is unknown")
        if e.torsional_compliance is not None and self.stiffness is None \
                and e.torsional_compliance.stiffness_nm_per_rad is None:
            raise ValueError("axis model: torsional_compliance needs a catalogue curve or a stiffness")
        if self.load_side_inertia_kgm2 <= 0:
            raise ValueError("axis model: inertia_error leaves no positive load-side inertia")

    # ----- construction -------------------------------------------------------------------
    @classmethod
    def from_actuator(cls, actuator: Any, load_inertia_kgm2: float = 0.0, effects: Effects | None = None,
                      **overrides: Any) -> AxisModel:
        """From a catalogue `Actuator` (fha_studio.catalog.get_actuator) and the load inertia.

        effects=None means the nominal model (all off); see catalogue_effects() for the
        catalogue's friction and stiffness. overrides replace any field (e.g. flange_inertia_kgm2).
        """
        stiffness = getattr(actuator, "stiffness", None)
        values: dict[str, Any] = dict(
            torque_constant_nm_per_a=float(actuator.torque_constant_nm_per_a),
            max_current_a=float(actuator.max_current_a),
            actuator_inertia_kgm2=float(actuator.inertia_kgm2),
            load_inertia_kgm2=float(load_inertia_kgm2),
            ratio=float(actuator.ratio),
            output_resolution_ppr=int(actuator.output_resolution_ppr),
            max_speed_rpm=float(actuator.max_speed_rpm),
            max_torque_nm=float(actuator.max_torque_nm),
            phase_resistance_ohm=float(getattr(actuator, "phase_resistance_ohm", 0.0) or 0.0),
            stiffness=GearStiffness.from_catalogue(stiffness) if stiffness is not None else None,
            actuator_code=str(getattr(actuator, "model_code", None) or getattr(actuator, "code", "custom")),
            effects=effects if effects is not None else Effects(),
        )
        values.update(overrides)
        return cls(**values)

    @classmethod
    def from_code(cls, code: str, load_inertia_kgm2: float = 0.0, effects: Effects | None = None,
                  **overrides: Any) -> AxisModel:
        """From a model code through the catalogue (fha_studio.catalog.get_actuator)."""
        from fha_studio import catalog

        return cls.from_actuator(catalog.get_actuator(code), load_inertia_kgm2, effects, **overrides)

    def replace(self, **changes: Any) -> AxisModel:
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)

    def with_effects(self, effects: Effects) -> AxisModel:
        """A copy with another set of effects."""
        return dataclasses.replace(self, effects=effects)

    # ----- derived quantities --------------------------------------------------------------
    @property
    def motor_side_inertia_kgm2(self) -> float:
        """Output-referred inertia on the motor side of the gear spring."""
        return self.actuator_inertia_kgm2 - self.flange_inertia_kgm2  # type: ignore[operator]

    @property
    def load_side_inertia_kgm2(self) -> float:
        """Flange + declared load + inertia_error (if on)."""
        extra = self.effects.inertia_error.inertia_kgm2 if self.effects.inertia_error else 0.0
        return self.flange_inertia_kgm2 + self.load_inertia_kgm2 + extra  # type: ignore[operator]

    @property
    def total_inertia_kgm2(self) -> float:
        """Rigid-body inertia seen at the output: J_A + J_L (+ inertia_error)."""
        return self.motor_side_inertia_kgm2 + self.load_side_inertia_kgm2

    @property
    def peak_torque_nm(self) -> float:
        """Motor torque at the current limit, Kt x Imax (before friction)."""
        return self.torque_constant_nm_per_a * self.max_current_a

    @property
    def friction_torque_nm(self) -> float | None:
        """TF = Kt x Im - TM (manual 2-4-4), the friction at maximum speed; None without TM."""
        if self.max_torque_nm is None:
            return None
        return max(0.0, self.peak_torque_nm - self.max_torque_nm)

    @property
    def max_speed_rad_s(self) -> float | None:
        """Maximum output speed in rad/s (None when unknown)."""
        return None if self.max_speed_rpm is None else self.max_speed_rpm * 2.0 * math.pi / 60.0

    @property
    def output_pulse_rad(self) -> float:
        """One encoder pulse at the output, in rad."""
        return 2.0 * math.pi / self.output_resolution_ppr

    @property
    def gear_stiffness(self) -> GearStiffness | None:
        """The spring in use: None when torsional_compliance is off, else catalogue + overrides."""
        tc = self.effects.torsional_compliance
        if tc is None:
            return None
        base = self.stiffness
        if base is None:
            base = GearStiffness.linear(tc.stiffness_nm_per_rad)  # type: ignore[arg-type]
        k1 = tc.stiffness_nm_per_rad if tc.stiffness_nm_per_rad is not None else base.k1_nm_per_rad
        factor = k1 / base.k1_nm_per_rad
        return GearStiffness(
            t1_nm=tc.t1_nm if tc.t1_nm is not None else base.t1_nm,
            t2_nm=tc.t2_nm if tc.t2_nm is not None else base.t2_nm,
            k1_nm_per_rad=k1,
            k2_nm_per_rad=tc.k2_nm_per_rad if tc.k2_nm_per_rad is not None else base.k2_nm_per_rad * factor,
            k3_nm_per_rad=tc.k3_nm_per_rad if tc.k3_nm_per_rad is not None else base.k3_nm_per_rad * factor,
        )

    def max_acceleration_rad_s2(self, load_torque_nm: float = 0.0) -> float:
        """Torque-limited acceleration (TM - TL)/(J_A + J_L), as the manual's ta formula (2-4-4).

        Uses TM when known, else Kt x Imax less the modelled friction at rest.
        """
        torque = self.max_torque_nm if self.max_torque_nm is not None else self.peak_torque_nm
        return max(torque - load_torque_nm, 0.0) / self.total_inertia_kgm2

    # ----- model file ----------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The model as plain data (what the TOML file holds)."""
        plant: dict[str, Any] = {}
        for f in dataclasses.fields(self):
            if f.name in ("stiffness", "effects", "actuator_code"):
                continue
            value = getattr(self, f.name)
            if value is not None:
                plant[f.name] = value
        data: dict[str, Any] = {"format": MODEL_FORMAT, "actuator": self.actuator_code, "plant": plant}
        if self.stiffness is not None:
            s = self.stiffness
            data["stiffness"] = {
                "t1_nm": s.t1_nm, "t2_nm": s.t2_nm, "k1_nm_per_rad": s.k1_nm_per_rad,
                "k2_nm_per_rad": s.k2_nm_per_rad, "k3_nm_per_rad": s.k3_nm_per_rad,
            }
        data["effects"] = self.effects.to_dict()
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any], where: str = "model") -> AxisModel:
        """From plain data as written by to_dict(); errors name the field."""
        if not isinstance(data, dict):
            raise ValueError(f"{where}: expected a table, got {type(data).__name__}")
        fmt = data.get("format")
        if fmt != MODEL_FORMAT:
            raise ValueError(f"{where}: format must be {MODEL_FORMAT!r}, got {fmt!r}")
        plant = data.get("plant")
        if not isinstance(plant, dict):
            raise ValueError(f"{where}: missing [plant] table")
        known = {f.name for f in dataclasses.fields(cls)} - {"stiffness", "effects", "actuator_code"}
        unknown = sorted(set(plant) - known)
        if unknown:
            raise ValueError(f"{where}: unknown plant field(s) {', '.join(unknown)}")
        values = dict(plant)
        if "output_resolution_ppr" in values:
            ppr = values["output_resolution_ppr"]
            if isinstance(ppr, bool) or not isinstance(ppr, int | float) or not math.isfinite(ppr) \
                    or ppr != int(ppr) or not 1 <= ppr <= 2**31:
                raise ValueError(f"{where}: [plant] output_resolution_ppr must be a whole number "
                                 f"1 ... {2**31}, got {ppr!r}")
            values["output_resolution_ppr"] = int(ppr)
        for name, allowed in _PLANT_RANGES.items():
            value = values.get(name)
            if isinstance(value, int | float) and not isinstance(value, bool) and not allowed.contains(value):
                raise ValueError(f"{where}: [plant] {name} = {value:g} is outside {allowed.allowed()} "
                                 f"({allowed.reason})")
        stiffness = data.get("stiffness")
        if stiffness is not None and not isinstance(stiffness, dict):
            raise ValueError(f"{where}: [stiffness] must be a table")
        if stiffness is not None:
            try:
                values["stiffness"] = GearStiffness(**stiffness)
            except TypeError as exc:
                raise ValueError(f"{where}: [stiffness]: {exc}") from None
        values["effects"] = Effects.from_dict(data.get("effects", {}), where=f"{where}: [effects]")
        values["actuator_code"] = str(data.get("actuator", "custom"))
        try:
            return cls(**values)
        except TypeError as exc:
            raise ValueError(f"{where}: {exc}") from None

    def to_toml(self) -> str:
        """The model file text (TOML, format fha-axis-model/1)."""
        data = self.to_dict()
        lines = [
            "# FHA Studio axis model: output-referred, SI; positive = CW seen from the output flange.",
            f"format = {_toml_value(data['format'])}",
            f"actuator = {_toml_value(data['actuator'])}",
            "",
            "[plant]",
        ]
        lines += [f"{k} = {_toml_value(v)}" for k, v in data["plant"].items()]
        if "stiffness" in data:
            lines += ["", "# gear wind-up curve (FHA-C manual 1-9-2)", "[stiffness]"]
            lines += [f"{k} = {_toml_value(v)}" for k, v in data["stiffness"].items()]
        lines += ["", "# effects that are on (ids and parameters: the model check contract)", "[effects]"]
        for effect_id, params in data["effects"].items():
            lines += ["", f"[effects.{effect_id}]"]
            lines += [f"{k} = {_toml_value(v)}" for k, v in params.items()]
        return "\n".join(lines) + "\n"

    @classmethod
    def from_toml(cls, text: str, where: str = "model file") -> AxisModel:
        """Parse a model file's text; errors name the file (where) and the field."""
        try:
            from fha_studio import fileio

            data = fileio.parse_toml(text)  # bounded in depth
        except tomllib.TOMLDecodeError as exc:
            raise ValueError(f"{where}: not valid TOML: {exc}") from None
        return cls.from_dict(data, where=where)

    def save(self, path: str | Path) -> None:
        """Write the model file whole or not at all (fha_studio.fileio.FileProblem if it cannot be)."""
        from fha_studio import fileio

        fileio.write_text(path, self.to_toml())

    @classmethod
    def load(cls, path: str | Path) -> AxisModel:
        """Read a model file (a regular file of at most a megabyte); ValueError names the file."""
        from fha_studio import fileio

        return cls.from_toml(fileio.read_text(path, limit_bytes=1024 * 1024), where=str(path))


def catalogue_effects(model: AxisModel) -> Effects:
    """The catalogue's own effects for a realistic axis: friction from TF and the gear's stiffness.

    TF = Kt x Im - TM (2-4-4) is the friction at maximum speed; COULOMB_SHARE_OF_TF of it is
    Coulomb, the rest viscous (reaching TF at max speed). The split is an assumption: the manual
    gives only TF. Torsional compliance uses the catalogue curve (1-9-2).
    """
    effects = model.effects
    tf = model.friction_torque_nm
    if tf is not None and tf > 0 and model.max_speed_rad_s:
        effects = dataclasses.replace(
            effects,
            coulomb_friction=CoulombFriction(torque_nm=COULOMB_SHARE_OF_TF * tf),
            viscous_friction=ViscousFriction(
                coefficient_nm_s_per_rad=(1.0 - COULOMB_SHARE_OF_TF) * tf / model.max_speed_rad_s),
        )
    if model.stiffness is not None:
        effects = dataclasses.replace(effects, torsional_compliance=TorsionalCompliance())
    return effects


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            raise ValueError("cannot write nan to a model file")
        return repr(value) if math.isfinite(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, str):
        escaped = value.replace("\\", "\\\\").replace('"', '\\"')
        return f'"{escaped}"'
    raise TypeError(f"cannot write {type(value).__name__} to a model file")
