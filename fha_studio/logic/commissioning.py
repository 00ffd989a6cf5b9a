"""The axis being commissioned: one object that every page reads and edits.

What the technician and the drive have said about one axis: the actuator (its model code, parsed
by the catalogue), the driver, the supply voltage, the declared load inertia, the parameter values
read from the drive, the values entered by hand from the drive's front panel (with who and when),
the backup made before the first write, and the log of every write. Everything derived (scope
scaling, sizing, recording metadata, the model check's declaration, procedures, report) is computed
from it when it changes, never kept as a copy.

Plain Python, no Qt: listeners are callables ``listener(change: Change)`` registered with
:meth:`CommissioningState.subscribe`. A machine with several axes has one state per axis, so this
is an ordinary object, never a module-level singleton.
"""

from __future__ import annotations

import enum
import math
import types
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from fha_studio import clock
from fha_studio.hardware.parameters import driver_family
from fha_studio.logic.session_log import SessionLog, WriteRecord

if TYPE_CHECKING:
    from fha_studio.catalog import Actuator, ModelCode

#: (mode, number) of a parameter item, e.g. ("system", 8) for rotary_direction.
ParameterId = tuple[str, int]

#: The supply voltage [V] of a driver whose TYPE line and actuator say nothing (the 200 V range).
DEFAULT_SUPPLY_VOLTAGE_V = 200


class Change(enum.Enum):
    """What changed; a listener gets one of these per change."""

    ACTUATOR = "actuator"  # the model code (or its acknowledgement of a pairing warning)
    DRIVER = "driver"  # the driver's TYPE and ADJUSTED FOR USE WITH lines
    LOAD_INERTIA = "load inertia"
    DRIVE_VALUES = "values read from the drive"
    FRONT_PANEL = "values entered from the front panel"
    BACKUP = "backup"
    WRITE_LOG = "write log"


class BackupRequired(RuntimeError):
    """A write was to be logged before the drive's values were backed up."""


@dataclass(frozen=True)
class FrontPanelEntry:
    """A value the technician read on (or set at) the drive's front panel.

    ``value`` is the item's wire integer, as the panel shows it; ``time`` ISO 8601 local time with
    offset; ``who`` the person who entered it."""

    mode: str
    number: int
    value: int
    who: str
    time: str
    note: str = ""

    @property
    def parameter_id(self) -> ParameterId:
        return (self.mode, self.number)


def driver_supply_voltage_v(driver_model: str) -> int | None:
    """The supply voltage [V] in a driver's TYPE line (its last three digits: 100 or 200)."""
    tail = driver_model.strip().rsplit("-", 1)[-1]
    return int(tail) if tail in ("100", "200") else None


def _now() -> str:
    return clock.local_iso()


Listener = Callable[[Change], None]


class CommissioningState:
    """The axis being commissioned (see the module's docstring).

    ``actuator_code``: the model code on the actuator's label ("" = not known yet); raises the
    catalogue's ``ModelCodeError`` (a ``ValueError``) when it is not a valid code.
    ``load_inertia_kgm2``: the declared load inertia, output side [kg m^2].
    ``write_log``: where writes go (a ``SessionLog`` with a file, or in memory only by default).
    """

    def __init__(
        self,
        actuator_code: str = "",
        *,
        driver_model: str = "",
        adjusted_for: str = "",
        load_inertia_kgm2: float = 0.0,
        write_log: SessionLog | None = None,
    ):
        self._listeners: list[Listener] = []
        self._code = ""
        self._model_code: ModelCode | None = None
        self._actuator: Actuator | None = None
        self._acknowledged = False
        self._driver_model = ""
        self._adjusted_for = ""
        self._load_inertia_kgm2 = 0.0
        self._drive_values: dict[ParameterId, int] = {}
        self._front_panel: dict[ParameterId, FrontPanelEntry] = {}
        self._backup_path: Path | None = None
        self.write_log = write_log if write_log is not None else SessionLog(None)
        self.set_actuator(actuator_code)
        self.set_driver(driver_model, adjusted_for)
        self.set_load_inertia(load_inertia_kgm2)

    # -- listeners ----------------------------------------------------------------------------------
    def subscribe(self, listener: Listener) -> Callable[[], None]:
        """Calls ``listener(change)`` after every change; returns a function that unsubscribes."""
        self._listeners.append(listener)

        def unsubscribe() -> None:
            if listener in self._listeners:
                self._listeners.remove(listener)

        return unsubscribe

    def _notify(self, change: Change) -> None:
        # Every listener hears of the change even when one fails; the first failure is raised after.
        failure: BaseException | None = None
        for listener in list(self._listeners):
            try:
                listener(change)
            except Exception as exc:  # re-raised below, after the others ran
                failure = failure or exc
        if failure is not None:
            raise failure

    # -- the actuator -------------------------------------------------------------------------------
    @property
    def actuator_code(self) -> str:
        """The model code, normalised (upper case, no spaces); "" when not known."""
        return self._code

    @property
    def model_code(self) -> ModelCode | None:
        """The parsed model code (frame, ratio, encoder, options); None when not known."""
        return self._model_code

    @property
    def actuator(self) -> Actuator | None:
        """The catalogue's data of the actuator; None when not known."""
        return self._actuator

    @property
    def actuator_acknowledged(self) -> bool:
        """True when the pairing with the driver was found right or its warning acknowledged
        (for this driver: another one undoes it)."""
        return self._acknowledged

    @property
    def ratio(self) -> int | None:
        """The reduction ratio (50, 100, 160); None without an actuator."""
        return int(self._actuator.ratio) if self._actuator is not None else None

    @property
    def output_resolution_ppr(self) -> int | None:
        """Position pulses per output revolution; None without an actuator."""
        return int(self._actuator.output_resolution_ppr) if self._actuator is not None else None

    def set_actuator(self, code: str, acknowledged: bool | None = None) -> bool:
        """Sets the actuator (``""`` forgets it). Nothing changes when the code is invalid: the
        catalogue's ``ModelCodeError`` says what is wrong. ``acknowledged``: whether the pairing is
        right or its warning acknowledged; None keeps it for the same code and clears it for
        another. Returns True when the code changed."""
        from fha_studio.catalog import get_actuator, parse_model_code

        text = "".join(code.split()).upper()
        if text:
            parsed = parse_model_code(text)
            actuator = get_actuator(parsed)
        else:
            parsed, actuator = None, None
        changed = text != self._code
        if acknowledged is None:
            acknowledged = self._acknowledged and not changed
        if not changed and acknowledged == self._acknowledged:
            return False
        self._code, self._model_code, self._actuator = text, parsed, actuator
        self._acknowledged = acknowledged
        self._notify(Change.ACTUATOR)
        return changed

    def acknowledge_actuator(self) -> None:
        """The technician checked the labels: the pairing warning is acknowledged."""
        if self._code and not self._acknowledged:
            self._acknowledged = True
            self._notify(Change.ACTUATOR)

    # -- the driver and the supply ------------------------------------------------------------------
    @property
    def driver_model(self) -> str:
        """The driver's TYPE line (e.g. "HA-655-2-200"); "" when the drive did not say."""
        return self._driver_model

    @property
    def adjusted_for(self) -> str:
        """The driver label's ADJUSTED FOR USE WITH line; "" when not known."""
        return self._adjusted_for

    @property
    def driver(self) -> str:
        """The driver family whose parameter model applies: "HA-655" or "HA-675"."""
        return driver_family(self._driver_model)

    def set_driver(self, driver_model: str, adjusted_for: str = "") -> None:
        """The driver's TYPE and ADJUSTED FOR USE WITH lines. Another driver undoes the
        acknowledgement of a pairing warning: it was given for the other pair."""
        driver_model, adjusted_for = driver_model.strip().upper(), adjusted_for.strip().upper()
        if (driver_model, adjusted_for) == (self._driver_model, self._adjusted_for):
            return
        self._driver_model, self._adjusted_for = driver_model, adjusted_for
        self._notify(Change.DRIVER)
        if self._acknowledged:
            self._acknowledged = False
            self._notify(Change.ACTUATOR)

    @property
    def supply_voltage_v(self) -> int:
        """The supply voltage [V]: the actuator's (option A = 100 V, else 200 V), else the
        driver's TYPE line, else 200 V."""
        if self._model_code is not None:
            return int(self._model_code.supply_voltage)
        return driver_supply_voltage_v(self._driver_model) or DEFAULT_SUPPLY_VOLTAGE_V

    # -- the load -----------------------------------------------------------------------------------
    @property
    def load_inertia_kgm2(self) -> float:
        """The declared load inertia, output side [kg m^2]."""
        return self._load_inertia_kgm2

    def set_load_inertia(self, load_inertia_kgm2: float) -> None:
        """Raises ValueError (and changes nothing) for a negative or non-finite value."""
        value = float(load_inertia_kgm2)
        if not math.isfinite(value) or value < 0:
            raise ValueError(f"load inertia: {load_inertia_kgm2!s} kg·m² is not a value >= 0")
        if value == self._load_inertia_kgm2:
            return
        self._load_inertia_kgm2 = value
        self._notify(Change.LOAD_INERTIA)

    # -- values read from the drive -----------------------------------------------------------------
    @property
    def drive_values(self) -> Mapping[ParameterId, int]:
        """The drive's parameter values (wire integers) as last read or written, read-only."""
        return types.MappingProxyType(self._drive_values)

    def record_read(self, values: Mapping[ParameterId, int]) -> None:
        """Values read from the drive (wire integers by (mode, number))."""
        new = {(str(m), int(n)): int(v) for (m, n), v in values.items()}
        if all(self._drive_values.get(k) == v for k, v in new.items()):
            return
        self._drive_values.update(new)
        self._notify(Change.DRIVE_VALUES)

    def forget_drive(self) -> None:
        """Another drive (or the same one again) was connected: its values must be read anew and
        it gets its own backup before its first write. Front-panel entries stay: they were typed
        by a person and are removed only by one."""
        had_values, had_backup = bool(self._drive_values), self._backup_path is not None
        self._drive_values.clear()
        self._backup_path = None
        if had_values:
            self._notify(Change.DRIVE_VALUES)
        if had_backup:
            self._notify(Change.BACKUP)

    # -- values entered from the front panel --------------------------------------------------------
    @property
    def front_panel(self) -> Mapping[ParameterId, FrontPanelEntry]:
        """Entries typed from the drive's front panel, by (mode, number), read-only."""
        return types.MappingProxyType(self._front_panel)

    def enter_front_panel(
        self, mode: str, number: int, value: int, who: str, time: str | None = None, note: str = ""
    ) -> FrontPanelEntry:
        """Records what the panel shows for item (mode, number); ``who`` must be given."""
        if not who.strip():
            raise ValueError(f"front-panel value of {mode} {number}: say who entered it")
        entry = FrontPanelEntry(str(mode), int(number), int(value), who.strip(), time or _now(), note)
        self._front_panel[entry.parameter_id] = entry
        self._notify(Change.FRONT_PANEL)
        return entry

    def remove_front_panel(self, mode: str, number: int) -> None:
        if self._front_panel.pop((mode, int(number)), None) is not None:
            self._notify(Change.FRONT_PANEL)

    def value_of(self, mode: str, number: int) -> int | None:
        """The item's value as known: read from the drive, else entered from the panel, else None."""
        key = (mode, int(number))
        if key in self._drive_values:
            return self._drive_values[key]
        entry = self._front_panel.get(key)
        return entry.value if entry is not None else None

    # -- back up the drive before the first write ---------------------------------------------------
    @property
    def backup_path(self) -> Path | None:
        """Where the backup of this drive's values was saved; None when not made yet."""
        return self._backup_path

    @property
    def backup_made(self) -> bool:
        return self._backup_path is not None

    @property
    def needs_backup(self) -> bool:
        """True until a backup is made: the first write to a drive must wait for it."""
        return self._backup_path is None

    def record_backup(self, path: Path) -> None:
        self._backup_path = Path(path)
        self._notify(Change.BACKUP)

    # -- the write log ------------------------------------------------------------------------------
    @property
    def writes(self) -> list[WriteRecord]:
        """Every write of this session, oldest first (a copy)."""
        return list(self.write_log.records)

    def require_backup(self, what: str = "a write") -> None:
        """Raises BackupRequired unless the drive's values were backed up: call it before sending
        a write to the drive."""
        if self._backup_path is None:
            raise BackupRequired(f"{what}: back up the drive's parameters before the first write")

    def record_write(self, record: WriteRecord) -> None:
        """Logs a write that was made and takes its outcome as the drive's value (the read-back, or
        the new value when verified). A write is a fact: it is logged even without a backup
        (:meth:`require_backup` is what stops one before it is sent). The log file is a copy: when
        it cannot be written, OSError is raised after the record is kept in memory."""
        error: OSError | None = None
        try:
            self.write_log.append(record)  # keeps the record in memory before writing the file
        except OSError as exc:
            error = exc
        key = (record.mode, record.number)
        if record.read_back is not None:
            self._drive_values[key] = record.read_back
        elif record.verified:
            self._drive_values[key] = record.new
        self._notify(Change.WRITE_LOG)
        self._notify(Change.DRIVE_VALUES)
        if error is not None:
            raise error

