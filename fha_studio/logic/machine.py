"""A machine project: a machine of several axes, each an FHA-C actuator on its own driver and port.

A machine has a name, a site and its axes. An axis has a name, a port (URL: a serial device, a
pty, ``socket://host:port`` or ``sim://...``), notes, the actuator's serial number, the procedure
session file of its commissioning, and one :class:`CommissioningState`: the actuator's model code,
the driver, the declared load inertia and everything read or written live there, not in a copy.

The project is kept in the register (machine and axis rows, :meth:`MachineProject.save_to` /
:meth:`MachineProject.from_register`) and can be carried as a file (``fha-machine/1``, JSON,
written atomically).
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fha_studio import fileio, names, plausible
from fha_studio.logic.commissioning import CommissioningState
from fha_studio.names import kind_of, quoted

FORMAT = "fha-machine/1"


#: The text fields of a machine file, and of each of its axes (load_inertia_kgm2 is a number).
MACHINE_FIELDS = ("name", "site", "notes")
AXIS_FIELDS = ("name", "actuator_code", "driver_model", "port_url", "notes", "serial_number", "session_file")
#: The longest text field a machine file may hold (notes); names are shorter (fha_studio.names).
MAX_FIELD_TEXT = 10_000


class MachineError(ValueError):
    """A machine or axis that does not fit (a name taken, a file that is not a machine file);
    the message says what and where."""


@dataclass
class MachineAxis:
    """One axis of a machine. Actuator, driver and load inertia are the commissioning state's."""

    name: str
    port_url: str = ""
    notes: str = ""
    serial_number: str = ""
    session_file: Path | None = None
    state: CommissioningState = field(default_factory=CommissioningState)

    @property
    def actuator_code(self) -> str:
        return self.state.actuator_code

    @property
    def driver_model(self) -> str:
        return self.state.driver_model

    @property
    def load_inertia_kgm2(self) -> float:
        return self.state.load_inertia_kgm2

    def to_json(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "actuator_code": self.actuator_code,
            "driver_model": self.driver_model,
            "port_url": self.port_url,
            "load_inertia_kgm2": self.load_inertia_kgm2,
            "notes": self.notes,
            "serial_number": self.serial_number,
            "session_file": str(self.session_file) if self.session_file else "",
        }


class MachineProject:
    """A machine and its axes, in the order they were added."""

    def __init__(self, name: str, site: str = "", notes: str = ""):
        if not name.strip():
            raise MachineError("a machine needs a name")
        try:  # one line of printable text, of a length a list shows (fha_studio.names)
            name = names.check_name(name, "machine name")
            site = names.check_name(site, "site", names.TEXT_MAX, empty_ok=True)
        except names.NameProblem as exc:
            raise MachineError(str(exc)) from None
        if "/" in name:
            raise MachineError(f"machine name '{name}': '/' separates machine and axis, use another sign")
        self.name = name
        self.site = site.strip()
        self.notes = notes
        self._axes: list[MachineAxis] = []

    # -- axes -----------------------------------------------------------------------------------------
    @property
    def axes(self) -> tuple[MachineAxis, ...]:
        return tuple(self._axes)

    def __iter__(self) -> Iterator[MachineAxis]:
        return iter(self._axes)

    def __len__(self) -> int:
        return len(self._axes)

    def add_axis(
        self,
        name: str,
        actuator_code: str = "",
        driver_model: str = "",
        port_url: str = "",
        load_inertia_kgm2: float = 0.0,
        notes: str = "",
        serial_number: str = "",
        session_file: str | Path | None = None,
    ) -> MachineAxis:
        """A new axis with its own commissioning state. Raises MachineError for an empty or taken
        name, and the catalogue's ModelCodeError (a ValueError) for a wrong model code; nothing is
        added then."""
        if not name.strip():
            raise MachineError(f"an axis of '{self.name}' needs a name")
        try:
            name = names.check_name(name, "axis name")
            port_url = names.check_name(port_url, "port", names.PORT_MAX, empty_ok=True)
            serial_number = names.check_name(serial_number, "serial number", names.TEXT_MAX, empty_ok=True)
        except names.NameProblem as exc:
            raise MachineError(str(exc)) from None
        if any(a.name == name for a in self._axes):
            raise MachineError(f"'{self.name}' already has an axis called '{name}'")
        port = port_url.strip()
        # one port, one drive: two axes on one serial line would fight over it (an embedded
        # simulated drive is made anew for every connection, so sim:// URLs may repeat)
        taken = next(
            (a for a in self._axes if port and a.port_url == port and not port.startswith("sim://")), None
        )
        if taken is not None:
            raise MachineError(f"axis '{name}': port {port} is already axis '{taken.name}''s")
        state = CommissioningState(
            actuator_code, driver_model=driver_model, load_inertia_kgm2=load_inertia_kgm2
        )
        axis = MachineAxis(
            name=name,
            port_url=port_url.strip(),
            notes=notes,
            serial_number=serial_number.strip(),
            session_file=Path(session_file) if session_file else None,
            state=state,
        )
        self._axes.append(axis)
        return axis

    def axis(self, name: str) -> MachineAxis:
        for axis in self._axes:
            if axis.name == name.strip():
                return axis
        known = ", ".join(a.name for a in self._axes) or "none"
        raise MachineError(f"'{self.name}' has no axis '{name}' (axes: {known})")

    def remove_axis(self, name: str) -> None:
        self._axes.remove(self.axis(name))

    # -- the file -------------------------------------------------------------------------------------
    def to_json(self) -> dict[str, Any]:
        return {
            "format": FORMAT,
            "name": self.name,
            "site": self.site,
            "notes": self.notes,
            "axes": [a.to_json() for a in self._axes],
        }

    def save(self, path: str | Path) -> Path:
        """Writes the project file atomically (a crash leaves the old file whole)."""
        path = Path(path)
        if not os.path.lexists(path.parent):
            path.parent.mkdir(parents=True, exist_ok=True)
        # fileio: temporary file, fsync, rename; a device or a path under a file is refused
        fileio.write_text(path, json.dumps(self.to_json(), indent=2, ensure_ascii=False) + "\n")
        return path

    @classmethod
    def from_json(cls, data: Any, where: str = "machine file") -> MachineProject:
        """A machine from a machine file's data, every field checked against its shape first
        (MACHINE_FIELDS, AXIS_FIELDS): MachineError names the file and the field."""
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise MachineError(f"{where}: not an {FORMAT} machine file")
        _known(data, ("format", *MACHINE_FIELDS, "axes"), where)
        if "name" not in data:
            raise MachineError(f"{where}: no name")
        texts = {k: _field_text(data.get(k, ""), f"{where}: field {k}") for k in MACHINE_FIELDS}
        axes = data.get("axes", [])
        if not isinstance(axes, list):
            raise MachineError(f"{where}: field axes: must be a list of axes, got {kind_of(axes)}")
        try:
            project = cls(texts["name"], texts["site"], texts["notes"])
        except ValueError as exc:
            raise MachineError(f"{where}: {_reason(exc)}") from None
        for number, axis in enumerate(axes, start=1):
            at = f"{where}: axis {number}"
            if not isinstance(axis, dict):
                raise MachineError(f"{at}: must be a table of fields, got {kind_of(axis)}")
            _known(axis, (*AXIS_FIELDS, "load_inertia_kgm2"), at)
            if "name" not in axis:
                raise MachineError(f"{at}: no name")
            fields = {k: _field_text(axis.get(k, ""), f"{at}: field {k}") for k in AXIS_FIELDS}
            inertia = axis.get("load_inertia_kgm2", 0.0)
            if inertia is None:
                inertia = 0.0
            if isinstance(inertia, bool) or not isinstance(inertia, int | float):
                raise MachineError(f"{at}: field load_inertia_kgm2: must be a number of kg m^2, "
                                   f"got {kind_of(inertia)}")
            if not plausible.LOAD_INERTIA_KGM2.contains(float(inertia)):
                raise MachineError(f"{at}: field load_inertia_kgm2: {inertia:g} is outside "
                                   f"{plausible.LOAD_INERTIA_KGM2.allowed()}")
            try:
                project.add_axis(
                    fields["name"],
                    fields["actuator_code"],
                    fields["driver_model"],
                    fields["port_url"],
                    float(inertia),
                    fields["notes"],
                    fields["serial_number"],
                    fields["session_file"] or None,
                )
            except (KeyError, TypeError, ValueError) as exc:
                raise MachineError(f"{at}: {_reason(exc)}") from None
        return project

    @classmethod
    def load(cls, path: str | Path) -> MachineProject:
        """Reads a project file; MachineError names the file and what is wrong."""
        path = Path(path)
        try:
            text = fileio.read_text(path)  # a regular file, bounded
        except fileio.FileProblem as exc:
            if exc.reason == "no such file or directory":
                raise MachineError(f"{path}: no such machine file") from None
            raise MachineError(str(exc)) from None
        try:
            data = fileio.parse_json(text)  # bounded in depth, finite numbers
        except ValueError as exc:
            raise MachineError(f"{path}: not a readable machine file: {exc}") from None
        return cls.from_json(data, str(path))

    # -- the register ---------------------------------------------------------------------------------
    def save_to(self, register: Any, who: str = "") -> None:
        """Puts the machine and its axes into the register (added when missing; an axis's
        actuator, driver, port, load inertia, notes and serial number brought up to date, each
        change going into the axis's history)."""
        register.ensure_machine(self.name, self.site)
        for axis in self._axes:
            fields = {
                "actuator_code": axis.actuator_code,
                "driver_model": axis.driver_model,
                "port_url": axis.port_url,
                "load_inertia_kgm2": axis.load_inertia_kgm2,
                "notes": axis.notes,
                "serial_number": axis.serial_number,
            }
            try:
                row = register.axis(f"{self.name}/{axis.name}")
            except ValueError:
                register.add_axis(self.name, axis.name, who=who, **fields)
                continue
            if row.load_inertia_kgm2 is None and not axis.load_inertia_kgm2:
                del fields["load_inertia_kgm2"]  # not declared there, nothing declared here
            register.update_axis(row, who=who, **fields)

    @classmethod
    def from_register(cls, register: Any, name: str) -> MachineProject:
        """The machine ``name`` as the register holds it (RegisterError when it is not there)."""
        machine = register.machine(name)
        project = cls(machine.name, machine.site, machine.notes)
        for row in register.axes(machine.name):
            project.add_axis(
                row.name,
                row.actuator_code,
                row.driver_model,
                row.port_url,
                row.load_inertia_kgm2 or 0.0,
                row.notes,
                row.serial_number,
            )
        return project


def _reason(exc: BaseException) -> str:
    if isinstance(exc, KeyError):
        return f"no {exc.args[0]}"
    return str(exc)


def _field_text(value: Any, where: str) -> str:
    if not isinstance(value, str):
        raise MachineError(f"{where}: must be text, got {kind_of(value)}")
    if len(value) > MAX_FIELD_TEXT:
        raise MachineError(f"{where}: is {len(value)} characters long; at most {MAX_FIELD_TEXT}")
    return value


def _known(table: dict[str, Any], allowed: tuple[str, ...], where: str) -> None:
    unknown = sorted(str(k) for k in table if k not in allowed)
    if unknown:
        raise MachineError(f"{where}: field {quoted(unknown[0], 40)}: unknown; allowed: {', '.join(allowed)}")
