"""DocumentedDrive: a drive that answers only what the public HA-655 manual documents (p.21).

``DGR`` answers the absolute position (multi-turn x 8192 + single-turn count), ``OWW`` clears the
multi-turn data and acknowledges ``oww_s`` later (a repeat before the acknowledgement is ``x``),
an incremental encoder answers ``x`` to both, every other command (known or not) is ``x``, and
while the servo is on the drive processes nothing over CN3: ``s`` to everything. The facts are
in ../shared/reference/ha655-facts.md, section 7.

The simulated drive's ``documented`` profile (``sim://...?profile=documented``) is the product's
drive of the manual, with an axis behind it; this is the tests' one, with nothing behind it: a
handler for ``ScriptedDrive`` (``ScriptedDrive(end, DocumentedDrive())``) and the far end of
tests/cli/line_server.py's ``documented`` line. Switch ``servo_on``, ``position`` or
``incremental`` on the object while a test runs, as CN2 and the axis would.
"""

from __future__ import annotations

import time

from fha_studio.hardware import protocol as p
from tests.support.scripted import Answer

#: The position a drive of the manual reports unless told another (motor encoder counts).
POSITION = 123456


class DocumentedDrive:
    def __init__(self, position: int = POSITION, *, servo_on: bool = False, incremental: bool = False,
                 oww_s: float = 0.0):
        self.position = position
        self.servo_on = servo_on
        self.incremental = incremental
        self.oww_s = oww_s
        self._oww_due: float | None = None

    def answer(self, request: p.Request | p.UnknownRequest, now: float) -> p.Reply | None:
        """The reply to ``request`` at ``now`` (seconds, any clock); None when it comes later
        (OWW: see :meth:`due`)."""
        command = request.command if isinstance(request, p.Request) else None
        if self.servo_on:
            return p.Reply((), p.Status.SERVO_ON)
        if command is p.Command.DGR and not self.incremental:
            return p.Reply((str(self.position),))
        if command is p.Command.OWW and not self.incremental and self._oww_due is None:
            self._oww_due = now + self.oww_s
            return None
        return p.Reply((), p.Status.REJECTED)

    def due(self, now: float) -> list[p.Reply]:
        """The replies that have come due by ``now``: OWW's acknowledgement, the multi-turn data
        cleared."""
        if self._oww_due is None or now < self._oww_due:
            return []
        self._oww_due = None
        self.position %= p.ABSOLUTE_COUNTS_PER_TURN
        return [p.Reply()]

    def __call__(self, request: p.Request | p.UnknownRequest) -> Answer:
        """As a ``ScriptedDrive`` handler: OWW's acknowledgement after a pause of ``oww_s``."""
        now = time.monotonic()
        reply = self.answer(request, now)
        if reply is not None:
            return reply
        return [self.oww_s, *self.due(now + self.oww_s)]
