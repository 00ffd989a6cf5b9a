"""What the simulated drive answers one command: :class:`SimReply`, or :class:`SimRefused` raised
by whatever refuses it (the responder turns it into a ``s`` or ``x`` reply)."""

from __future__ import annotations

from dataclasses import dataclass

from fha_studio.hardware.protocol import Reply, Status


class SimRefused(Exception):
    """The command is refused: ``terminal`` is :attr:`Status.SERVO_ON` (``s``) or
    :attr:`Status.REJECTED` (``x``: not allowed now, bad value)."""

    def __init__(self, terminal: Status, reason: str):
        super().__init__(reason)
        self.terminal = terminal
        self.reason = reason


def rejected(reason: str) -> SimRefused:
    """A refusal answered ``x`` (unknown, not allowed now, out of range)."""
    return SimRefused(Status.REJECTED, reason)


def servo_is_on(reason: str) -> SimRefused:
    """A refusal answered ``s``: the servo is on, the command was not processed."""
    return SimRefused(Status.SERVO_ON, reason)


@dataclass(frozen=True)
class SimReply:
    """What the drive answers one command: data lines and the terminal status (``q``, ``s``, ``x``).

    ``reason`` says why a command was refused (for logs and messages; not on the wire). The
    codec's :class:`fha_studio.hardware.protocol.Reply` is this on the wire (:meth:`on_the_wire`).
    """

    terminal: Status = Status.DONE
    lines: tuple[str, ...] = ()
    reason: str = ""

    def on_the_wire(self) -> Reply:
        return Reply(self.lines, self.terminal)
