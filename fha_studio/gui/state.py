"""The GUI's one face of the axis being commissioned: a QObject that owns a
:class:`~fha_studio.logic.commissioning.CommissioningState` and turns its changes into signals.

The main window makes one and every page reads and edits the axis through it (the actuator, the
driver, the supply voltage, the declared load inertia, the drive's values, the front-panel
entries, the backup and the write log); no page keeps its own copy. Edits made on the model
directly are signalled too: the adapter listens to the model, it does not shadow it.
"""

from __future__ import annotations

import contextlib
from collections.abc import Mapping
from pathlib import Path

from PySide6.QtCore import QObject, QSettings, Signal

from fha_studio.catalog import Actuator, ModelCode
from fha_studio.logic.commissioning import Change, CommissioningState, FrontPanelEntry, ParameterId
from fha_studio.logic.session_log import WriteRecord

#: QSettings key of the declared load inertia (kept between runs, like the last actuator).
LOAD_INERTIA_KEY = "axis/load_inertia_kgm2"


class AxisState(QObject):
    """Signals and edits of one axis's commissioning state, on the GUI thread."""

    sigChanged = Signal(object)  # Change: any of the below
    sigActuatorChanged = Signal(str)  # the model code ("" = none), or its acknowledgement
    sigDriverChanged = Signal()  # the driver's TYPE / ADJUSTED FOR USE WITH lines
    sigLoadInertiaChanged = Signal(float)  # kg m^2
    sigParametersChanged = Signal()  # the values read from (or written to) the drive
    sigFrontPanelChanged = Signal()  # the values entered from the front panel
    sigBackupChanged = Signal()
    sigWriteLogChanged = Signal()

    def __init__(self, model: CommissioningState | None = None, parent: QObject | None = None):
        super().__init__(parent)
        self._model = model if model is not None else CommissioningState()
        self._unsubscribe = self._model.subscribe(self._on_change)
        self.destroyed.connect(self._unsubscribe)

    @property
    def model(self) -> CommissioningState:
        """The Qt-free state (what the logic layer, the report and a machine project keep)."""
        return self._model

    def _on_change(self, change: Change) -> None:
        if change is Change.ACTUATOR:
            self.sigActuatorChanged.emit(self._model.actuator_code)
        elif change is Change.DRIVER:
            self.sigDriverChanged.emit()
        elif change is Change.LOAD_INERTIA:
            self.sigLoadInertiaChanged.emit(self._model.load_inertia_kgm2)
        elif change is Change.DRIVE_VALUES:
            self.sigParametersChanged.emit()
        elif change is Change.FRONT_PANEL:
            self.sigFrontPanelChanged.emit()
        elif change is Change.BACKUP:
            self.sigBackupChanged.emit()
        elif change is Change.WRITE_LOG:
            self.sigWriteLogChanged.emit()
        self.sigChanged.emit(change)

    # -- settings -----------------------------------------------------------------------------------
    def restore_settings(self, settings: QSettings) -> None:
        value = settings.value(LOAD_INERTIA_KEY)
        if value is not None:
            with contextlib.suppress(TypeError, ValueError):  # a damaged setting: the load stays at 0
                self._model.set_load_inertia(float(value))

    def save_settings(self, settings: QSettings) -> None:
        settings.setValue(LOAD_INERTIA_KEY, self._model.load_inertia_kgm2)

    # -- reading (see CommissioningState for the meaning and units) ---------------------------------
    @property
    def actuator_code(self) -> str:
        return self._model.actuator_code

    @property
    def model_code(self) -> ModelCode | None:
        return self._model.model_code

    @property
    def actuator(self) -> Actuator | None:
        return self._model.actuator

    @property
    def actuator_acknowledged(self) -> bool:
        return self._model.actuator_acknowledged

    @property
    def ratio(self) -> int | None:
        return self._model.ratio

    @property
    def output_resolution_ppr(self) -> int | None:
        return self._model.output_resolution_ppr

    @property
    def driver_model(self) -> str:
        return self._model.driver_model

    @property
    def adjusted_for(self) -> str:
        return self._model.adjusted_for

    @property
    def driver(self) -> str:
        return self._model.driver

    @property
    def supply_voltage_v(self) -> int:
        return self._model.supply_voltage_v

    @property
    def load_inertia_kgm2(self) -> float:
        return self._model.load_inertia_kgm2

    @property
    def drive_values(self) -> Mapping[ParameterId, int]:
        return self._model.drive_values

    @property
    def front_panel(self) -> Mapping[ParameterId, FrontPanelEntry]:
        return self._model.front_panel

    def value_of(self, mode: str, number: int) -> int | None:
        return self._model.value_of(mode, number)

    @property
    def backup_path(self) -> Path | None:
        return self._model.backup_path

    @property
    def needs_backup(self) -> bool:
        return self._model.needs_backup

    @property
    def writes(self) -> list[WriteRecord]:
        return self._model.writes

    # -- editing ------------------------------------------------------------------------------------
    def set_actuator(self, code: str, acknowledged: bool | None = None) -> bool:
        return self._model.set_actuator(code, acknowledged)

    def acknowledge_actuator(self) -> None:
        self._model.acknowledge_actuator()

    def set_driver(self, driver_model: str, adjusted_for: str = "") -> None:
        self._model.set_driver(driver_model, adjusted_for)

    def set_load_inertia(self, load_inertia_kgm2: float) -> None:
        self._model.set_load_inertia(load_inertia_kgm2)

    def record_read(self, values: Mapping[ParameterId, int]) -> None:
        self._model.record_read(values)

    def forget_drive(self) -> None:
        self._model.forget_drive()

    def enter_front_panel(
        self, mode: str, number: int, value: int, who: str, time: str | None = None, note: str = ""
    ) -> FrontPanelEntry:
        return self._model.enter_front_panel(mode, number, value, who, time, note)

    def remove_front_panel(self, mode: str, number: int) -> None:
        self._model.remove_front_panel(mode, number)

    def record_backup(self, path: Path) -> None:
        self._model.record_backup(path)

    def record_write(self, record: WriteRecord) -> None:
        self._model.record_write(record)

    def require_backup(self, what: str = "a write") -> None:
        self._model.require_backup(what)
