"""Does the actuator on the axis belong to the driver? (FHA-C manual 1-3 and 3-1.)

The driver is tuned for the actuator printed on its label's ADJUSTED FOR USE WITH line; a wrong
pair causes low torque or overcurrent (manual 3-1). The last three digits of the driver model
(TYPE line) are its supply voltage: 200 or 100 V.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class PairingCheck:
    """The outcome: `warnings` empty means the pair is the catalogue's."""

    actuator_code: str
    driver_model: str
    adjusted_for: str
    compatible_drivers: tuple[str, ...] = ()
    warnings: tuple[str, ...] = field(default_factory=tuple)

    @property
    def ok(self) -> bool:
        return not self.warnings


def _normalise(code: str) -> str:
    return code.strip().upper()


def _base_code(code: str) -> str:
    """FHA-25C-50-US250-B -> FHA-25C-50-US250 (options do not change the pairing)."""
    parts = _normalise(code).split("-")
    return "-".join(parts[:4])


def check_pairing(actuator_code: str, driver_model: str = "", adjusted_for: str = "") -> PairingCheck:
    """Compares the actuator's model code with the driver's TYPE and ADJUSTED FOR USE WITH lines.

    Raises the catalogue's ModelCodeError (a ValueError) when the actuator code is not valid.
    """
    from fha_studio.catalog import compatible_drivers, parse_model_code

    code = _normalise(actuator_code)
    parsed = parse_model_code(code)
    drivers = tuple(compatible_drivers(code))
    warnings: list[str] = []
    driver = _normalise(driver_model)
    if adjusted_for and _base_code(adjusted_for) != _base_code(code):
        warnings.append(
            f"The driver is ADJUSTED FOR USE WITH {_normalise(adjusted_for)}, but the actuator is {code}. "
            "The driver is tuned for the actuator on its label: a wrong pair can cause low torque or "
            "overcurrent (manual 3-1)."
        )
    if driver and drivers and not any(_same_driver(driver, d) for d in drivers):
        warnings.append(
            f"{driver} is not a driver for {code} in the manual's combination table (1-3); "
            f"it lists {', '.join(drivers)}."
        )
    supply = getattr(parsed, "supply_voltage", None)
    driver_volts = driver.rsplit("-", 1)[-1] if driver else ""
    if supply and driver_volts.isdigit() and int(driver_volts) != int(supply):
        warnings.append(
            f"The actuator is for a {supply} V supply, the driver {driver} for {driver_volts} V "
            "(last three digits of its TYPE line)."
        )
    return PairingCheck(code, driver, _normalise(adjusted_for), drivers, tuple(warnings))


def _same_driver(driver: str, listed: str) -> bool:
    # "HA-655-2-200" on the label may carry a suffix; the table names the base model.
    return driver == listed or driver.startswith(listed + "-")
