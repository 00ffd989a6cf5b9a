"""The simulated drive's parameters and EEPROM: stored and active item values, and the EEPROM
document that also keeps the alarm history and the absolute encoder's data over a power cycle.

Stored values are what the EEPROM holds (PRD reads them); active values are copied from them at
power-on, and a write of an item that needs no restart takes effect at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from fha_studio.hardware.parameters import Mode, ParameterItem, ParameterModel, ParameterValueError
from fha_studio.hardware.sim.eeprom import EepromError, EepromFile
from fha_studio.hardware.sim.reply import rejected, servo_is_on
from fha_studio.hardware.sim.supervision import SimAlarmRecord

ItemId = tuple[Mode, int]


@dataclass
class PersistentState:
    """What the EEPROM keeps besides the items: the alarm history, newest first, the shaft's
    output angle (it does not move while the drive is off) and where the absolute count is 0."""

    alarm_history: list[SimAlarmRecord] = field(default_factory=list)
    mechanical_angle_rad: float = 0.0
    absolute_zero_rad: float = 0.0


class ParameterMemory:
    """The tune / parameter (system) / test items of one drive and the EEPROM file behind them."""

    def __init__(self, parameters: ParameterModel, eeprom: EepromFile, *, driver: str, actuator_code: str):
        self.parameters = parameters
        self.eeprom = eeprom
        self.driver = driver
        self.actuator_code = actuator_code
        self.stored: dict[ItemId, int] = self._defaults()
        self.active: dict[ItemId, int] = dict(self.stored)

    def _defaults(self) -> dict[ItemId, int]:
        return {
            (item.mode, item.number): item.default
            for item in self.parameters
            if item.mode is not Mode.MONITOR and item.default is not None
        }

    # ---- values ------------------------------------------------------------------------------
    def power_on(self) -> None:
        """Control power on: every item's stored value becomes active."""
        self.active = dict(self.stored)

    def value(self, key: str) -> int:
        """The active value of item ``key``."""
        item = self.parameters.by_key(key)
        return self.active[(item.mode, item.number)]

    def item(self, key: str) -> ParameterItem:
        return self.parameters.by_key(key)

    def stored_value(self, mode: Mode | str, number: int) -> int:
        """The stored (EEPROM) value of an item; KeyError for an unknown item."""
        item = self.parameters.item(mode, number)
        return self.stored[(item.mode, item.number)]

    def by_key(self, values: dict[ItemId, int]) -> dict[str, int]:
        """``values`` keyed by item key (``rotary_direction``) instead of (mode, number)."""
        return {self.parameters.item(mode, number).key: v for (mode, number), v in values.items()}

    def write(self, mode: Mode | str, number: int, value: int, *, servo_on: bool) -> bool:
        """Store an item (the caller saves the EEPROM). Returns True when the active value changed
        too (an item that needs no restart). Raises SimRefused: ``x`` for an unknown, read-only or
        out-of-range value, ``s`` for a parameter-mode item with the servo on."""
        try:
            item = self.parameters.item(mode, number)
        except (KeyError, ValueError) as exc:
            raise rejected(str(exc.args[0])) from None
        if not item.writable or item.mode is Mode.MONITOR:
            raise rejected(f"{item.label} is read-only")
        if item.mode is Mode.SYSTEM and servo_on:
            raise servo_is_on(f"{item.label}: parameter-mode items are written with the servo off")
        try:
            item.check(value)
        except ParameterValueError as exc:
            raise rejected(str(exc)) from None
        self.stored[(item.mode, item.number)] = value
        if item.restart_required:
            return False
        self.active[(item.mode, item.number)] = value
        return True

    # ---- the EEPROM file ---------------------------------------------------------------------
    def load(self) -> PersistentState | None:
        """Read the EEPROM: the stored items (factory defaults for those it lacks) and the state
        it keeps; None when there is no file yet. Raises EepromError naming the file and what."""
        stored = self._defaults()
        doc = self.eeprom.load()
        path = self.eeprom.path
        if doc is None:
            self.stored = stored
            return None
        if doc.get("actuator") not in (None, self.actuator_code):
            raise EepromError(
                f"simulated drive EEPROM {path} was adjusted for {doc.get('actuator')}, not "
                f"{self.actuator_code}; use another file (or delete it)"
            )
        params = doc.get("parameters", {})
        if not isinstance(params, dict):
            raise EepromError(f"simulated drive EEPROM {path}: 'parameters' is not a table")
        for mode_name, values in params.items():
            try:
                mode = Mode(mode_name)
            except ValueError:
                raise EepromError(f"simulated drive EEPROM {path}: unknown mode {mode_name!r}") from None
            if not isinstance(values, dict):
                raise EepromError(f"simulated drive EEPROM {path}: parameters.{mode_name} is not a table")
            for key, value in values.items():
                try:
                    item = self.parameters.by_key(key)
                except KeyError:
                    continue  # an item this version no longer has
                if item.mode is not mode:
                    raise EepromError(f"simulated drive EEPROM {path}: {key} is a {item.mode.value} item")
                try:
                    item.check(value)
                except ParameterValueError as exc:
                    raise EepromError(f"simulated drive EEPROM {path}: {exc}") from None
                stored[(mode, item.number)] = value
        try:
            history = [SimAlarmRecord(int(a["code"]), float(a["seconds"]), str(a["time_utc"]))
                       for a in doc.get("alarm_history", [])]
            encoder = doc.get("encoder", {})
            mechanical = float(encoder.get("mechanical_angle_rad", 0.0))
            absolute_zero = float(encoder.get("absolute_zero_rad", 0.0))
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise EepromError(
                f"simulated drive EEPROM {path}: bad alarm history or encoder data ({exc})"
            ) from None
        if not (math.isfinite(mechanical) and math.isfinite(absolute_zero)):
            raise EepromError(f"simulated drive EEPROM {path}: encoder data is not finite")
        self.stored = stored
        return PersistentState(history, mechanical, absolute_zero)

    def save(self, state: PersistentState) -> None:
        """Write the stored items and ``state`` to the EEPROM file (atomically)."""
        by_mode: dict[str, dict[str, int]] = {}
        for (mode, number), value in sorted(self.stored.items()):
            by_mode.setdefault(mode.value, {})[self.parameters.item(mode, number).key] = value
        self.eeprom.save({
            "driver": self.driver,
            "actuator": self.actuator_code,
            "parameters": by_mode,
            "alarm_history": [
                {"code": a.code, "seconds": round(a.seconds_since_power_on, 3), "time_utc": a.time_utc}
                for a in state.alarm_history
            ],
            "encoder": {
                "mechanical_angle_rad": state.mechanical_angle_rad,
                "absolute_zero_rad": state.absolute_zero_rad,
            },
        })
