"""Bringing files made before the register (or beside it) into it.

- :func:`record_session`: a procedure session (``fha-session/1``): every check answered, where
  each procedure stands, the parameter values it holds. Recording the same session again adds only
  what is new, so the GUI calls it after every answer and an import of the file later changes
  nothing.
- :func:`import_session_file` and :func:`import_parameter_file` read the files.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fha_studio import fileio
from fha_studio.hardware.parameters import driver_family
from fha_studio.logic.register.store import Axis, Register, RegisterError, utc_stamp


@dataclass(frozen=True)
class ImportResult:
    """What an import added to which axis, and what it could not take (one line each)."""

    axis: Axis
    checks_added: int = 0
    procedures: int = 0
    snapshot: int | None = None
    not_taken: tuple[str, ...] = field(default_factory=tuple)


def _procedures_for(actuator_code: str) -> list[Any]:
    from fha_studio.catalog import ModelCodeError
    from fha_studio.logic.procedures import ProcedureError, load_all
    from fha_studio.logic.procedures.context import build_context

    try:
        return load_all(build_context(actuator_code))
    except (ModelCodeError, ProcedureError, KeyError, ValueError):
        return []


def record_session(register: Register, axis: Axis | str | int, session: Any) -> ImportResult:
    """Records a procedure session of ``axis``: its check answers (new ones only), the status of
    every procedure that applies to the actuator, and its parameter values as a snapshot (once)."""
    with register.batch():  # a session is recorded whole or not at all
        return _record_session(register, register.axis(axis), session)


def _record_session(register: Register, axis: Axis, session: Any) -> ImportResult:
    source = str(session.path or "")
    records = [r for state in session.runs.values() for r in state.records]
    added = register.record_checks(axis, records, session_file=source)
    procedures = _procedures_for(session.actuator_code)
    count = 0
    if procedures:
        for procedure in procedures:
            state = session.runs.get(procedure.id)
            status = (state.status if state else "not_started") if procedure.applies else "not applicable"
            register.record_procedure_status(
                axis, procedure.id, procedure.title, status, procedure.section, session_file=source
            )
            count += 1
    else:  # an actuator the catalogue does not know: the procedures the session walked
        for procedure_id, state in session.runs.items():
            register.record_procedure_status(
                axis, procedure_id, procedure_id, state.status, session_file=source
            )
            count += 1
    snapshot, not_taken = _session_parameters(register, axis, session)
    return ImportResult(axis, added, count, snapshot, tuple(not_taken))


def _session_parameters(register: Register, axis: Axis, session: Any) -> tuple[int | None, list[str]]:
    source = str(session.path or "")
    params = session.parameters or {}
    values = params.get("values") or {}
    if not values:
        return None, []
    from fha_studio.hardware.parameters import load_parameter_model

    driver_model = (session.driver or {}).get("model", "")
    model = load_parameter_model(driver_family(driver_model))
    rows, not_taken = [], []
    for key, wire in values.items():
        try:
            item = model.by_key(key)
        except KeyError as exc:
            not_taken.append(f"parameter {key}: {exc.args[0]}")
            continue
        try:
            item.check(wire)  # 77 for the rotary direction, 12 for an item of 0 ... 10: refused
        except ValueError as exc:
            raise RegisterError(f"{source or 'session'}: field parameters.values.{key}: {exc}") from None
        rows.append((item.mode.value, item.number, item.key, int(wire)))
    if not rows:
        return None, not_taken
    at = params.get("read_utc") or session.created_utc
    file = str(params.get("file", "") or session.path or "")
    try:
        stamp = utc_stamp(at)
    except RegisterError as exc:  # past 9999 UTC, not a time: say which field of which file
        field = "parameters.read_utc" if params.get("read_utc") else "created_utc"
        raise RegisterError(f"{source or 'session'}: field {field}: {exc}") from None
    if register.has_snapshot(axis, stamp, file):
        return None, not_taken
    number = register.record_snapshot(
        axis,
        rows,
        "file" if params.get("file") else "link",
        who=session.operator,
        at_utc=at,
        driver_model=driver_model,
        file=file,
        note="from the procedure session",
    )
    return number, not_taken


def import_session_file(
    register: Register, path: str | Path, machine: str, axis: str | None = None
) -> ImportResult:
    """Imports a session file into ``machine`` (added when missing) as the axis ``axis`` (default:
    the axis name the session holds; added when missing, with the session's actuator and driver).
    Raises RegisterError for a file that is not a session file or an axis of another actuator."""
    from fha_studio.logic.procedures.session import ProcedureSession, SessionError

    try:
        session = ProcedureSession.load(path)
    except SessionError as exc:
        raise RegisterError(str(exc)) from None
    name = (axis or session.axis or "axis 1").strip()
    driver = (session.driver or {}).get("model", "")
    with register.batch():  # all of it or nothing: no machine or axis left behind by a refusal
        target = register.ensure_axis(
            machine, name, actuator_code=session.actuator_code, driver_model=driver, who=session.operator
        )
        if target.actuator_code and target.actuator_code != session.actuator_code.strip().upper():
            raise RegisterError(
                f"{path}: a session for {session.actuator_code}, but axis {target.ref} has "
                f"{target.actuator_code}"
            )
        return record_session(register, target, session)


def import_parameter_file(
    register: Register, path: str | Path, machine: str, axis: str, who: str = ""
) -> ImportResult:
    """Imports a parameter file (``fha-parameters/1``) as a snapshot of ``machine/axis`` (added
    when missing), at the time the file was saved. Items the driver does not have are listed in
    ``not_taken``; a file that is not a parameter file raises RegisterError naming the line."""
    from fha_studio.hardware.parameters import load_parameter_model
    from fha_studio.logic.paramfile import ParameterFileError, read_parameter_file

    path = Path(path)
    try:
        text = fileio.read_text(path)  # a regular file, bounded
    except fileio.FileProblem as exc:
        raise RegisterError(str(exc)) from None
    # the file's driver decides the model; a file without one is read as HA-655
    first = _peek_driver(text)
    model = load_parameter_model(driver_family(first))
    try:
        loaded = read_parameter_file(text, model, name=str(path))
    except ParameterFileError as exc:
        raise RegisterError(str(exc)) from None
    if loaded.actuator:
        from fha_studio.catalog import ModelCodeError, parse_model_code

        try:
            parse_model_code(loaded.actuator)
        except ModelCodeError as exc:
            raise RegisterError(f"{path}: actuator: {exc}") from None
    with register.batch():  # all of it or nothing: no machine or axis left behind by a refusal
        target = register.ensure_axis(
            machine, axis, actuator_code=loaded.actuator, driver_model=loaded.driver_model, who=who
        )
        rows = [
            (mode, number, model.item(mode, number).key, wire)
            for (mode, number), wire in loaded.values.items()
        ]
        if not rows:
            raise RegisterError(f"{path}: no value in it fits {model.driver}")
        at = loaded.saved or None
        file = str(path.resolve())
        if register.has_snapshot(target, utc_stamp(at), file):
            return ImportResult(target, not_taken=tuple(loaded.not_mapped))
        number = register.record_snapshot(
            target,
            rows,
            "file",
            who=who,
            at_utc=at,
            driver_model=loaded.driver_model,
            file=file,
            note="imported parameter file",
        )
        return ImportResult(target, snapshot=number, not_taken=tuple(loaded.not_mapped))


def _peek_driver(text: str) -> str:
    import tomllib

    try:
        data = fileio.parse_toml(text)
    except tomllib.TOMLDecodeError:
        return ""  # read_parameter_file says where it is broken
    return str(data.get("driver_model") or data.get("driver") or "")
