"""The commissioning workflow the pages share: the link, the driver's parameter model, reading and
writing parameters with the automatic backup before the first write. What is known of the axis
(actuator, load, the drive's values, the backup, the write log) lives in the commissioning state
(`state`, an `AxisState`), never here."""

from __future__ import annotations

import logging
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import cast

from PySide6.QtCore import QObject, QStandardPaths, Signal, Slot

from fha_studio import clock, fileio
from fha_studio.catalog import DEFAULT_ACTUATOR
from fha_studio.gui.link import (
    LinkController,
    LinkInfo,
    LinkReply,
    OnReply,
    ParameterReadout,
    ReadParameters,
    WriteEntry,
    WriteParameters,
)
from fha_studio.gui.state import AxisState
from fha_studio.hardware.parameters import Mode
from fha_studio.logic.commissioning import CommissioningState
from fha_studio.logic.drive_session import ParameterWrite
from fha_studio.logic.paramfile import dump_parameter_file
from fha_studio.logic.session_log import SessionLog, WriteRecord

log = logging.getLogger(__name__)

DEFAULT_SIM_URL = f"sim://{DEFAULT_ACTUATOR}"


def data_dir() -> Path:
    """Where backups and session logs go (per user; tests redirect it through XDG_DATA_HOME)."""
    base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
    path = Path(base) if base else Path.home() / ".fha-studio"
    path.mkdir(parents=True, exist_ok=True)
    return path


def new_axis_state(parent: QObject | None = None) -> AxisState:
    """A commissioning state whose write log goes to a new file in the data directory."""
    stamp = clock.file_stamp()
    log = SessionLog(data_dir() / "sessions" / f"session-{stamp}.jsonl")
    return AxisState(CommissioningState(write_log=log), parent)


class Session(QObject):
    """The parameter workflow of the session, on the GUI thread. ``state`` is the axis's
    commissioning state (one per window; the pages read and edit the axis through it)."""

    sigWritesDone = Signal(object)  # list of write entries of one request
    sigParametersRead = Signal(object)  # the LinkReply of each read of the session (a ParameterReadout)
    sigMessage = Signal(str)  # something for the status bar

    def __init__(self, link: LinkController, state: AxisState | None = None, parent: QObject | None = None):
        super().__init__(parent)
        self.link = link
        self.state = state if state is not None else new_axis_state(self)
        self._models: dict[str, object] = {}
        self._pending_writes: list[ParameterWrite] | None = None
        link.sigWrite.connect(self._on_write)
        link.sigConnected.connect(self._on_connected)

    # -- the driver's parameter model ---------------------------------------------------------------
    @property
    def driver(self) -> str:
        """The driver family of the connected drive (HA-655 when unknown)."""
        return self.state.driver

    @property
    def parameter_model(self):
        """The parameter model of the connected driver family (HA-655 when unknown)."""
        driver = self.driver
        if driver not in self._models:
            from fha_studio.hardware.parameters import load_parameter_model

            self._models[driver] = load_parameter_model(driver)
        return self._models[driver]

    def editable_items(self) -> list:
        """Writable tune and parameter (system) items, in panel order."""
        return [i for i in self.parameter_model if i.mode in (Mode.TUNE, Mode.SYSTEM) and i.writable]

    def item(self, key: str):
        return self.parameter_model.by_key(key)

    # -- reading and writing ------------------------------------------------------------------------
    def read_all(self) -> int:
        """Read every editable item; the values go into the state, the reply to
        ``sigParametersRead``."""
        return self._read_all()

    def _read_all(self, then: OnReply[ParameterReadout] | None = None) -> int:
        items = tuple((Mode(i.mode), i.number) for i in self.editable_items())

        def on_reply(result: LinkReply[ParameterReadout]) -> None:
            if result.ok:  # keyed by Mode, a str: the state's (mode name, number) keys
                self.state.record_read(cast(Mapping[tuple[str, int], int], result.answer.values))
            if then is not None:
                then(result)
            self.sigParametersRead.emit(result)

        return self.link.send(ReadParameters(items), on_reply)

    def known_values(self) -> dict[tuple[str, int], int]:
        """The items' values as known: read from the drive, else entered from its front panel."""
        values = {key: entry.value for key, entry in self.state.front_panel.items()}
        values.update(self.state.drive_values)
        return values

    def parameter_file_text(self, values: dict | None = None) -> str:
        """The parameter file of the known values (those entered from the front panel marked so)."""
        values = self.known_values() if values is None else values
        panel = {k: e for k, e in self.state.front_panel.items() if k not in self.state.drive_values}
        return dump_parameter_file(
            self.parameter_model,
            values,
            self.state.actuator_code,
            self.state.driver_model,
            front_panel=panel,
        )

    def write(self, writes: Iterable[tuple[Mode | str, int, int]]) -> None:
        """Writes (mode, number, wire value) items, each verified by read-back. Before the first
        write of a session the drive's values are read and saved as a backup."""
        typed = [(Mode(mode), number, value) for mode, number, value in writes]
        if not typed:
            return
        if self.state.needs_backup:
            self._pending_writes = typed
            self._read_all(then=self._backup_read)
            self.sigMessage.emit("Reading the drive's parameters for the backup before the first write …")
            return
        self.state.require_backup()
        self._send_writes(typed)

    def _send_writes(self, writes: list[ParameterWrite]) -> None:
        self.link.send(WriteParameters(tuple(writes)), self._writes_answered)

    def _writes_answered(self, result: LinkReply[list[WriteEntry]]) -> None:
        self.sigWritesDone.emit(result.value if result.ok else [])

    def write_backup(self) -> Path:
        """Saves the drive's values as read before the first write of the session."""
        stamp = clock.file_stamp()
        directory = data_dir() / "backups"
        directory.mkdir(parents=True, exist_ok=True)
        base = f"backup-{self.state.actuator_code or 'unknown-actuator'}-{stamp}"
        path = directory / f"{base}.toml"
        n = 1
        while path.exists():
            n += 1
            path = directory / f"{base}-{n}.toml"
        fileio.write_text(path, self.parameter_file_text())
        self.state.record_backup(path)
        self.sigMessage.emit(f"Backup of the drive's parameters saved before the first write: {path}")
        return path

    # -- from the link ------------------------------------------------------------------------------
    @Slot(object)
    def _on_connected(self, info: LinkInfo) -> None:
        self._pending_writes = None
        self.state.set_driver(info.driver_model or "", info.adjusted_for or "")
        self.state.forget_drive()  # a new drive: its values read anew, a new backup before its first write
        if not self.state.actuator_code and info.adjusted_for:
            try:
                self.state.set_actuator(info.adjusted_for)
            except ValueError as exc:  # the label's line is not a model code: the technician types it
                self.sigMessage.emit(f"ADJUSTED FOR USE WITH {info.adjusted_for}: not a model code ({exc})")

    def _backup_read(self, result: LinkReply[ParameterReadout]) -> None:
        """The read before the first write: saved as the backup, then the writes go."""
        writes, self._pending_writes = self._pending_writes, None
        if not result.ok or result.value.errors:
            why = result.error or "; ".join(f"{m} {n}: {e}" for (m, n), e in result.value.errors.items())
            self.sigMessage.emit(f"Nothing written: the backup read failed ({why}).")
            self.sigWritesDone.emit([])
            return
        try:
            self.write_backup()
        except (OSError, ValueError) as exc:  # fileio.FileProblem is a ValueError
            self.sigMessage.emit(f"Nothing written: the backup could not be saved ({exc}).")
            self.sigWritesDone.emit([])
            return
        if writes:
            self._send_writes(writes)

    @Slot(object)
    def _on_write(self, entry: dict) -> None:
        key = (entry["mode"], entry["number"])
        try:
            item = self.parameter_model.item(*key)
            item_key, name = item.key, item.name
        except KeyError:
            item_key, name = f"{key[0]}_{key[1]}", ""
        record = WriteRecord(
            time=SessionLog.now(),
            mode=str(key[0]),
            number=int(key[1]),
            key=item_key,
            name=name,
            old=entry.get("old"),
            new=int(entry["new"]),
            read_back=entry.get("read_back"),
            verified=bool(entry.get("verified")),
            error=entry.get("error"),
        )
        try:
            self.state.record_write(record)
        except OSError as exc:  # the log file is a copy; the write itself happened
            log.warning("session log file not written (the record is kept in memory): %s", exc)
