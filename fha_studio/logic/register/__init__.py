"""The register: every commissioning fact of every axis, in one SQLite file (no Qt).

- :mod:`.store`: :class:`Register` (machines, axes, snapshots, writes, checks, alarms, reports,
  recordings, model checks; history, diff, find, open items, export), in layers: :mod:`.connection`,
  :mod:`.axes`, :mod:`.facts`, :mod:`.queries`, :mod:`.history`; :mod:`.records` what they return.
- :mod:`.schema`: the tables and their migrations (``PRAGMA user_version``).
- :mod:`.importers`: procedure session files and parameter files into the register.
"""

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
