"""The register: every commissioning fact of every axis, in one SQLite file (no Qt).

- :mod:`.store`: :class:`Register` (machines, axes, snapshots, writes, checks, alarms, reports,
  recordings, model checks; history, diff, find, open items, export), in layers: :mod:`.connection`,
  :mod:`.axes`, :mod:`.facts`, :mod:`.queries`, :mod:`.history`; :mod:`.records` what they return.
- :mod:`.schema`: the tables and their migrations (``PRAGMA user_version``).
- :mod:`.importers`: procedure session files and parameter files into the register.

The names below are imported when first asked for (PEP 562): a module of the package that needs
none of them (``words``, for every command's help) does not load the register, its stores and
the signing library with it.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fha_studio.logic.register.importers import (
        ImportResult,
        import_parameter_file,
        import_session_file,
        record_session,
    )
    from fha_studio.logic.register.schema import SCHEMA_VERSION
    from fha_studio.logic.register.store import (
        ENV_REGISTER,
        Axis,
        Difference,
        Event,
        EventKind,
        Found,
        Machine,
        OpenItem,
        ParameterSet,
        ParameterValue,
        Register,
        RegisterError,
        default_register_path,
        file_sha256,
        register_location,
        utc_stamp,
    )

__all__ = [
    "ENV_REGISTER",
    "SCHEMA_VERSION",
    "Axis",
    "Difference",
    "Event",
    "EventKind",
    "Found",
    "ImportResult",
    "Machine",
    "OpenItem",
    "ParameterSet",
    "ParameterValue",
    "Register",
    "RegisterError",
    "default_register_path",
    "file_sha256",
    "import_parameter_file",
    "import_session_file",
    "record_session",
    "register_location",
    "utc_stamp",
]
#: The module each name comes from (the others: ``store``).
_FROM = {
    **dict.fromkeys(("ImportResult", "import_parameter_file", "import_session_file", "record_session"),
                    "importers"),
    "SCHEMA_VERSION": "schema",
}


def __getattr__(name: str) -> Any:
    if name not in __all__:  # a submodule not imported yet: the import system imports it
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_FROM.get(name, 'store')}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
