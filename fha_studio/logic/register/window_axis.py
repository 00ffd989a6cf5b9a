"""Under which machine and axis the single-axis window records into the register (no Qt).

The machine window's axes are named by the machine project. The single-axis window (``fha-studio``,
``fha-studio --url ...``) records too: under the machine and axis the technician names (the
window's *Register* line, ``--machine``/``--axis``), or else under a default one:

- the machine is this computer's bench, ``"<computer> bench"``, so two laptops' benches stay two
  machines when their registers meet;
- the axis is named after the actuator's model code when it is declared (``FHA-25C-50-US250``;
  an embedded or other simulated drive's with ``(simulated)``), else after the connection
  (``drive at ttyUSB0``, ``simulated drive``).

The default axis is taken when the first fact of a connection is recorded and kept for that
connection (:class:`DefaultAxis`): an actuator declared after the parameters were read does not
split the axis's history in two.
"""

from __future__ import annotations

import socket
from dataclasses import dataclass
from urllib.parse import urlsplit

from fha_studio import names

#: The axis when neither an actuator nor a connection names one.
UNNAMED_AXIS = "unnamed axis"
#: The computer when it has no name Python can find.
UNNAMED_COMPUTER = "this computer"


def computer_name(hostname: str | None = None) -> str:
    """This computer's name without its domain (``laptop-07`` of ``laptop-07.plant.example``),
    as text a register takes; :data:`UNNAMED_COMPUTER` when there is none."""
    if hostname is None:
        try:
            hostname = socket.gethostname()
        except OSError:
            hostname = ""
    name = hostname.strip().split(".", 1)[0].strip()
    if not name or not names.printable(name):
        return UNNAMED_COMPUTER
    return name[: names.NAME_MAX - len(" bench")]


def default_machine_name(computer: str | None = None) -> str:
    """The machine a window records under when nobody named one: this computer's bench."""
    return f"{computer_name(computer)} bench"


def port_name(url: str) -> str:
    """The connection as a person names it: ``ttyUSB0`` (of ``/dev/ttyUSB0`` or a by-id path),
    ``COM3``, ``10.0.0.5:4001`` (of ``socket://10.0.0.5:4001``); "" for none."""
    text = url.strip()
    if not text:
        return ""
    if "://" in text:
        parts = urlsplit(text)
        if parts.scheme == "sim":
            return "simulated drive"
        where = parts.netloc or parts.path.strip("/") or parts.scheme
    else:
        where = text.replace("\\", "/").rstrip("/").rsplit("/", 1)[-1]
    where = "".join(c if names.printable(c) else "?" for c in where).replace("/", "-")
    return where[:40]


def default_axis_name(actuator_code: str, url: str = "", simulated: bool = False) -> str:
    """The axis a window records under when nobody named one: the actuator's model code when it
    is declared (``(simulated)`` after it on a simulated drive), else the connection's name."""
    code = actuator_code.strip().upper()
    if code:
        return f"{code} (simulated)" if simulated else code
    where = port_name(url)
    if where == "simulated drive":
        return where
    if where:
        return f"{'simulated drive' if simulated else 'drive'} at {where}"
    return "simulated drive" if simulated else UNNAMED_AXIS


@dataclass(frozen=True)
class WindowAxis:
    """The machine and axis a window records under, and whether a person named them."""

    machine: str
    axis: str
    machine_named: bool = False
    axis_named: bool = False

    @property
    def ref(self) -> str:
        """``MACHINE/AXIS``, as the register names an axis."""
        return f"{self.machine}/{self.axis}"

    @property
    def named(self) -> bool:
        return self.machine_named and self.axis_named


def check_names(machine: str, axis: str) -> tuple[str, str]:
    """The names a person gave, stripped; ``names.NameProblem`` (a ValueError, one line) for a
    name the register would refuse. An empty one stays empty (the default is taken)."""
    machine = names.check_name(machine, "machine name", empty_ok=True)
    axis = names.check_name(axis, "axis name", empty_ok=True)
    if "/" in machine:
        raise names.NameProblem(
            f"machine name {names.quoted(machine)}: '/' separates machine and axis, use another sign"
        )
    return machine, axis


class DefaultAxis:
    """The default axis of one window, kept from the first fact of a connection to its end.

    ``current(...)`` says what the default would be now (for the window to show); ``take(...)``
    fixes it for the connection (the first fact is being recorded); ``forget()`` lets the next
    fact choose again (another drive was connected, or a person went back to the default)."""

    def __init__(self) -> None:
        self._taken: str | None = None
        self._for_url: str | None = None

    def current(self, actuator_code: str, url: str, simulated: bool) -> str:
        if self._taken is not None and url == self._for_url:
            return self._taken
        return default_axis_name(actuator_code, url, simulated)

    def take(self, actuator_code: str, url: str, simulated: bool) -> str:
        name = self.current(actuator_code, url, simulated)
        self._taken, self._for_url = name, url
        return name

    def forget(self) -> None:
        self._taken = self._for_url = None
