"""What was done to a training drive: every CN3 command and panel action with the drive's state
at that moment, so a trainee's session can be scored afterwards (fha_studio.logic.training).

The journal belongs to a training registration, not to one drive: a trainee who reconnects gets a
new :class:`SimDrive` that writes on in the same journal.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from enum import StrEnum

from fha_studio import clock
from fha_studio.hardware.parameters import Mode
from fha_studio.hardware.protocol import Command, Status


class PanelAction(StrEnum):
    """What is done to the drive from outside CN3 (its panel, or ``fha-studio sim --panel``)."""

    HAND_TURN = "HAND_TURN"  # the output turned by hand; value: degrees, CW positive
    CN2_MOVE = "CN2_MOVE"  # the controller's pulse train on CN2; value: degrees, FWD positive


@dataclass(frozen=True)
class JournalEntry:
    """One command or panel action. ``at_s``: wall-clock time (UNIX seconds); the state fields are
    the drive's just before the command, ``alarm_after`` just after it."""

    at_s: float
    command: Command | PanelAction  # the CN3 command (JOG, PWR, ...) or the panel action
    value: int  # the command's value as sent; a panel action's in whole degrees
    terminal: Status | None  # q, s, x (None when the reply comes later: OWW)
    item: tuple[Mode, int] | None  # the item selected for PRD / PWR: (mode, number)
    servo_on: bool
    brake_holding: bool
    blocked_fwd: bool  # a FWD inhibit input or the CW-end limit switch is active
    blocked_rev: bool
    alarm_before: int
    alarm_after: int


class Journal:
    """A thread-safe list of :class:`JournalEntry` (the drive's thread appends, the GUI reads)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._entries: list[JournalEntry] = []
        self.started_s = clock.now_s()

    def append(self, entry: JournalEntry) -> None:
        with self._lock:
            self._entries.append(entry)

    def entries(self) -> list[JournalEntry]:
        """A copy of the entries, oldest first."""
        with self._lock:
            return list(self._entries)


__all__ = ["Journal", "JournalEntry", "PanelAction"]
