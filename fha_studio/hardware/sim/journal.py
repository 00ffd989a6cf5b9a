"""What was done to a training drive: every CN3 command and panel action with the drive's state
at that moment, so a trainee's session can be scored afterwards (fha_studio.logic.training).

The journal belongs to a training registration, not to one drive: a trainee who reconnects gets a
new :class:`SimDrive` that writes on in the same journal.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

from fha_studio import clock


@dataclass(frozen=True)
class JournalEntry:
    """One command or panel action. ``at_s``: wall-clock time (UNIX seconds); the state fields are
    the drive's just before the command, ``alarm_after`` just after it."""

    at_s: float
    command: str  # the CN3 command's name (JOG, PWR, ...), or a panel action (HAND_TURN, CN2_MOVE)
    value: int
    terminal: str  # q, s, x ("" when the reply comes later)
    item: tuple[str, int] | None  # the item selected for PRD / PWR: (mode, number)
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


__all__ = ["Journal", "JournalEntry"]
