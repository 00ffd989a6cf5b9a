"""How each class of the malformed-input corpus (tests/corpus/) is read: reader name -> callable
that reads one file and raises the reader's one-line error."""

from __future__ import annotations

from pathlib import Path


def read_recording(path: Path) -> None:
    from fha_studio.recording import read_recording

    read_recording(path)


def read_parameters(path: Path) -> None:
    from fha_studio.hardware.parameters import load_parameter_model
    from fha_studio.logic.paramfile import load_parameter_file

    load_parameter_file(path, load_parameter_model("HA-655"))


def read_session(path: Path) -> None:
    from fha_studio.logic.procedures import ProcedureSession

    ProcedureSession.load(path)


def read_eeprom(path: Path) -> None:
    from fha_studio.hardware.sim.eeprom import EepromFile

    EepromFile(path).load()


def read_model(path: Path) -> None:
    from fha_studio.physics import AxisModel

    AxisModel.load(path)


def read_machine(path: Path) -> None:
    from fha_studio.logic.machine import MachineProject

    MachineProject.load(path)


def read_register(path: Path) -> None:
    from fha_studio.logic.register import Register

    with Register(path, create=False, read_only=True) as register:  # a question: the file stays
        register.axes()


def read_capture(path: Path) -> None:
    from fha_studio.hardware.bench.readers import read_capture

    read_capture(path)


def read_import(path: Path) -> None:
    """Imports the file into a fresh register (session or parameter file, as `register import`)."""
    import tempfile

    from fha_studio.logic.register import Register, import_parameter_file, import_session_file

    with tempfile.TemporaryDirectory() as folder, Register(Path(folder) / "r.sqlite") as register:
        if path.suffix == ".json":
            import_session_file(register, path, "Press 7", "feed")
        else:
            import_parameter_file(register, path, "Press 7", "feed")


def read_scenario(path: Path) -> None:
    from fha_studio.logic.training.scenario import load_scenario

    load_scenario(path)


READERS = {
    "capture": read_capture,
    "recording": read_recording,
    "parameters": read_parameters,
    "session": read_session,
    "eeprom": read_eeprom,
    "model": read_model,
    "machine": read_machine,
    "register": read_register,
    "import": read_import,
    "scenario": read_scenario,
}
