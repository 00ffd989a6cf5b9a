"""The switchable physical effects of an axis, with the ids and parameter names of the model check.

Every effect is a small frozen dataclass; `Effects` holds one optional instance of each (None =
switched off). All values SI and output-referred unless the name says otherwise. Each effect's
docstring states what the motor must supply in addition to the nominal model (rigid,
frictionless, actuator + declared load inertia, torque = Kt x current), which is the model
check's contract (what the model check fits and names):

    coulomb_friction      torque_nm x sign(velocity)
    viscous_friction      coefficient_nm_s_per_rad x velocity
    gravity_load          amplitude_nm x sin(pos + phase_deg)
    load_torque_offset    torque_nm
    inertia_error         inertia_kgm2 x acceleration
    torque_ripple         amplitude_nm x sin(cycles_per_motor_rev x motor angle + phase_deg)
    asymmetric_friction   torque_pos_nm while turning CW (+), -torque_neg_nm while turning CCW
    stribeck_friction     static_torque_nm x exp(-(velocity / velocity_rad_s)^2) x sign(velocity):
                          breakaway above the Coulomb level, fading with speed
    torque_constant_error the motor gives ratio x Kt x current (the monitor or the catalogue Kt is
                          off by that factor); the nominal model assumes Kt x current
position channel (load_pos - pos):
    kinematic_error       amplitude_arcsec x sin(cycles_per_motor_rev x motor angle + phase_deg)
    torsional_compliance  - wind-up under the torque carried by the gear (catalogue K1/K2/K3, T1/T2
                          or overrides)
    lost_motion           a dead band of total width_arcsec seen at reversals

`phase_deg` of torque_ripple and kinematic_error is an addition to the contract (default 0): the
contract names only the amplitude, but a model file must fix the phase to reproduce a recording.
The motor angle is ratio x pos (pos = output-referred motor-side angle, rad, CW positive).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, ClassVar


def _check_finite(effect_id: str, name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ValueError(f"effect {effect_id}: {name} must be a finite number, got {value!r}")
    return float(value)


def _check_nonnegative(effect_id: str, name: str, value: float) -> None:
    if value < 0:
        raise ValueError(f"effect {effect_id}: {name} must not be negative, got {value!r}")


@dataclass(frozen=True)
class _Effect:
    id: ClassVar[str] = ""
    channel: ClassVar[str] = "torque"
    units: ClassVar[dict[str, str]] = {}

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if value is None:
                continue
            object.__setattr__(self, f.name, _check_finite(self.id, f.name, value))

    def params(self) -> dict[str, float]:
        """Parameters by contract name (None-valued optional overrides left out)."""
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        return {name: value for name, value in values.items() if value is not None}


@dataclass(frozen=True)
class CoulombFriction(_Effect):
    """Coulomb friction: the motor supplies torque_nm x sign(velocity); sticks at rest below it."""

    id: ClassVar[str] = "coulomb_friction"
    units: ClassVar[dict[str, str]] = {"torque_nm": "N m"}
    torque_nm: float = 0.0

    def __post_init__(self) -> None:
        super().__post_init__()
        _check_nonnegative(self.id, "torque_nm", self.torque_nm)


@dataclass(frozen=True)
class ViscousFriction(_Effect):
    """Viscous friction: the motor supplies coefficient_nm_s_per_rad x output speed (rad/s)."""

    id: ClassVar[str] = "viscous_friction"
    units: ClassVar[dict[str, str]] = {"coefficient_nm_s_per_rad": "N m s/rad"}
    coefficient_nm_s_per_rad: float = 0.0

    def __post_init__(self) -> None:
        super().__post_init__()
        _check_nonnegative(self.id, "coefficient_nm_s_per_rad", self.coefficient_nm_s_per_rad)


@dataclass(frozen=True)
class GravityLoad(_Effect):
    """An unbalanced load: the motor supplies amplitude_nm x sin(pos + phase_deg) to hold it."""

    id: ClassVar[str] = "gravity_load"
    units: ClassVar[dict[str, str]] = {"amplitude_nm": "N m", "phase_deg": "deg"}
    amplitude_nm: float = 0.0
    phase_deg: float = 0.0


@dataclass(frozen=True)
class LoadTorqueOffset(_Effect):
    """A constant load torque: the motor supplies torque_nm (positive opposes CW motion)."""

    id: ClassVar[str] = "load_torque_offset"
    units: ClassVar[dict[str, str]] = {"torque_nm": "N m"}
    torque_nm: float = 0.0


@dataclass(frozen=True)
class InertiaError(_Effect):
    """Inertia the declaration missed (negative if it overstated); sits on the load side."""

    id: ClassVar[str] = "inertia_error"
    units: ClassVar[dict[str, str]] = {"inertia_kgm2": "kg m^2"}
    inertia_kgm2: float = 0.0


@dataclass(frozen=True)
class TorqueRipple(_Effect):
    """Motor torque ripple: the motor supplies amplitude_nm x sin(cycles x motor angle + phase)."""

    id: ClassVar[str] = "torque_ripple"
    units: ClassVar[dict[str, str]] = {
        "amplitude_nm": "N m", "cycles_per_motor_rev": "1/rev", "phase_deg": "deg",
    }
    amplitude_nm: float = 0.0
    cycles_per_motor_rev: float = 1.0
    phase_deg: float = 0.0


@dataclass(frozen=True)
class AsymmetricFriction(_Effect):
    """Coulomb friction that differs by direction: torque_pos_nm while turning CW (positive speed),
    torque_neg_nm (a magnitude) while turning CCW; sticks at rest below the level of the push."""

    id: ClassVar[str] = "asymmetric_friction"
    units: ClassVar[dict[str, str]] = {"torque_pos_nm": "N m", "torque_neg_nm": "N m"}
    torque_pos_nm: float = 0.0
    torque_neg_nm: float = 0.0

    def __post_init__(self) -> None:
        super().__post_init__()
        _check_nonnegative(self.id, "torque_pos_nm", self.torque_pos_nm)
        _check_nonnegative(self.id, "torque_neg_nm", self.torque_neg_nm)


@dataclass(frozen=True)
class StribeckFriction(_Effect):
    """Breakaway above the Coulomb level at low speed (the Stribeck curve): the motor supplies
    static_torque_nm x exp(-(v / velocity_rad_s)^2) x sign(v) in addition to Coulomb friction, and a
    stuck axis needs that much more to break away."""

    id: ClassVar[str] = "stribeck_friction"
    units: ClassVar[dict[str, str]] = {"static_torque_nm": "N m", "velocity_rad_s": "rad/s"}
    static_torque_nm: float = 0.0
    velocity_rad_s: float = 0.01

    def __post_init__(self) -> None:
        super().__post_init__()
        _check_nonnegative(self.id, "static_torque_nm", self.static_torque_nm)
        if self.velocity_rad_s <= 0:
            raise ValueError(
                f"effect {self.id}: velocity_rad_s must be positive, got {self.velocity_rad_s!r}")


@dataclass(frozen=True)
class TorqueConstantError(_Effect):
    """The motor gives ratio x Kt x current, where the nominal model assumes Kt x current: the
    driver's current monitor or the catalogue torque constant is off by that factor."""

    id: ClassVar[str] = "torque_constant_error"
    units: ClassVar[dict[str, str]] = {"ratio": "1"}
    ratio: float = 1.0

    def __post_init__(self) -> None:
        super().__post_init__()
        if not 0.1 <= self.ratio <= 10.0:
            raise ValueError(f"effect {self.id}: ratio must be between 0.1 and 10, got {self.ratio!r}")


@dataclass(frozen=True)
class KinematicError(_Effect):
    """Transmission error of the gear: load_pos - pos = amplitude x sin(cycles x motor angle + phase)."""

    id: ClassVar[str] = "kinematic_error"
    channel: ClassVar[str] = "position"
    units: ClassVar[dict[str, str]] = {
        "amplitude_arcsec": "arcsec", "cycles_per_motor_rev": "1/rev", "phase_deg": "deg",
    }
    amplitude_arcsec: float = 0.0
    cycles_per_motor_rev: float = 2.0
    phase_deg: float = 0.0


@dataclass(frozen=True)
class TorsionalCompliance(_Effect):
    """The gear's wind-up between motor side and load side (two-mass model).

    Without overrides the catalogue curve (manual 1-9-2) is used. stiffness_nm_per_rad overrides
    K1; K2 and K3 then scale by the same factor unless given themselves; t1_nm/t2_nm override the
    breakpoints. An axis without a catalogue curve needs stiffness_nm_per_rad (a linear spring).
    """

    id: ClassVar[str] = "torsional_compliance"
    channel: ClassVar[str] = "position"
    units: ClassVar[dict[str, str]] = {
        "stiffness_nm_per_rad": "N m/rad", "k2_nm_per_rad": "N m/rad", "k3_nm_per_rad": "N m/rad",
        "t1_nm": "N m", "t2_nm": "N m",
    }
    stiffness_nm_per_rad: float | None = None
    k2_nm_per_rad: float | None = None
    k3_nm_per_rad: float | None = None
    t1_nm: float | None = None
    t2_nm: float | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if value is not None and value <= 0:
                raise ValueError(f"effect {self.id}: {f.name} must be positive, got {value!r}")


@dataclass(frozen=True)
class LostMotion(_Effect):
    """A dead band of total width_arcsec between motor side and load, seen at reversals."""

    id: ClassVar[str] = "lost_motion"
    channel: ClassVar[str] = "position"
    units: ClassVar[dict[str, str]] = {"width_arcsec": "arcsec"}
    width_arcsec: float = 0.0

    def __post_init__(self) -> None:
        super().__post_init__()
        _check_nonnegative(self.id, "width_arcsec", self.width_arcsec)


EFFECT_TYPES: dict[str, type[_Effect]] = {
    cls.id: cls
    for cls in (
        CoulombFriction, ViscousFriction, GravityLoad, LoadTorqueOffset, InertiaError, TorqueRipple,
        KinematicError, TorsionalCompliance, LostMotion, AsymmetricFriction, StribeckFriction,
        TorqueConstantError,
    )
}
EFFECT_IDS: tuple[str, ...] = tuple(EFFECT_TYPES)


@dataclass(frozen=True)
class Effects:
    """Which effects are on (a value) or off (None), with their parameters. Effects() = nominal model."""

    coulomb_friction: CoulombFriction | None = None
    viscous_friction: ViscousFriction | None = None
    gravity_load: GravityLoad | None = None
    load_torque_offset: LoadTorqueOffset | None = None
    inertia_error: InertiaError | None = None
    torque_ripple: TorqueRipple | None = None
    kinematic_error: KinematicError | None = None
    torsional_compliance: TorsionalCompliance | None = None
    lost_motion: LostMotion | None = None
    asymmetric_friction: AsymmetricFriction | None = None
    stribeck_friction: StribeckFriction | None = None
    torque_constant_error: TorqueConstantError | None = None

    def __post_init__(self) -> None:
        for effect_id, cls in EFFECT_TYPES.items():
            value = getattr(self, effect_id)
            if value is not None and not isinstance(value, cls):
                raise TypeError(
                    f"Effects.{effect_id} must be a {cls.__name__} or None, got {type(value).__name__}")

    def enabled(self) -> list[str]:
        """Ids of the effects that are on, in contract order."""
        return [i for i in EFFECT_IDS if getattr(self, i) is not None]

    def with_effect(self, effect_id: str, **params: float) -> Effects:
        """A copy with one effect switched on (or replaced) with the given parameters."""
        cls = _effect_type(effect_id)
        try:
            effect = cls(**params)
        except TypeError as exc:
            allowed = ", ".join(f.name for f in dataclasses.fields(cls))
            raise ValueError(
                f"effect {effect_id}: bad parameters {sorted(params)}; allowed: {allowed}") from exc
        changes: dict[str, Any] = {effect_id: effect}
        return dataclasses.replace(self, **changes)

    def without(self, effect_id: str) -> Effects:
        """A copy with one effect switched off."""
        _effect_type(effect_id)
        return dataclasses.replace(self, **{effect_id: None})

    def to_list(self) -> list[dict[str, Any]]:
        """[{id, params, channel}] for the effects that are on (the model check's report shape)."""
        return [
            {"id": i, "params": getattr(self, i).params(), "channel": getattr(self, i).channel}
            for i in self.enabled()
        ]

    def to_dict(self) -> dict[str, dict[str, float]]:
        """{id: params} for the effects that are on."""
        return {i: getattr(self, i).params() for i in self.enabled()}

    @classmethod
    def from_dict(cls, data: dict[str, dict[str, float]], where: str = "effects") -> Effects:
        """From {id: params} (a model file, the simulated drive's options): unknown ids or parameters,
        and values outside their plausible range (fha_studio.plausible), raise ValueError naming them."""
        from fha_studio.plausible import EFFECT_PARAMETER_RANGES

        if not isinstance(data, dict):
            raise ValueError(f"{where}: expected a table of effects by id, got {type(data).__name__}")
        effects = cls()
        for effect_id, params in data.items():
            if not isinstance(params, dict):
                raise ValueError(f"{where}.{effect_id}: expected a table of parameters, got {params!r}")
            for name, value in params.items():
                allowed = EFFECT_PARAMETER_RANGES.get(name)
                if allowed is not None and isinstance(value, int | float) and not isinstance(value, bool) \
                        and not allowed.contains(float(value)):
                    raise ValueError(f"{where}.{effect_id}.{name}: {value:g} is outside {allowed.allowed()} "
                                     f"({allowed.reason})")
            try:
                effects = effects.with_effect(effect_id, **params)
            except ValueError as exc:
                raise ValueError(f"{where}: {exc}") from None
        return effects

    @classmethod
    def from_list(cls, items: list[dict[str, Any]]) -> Effects:
        """From [{id, params}] (the model check's report shape)."""
        return cls.from_dict({item["id"]: dict(item.get("params", {})) for item in items})


def _effect_type(effect_id: str) -> type[_Effect]:
    try:
        return EFFECT_TYPES[effect_id]
    except KeyError:
        raise ValueError(f"unknown effect id {effect_id!r}; known: {', '.join(EFFECT_IDS)}") from None
