"""The simulated drive's actuator: model code -> catalogue entry + driver, and the physics axis.

The plant and its loops are :class:`fha_studio.physics.ServoAxis`; this module only resolves
what to build (options B and L from the code or the sim options, the driver from the combination
table of FHA-C manual 1-3, the effects). The HA-655's tune / parameter items become the physics'
:class:`ServoSettings` through ``physics.servo_settings``, the mapping tuning uses too.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from fha_studio.catalog import get_actuator, parse_model_code
from fha_studio.catalog.model_code import OPTION_ORDER
from fha_studio.hardware.sim.options import SimConfig, SimConfigError
from fha_studio.physics import AxisModel, Effects, ServoAxis, ServoSettings, catalogue_effects

DEFAULT_SERVO_RATE_HZ = 5000.0
#: what ``catalogue_friction`` takes of the catalogue's effects: the friction, not the gear's
#: compliance (the default gains make a compliant gear under a large load ring: that is tuning's
#: business, turned on on purpose with ``effects=torsional_compliance``)
CATALOGUE_FRICTION_IDS = ("coulomb_friction", "viscous_friction")


@dataclass(frozen=True)
class ResolvedActuator:
    """The actuator the sim drives, its driver, and whether the option-L sensors are fitted."""

    actuator: Any  # fha_studio.catalog Actuator
    driver: str
    has_sensors: bool

    @property
    def code(self) -> str:
        return str(self.actuator.model_code)

    @property
    def absolute_encoder(self) -> bool:
        return bool(self.actuator.encoder == "absolute")

    @property
    def brake_holding_torque_nm(self) -> float | None:
        brake = self.actuator.brake
        return None if brake is None else float(brake.holding_torque_nm)

    @property
    def continuous_current_a(self) -> float:
        """Continuous torque (2-4-6) over the torque constant: the I^2 t reference of alarm 20."""
        return float(self.actuator.continuous_torque_nm) / float(self.actuator.torque_constant_nm_per_a)


def resolve_actuator(config: SimConfig) -> ResolvedActuator:
    """The catalogue actuator for ``config`` (brake / sensors options override the code's B / L)
    and its driver (``config.driver`` if it is a valid combination, else the first HA-655 of 1-3).
    Raises SimConfigError naming what is wrong."""
    try:
        code = parse_model_code(config.actuator)
    except ValueError as exc:
        raise SimConfigError(f"simulated drive actuator: {exc}") from None
    options = set(code.options)
    for flag, option in ((config.brake, "B"), (config.sensors, "L")):
        if flag is True:
            options.add(option)
        elif flag is False:
            options.discard(option)
    text = "-".join([code.base_code, *(o for o in OPTION_ORDER if o in options)])
    try:
        actuator = get_actuator(text)
    except ValueError as exc:
        raise SimConfigError(f"simulated drive actuator: {exc}") from None
    drivers = list(actuator.compatible_drivers)
    if config.driver is not None:
        if config.driver not in drivers:
            raise SimConfigError(
                f"driver {config.driver} does not drive {actuator.model_code} (FHA-C manual 1-3); "
                f"use one of: {', '.join(drivers) or 'none exists'}"
            )
        driver = config.driver
    else:
        if not drivers:
            raise SimConfigError(f"no driver exists for {actuator.model_code} (FHA-C manual 1-3)")
        driver = next((d for d in drivers if d.startswith("HA-655")), drivers[0])
    return ResolvedActuator(actuator, driver, has_sensors="L" in options)


def catalogue_friction(model: AxisModel) -> dict[str, dict[str, float]]:
    """The catalogue's friction of ``model`` as effects by id: TF = Kt x Im - TM at maximum speed
    (FHA-C manual 2-4-4), split into Coulomb and viscous by ``physics.catalogue_effects``."""
    catalogue = catalogue_effects(model.with_effects(Effects())).to_dict()
    return {effect_id: catalogue[effect_id] for effect_id in CATALOGUE_FRICTION_IDS if effect_id in catalogue}


def build_model(resolved: ResolvedActuator, config: SimConfig) -> AxisModel:
    """The physics model: catalogue actuator, declared load inertia, switched-on effects (with
    ``catalogue_friction``, the catalogue's friction under the explicit ones: those win)."""
    try:
        explicit = Effects.from_dict(config.effects, where="sim effects")
        model = AxisModel.from_actuator(resolved.actuator, load_inertia_kgm2=config.load_inertia_kgm2,
                                        effects=explicit)
        if not config.catalogue_friction:
            return model
        merged = {**catalogue_friction(model), **config.effects}
        return model.with_effects(Effects.from_dict(merged, where="sim effects"))
    except (TypeError, ValueError) as exc:
        raise SimConfigError(f"simulated drive: {exc}") from None


def build_axis(model: AxisModel, settings: ServoSettings, initial_pos_rad: float) -> ServoAxis:
    return ServoAxis(model, settings, initial_pos_rad=initial_pos_rad)
