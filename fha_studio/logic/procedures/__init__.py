"""Guided procedures of the FHA-C manual as data, walked by an engine, recorded in a session.

- :mod:`.definitions`: procedures from ``resources/procedures/*.toml``, filled in per actuator.
- :mod:`.context`: what a procedure may refer to for one actuator (from the catalogue).
- :mod:`.engine`: :class:`ProcedureRun`, walking the steps and recording each check.
- :mod:`.session`: the ``fha-session/1`` file (pause, resume after a restart, the report's source).
- :mod:`.sensor_dogs`: the option-L sensor-dog wizard (4-7-2, 4-7-3).
- :mod:`.live`: checks against a drive through the drive client.
- :mod:`.report`: the commissioning report (model and HTML).
"""

from fha_studio.logic.procedures.definitions import (
    Procedure,
    ProcedureError,
    Step,
    load_all,
    load_procedure,
)
from fha_studio.logic.procedures.engine import Observation, ProcedureRun, StepInputError
from fha_studio.logic.procedures.session import CheckRecord, ProcedureSession, RunState, SessionError

__all__ = [
    "CheckRecord",
    "Observation",
    "Procedure",
    "ProcedureError",
    "ProcedureRun",
    "ProcedureSession",
    "RunState",
    "SessionError",
    "Step",
    "StepInputError",
    "load_all",
    "load_procedure",
]
