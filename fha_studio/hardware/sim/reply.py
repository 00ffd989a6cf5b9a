"""What the simulated drive answers one command: :class:`SimReply`, or :class:`SimRefused` raised
by whatever refuses it (the command table turns it into a ``s`` or ``x`` reply)."""

from __future__ import annotations

from dataclasses import dataclass


class SimRefused(Exception):
    """The command is refused: ``terminal`` is ``"s"`` (servo on) or ``"x"`` (not allowed / bad)."""

    def __init__(self, terminal: str, reason: str):
        super().__init__(reason)
        self.terminal = terminal
        self.reason = reason


def rejected(reason: str) -> SimRefused:
    """A refusal answered ``x`` (unknown, not allowed now, out of range)."""
    return SimRefused("x", reason)


@dataclass(frozen=True)
class SimReply:
    """What the drive answers one command: data lines and the terminal ``q``, ``s`` or ``x``.

    ``reason`` says why a command was refused (for logs and messages; not on the wire). The
    codec's :class:`fha_studio.hardware.protocol.Reply` is this on the wire.
    """

    terminal: str = "q"
    lines: tuple[str, ...] = ()
    reason: str = ""
