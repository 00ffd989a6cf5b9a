"""Where the facts an axis's recorder decides go: :class:`RegisterWriter`.

A register file is written on the GUI thread (:class:`DirectWriter`: a local file takes a fact in
milliseconds, and the machine window's questions read it at once). A register on a server is
written by a worker in a thread of its own (``gui/register_worker.py``), so that a slow or
vanished server never holds the window.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path

from PySide6.QtCore import QObject, Signal

from fha_studio.logic.register import Register, RegisterError
from fha_studio.logic.register.facts_from_session import AxisFact, Fact, record_fact

log = logging.getLogger(__name__)


class RegisterWriter(QObject):
    """Takes an axis's facts for the register; says each one that was not recorded."""

    #: (axis, what, why): a fact of the axis (``MACHINE/AXIS``) the register did not take, in
    #: words ("parameter write", one line)
    sigNotRecorded = Signal(str, str, str)

    @property
    def location(self) -> Path | str:
        """The register: its file, or the server's URL."""
        raise NotImplementedError

    def record(self, axis: str, facts: Sequence[Fact]) -> None:
        """Records ``facts`` of ``axis`` (``MACHINE/AXIS``) in order. An :class:`AxisFact` first
        adds the axis when it is not there; when it cannot be added, the facts after it are not
        recorded (one line says so)."""
        raise NotImplementedError

    def shutdown(self) -> None:
        """Records nothing more (idempotent)."""


class HeldRegisterFile:
    """An open register file used on the GUI thread until ``shutdown`` lets it go (the window
    closes it): what a local writer and a local asker share. Put before the QObject base."""

    def __init__(self, register: Register, parent: QObject | None = None):
        super().__init__(parent)  # type: ignore[call-arg]  # the QObject base after this one
        self.register: Register | None = register
        self._location = register.location

    @property
    def location(self) -> Path | str:
        return self._location

    def shutdown(self) -> None:
        self.register = None


class DirectWriter(HeldRegisterFile, RegisterWriter):
    """Writes into an open register on the GUI thread (a file)."""

    def record(self, axis: str, facts: Sequence[Fact]) -> None:
        for fact in facts:
            if self.register is None:
                return
            problem = write_fact(self.register, axis, fact)
            if problem:
                self.sigNotRecorded.emit(axis, fact.what, problem)
                if isinstance(fact, AxisFact):
                    return


def write_fact(register: Register, axis: str, fact: Fact) -> str:
    """Writes one fact; "" when it was recorded, else why not (one line; never raised: the
    commissioning goes on)."""
    try:
        record_fact(register, axis, fact)
        return ""
    except (RegisterError, OSError, ValueError) as exc:
        log.warning("register: %s of %s not recorded: %s", fact.what, axis, exc)
        return str(exc)
    except Exception as exc:  # sqlite3 errors (a locked or damaged file): said, not raised
        log.exception("register: %s of %s not recorded", fact.what, axis)
        return str(exc) or type(exc).__name__


def facts_text(count: int) -> str:
    """``1 fact``, ``3 facts``."""
    return f"{count} fact{'' if count == 1 else 's'}"
