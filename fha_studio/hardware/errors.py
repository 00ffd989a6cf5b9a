"""Errors of the drive link (re-exported by fha_studio.hardware.client).

Every error the client raises is a ``LinkError`` (one ``except`` for a caller that only reports).
Two families below it say very different things:

- ``LinkFailure``: the link did not work: ``LinkTimeout`` (no usable reply after the retries;
  ``LinkSilent`` when nothing at all arrived, ``LinkGarbled`` when bytes arrived but never a
  complete reply), ``LinkLost`` (the port is gone, or too many failures in a row).
- ``ReadAborted``: the caller asked a long read-out to give up (between exchanges); neither the
  link nor the drive failed.
- ``DriveRefused``: the link worked and the drive said no: ``ServoOnRefused`` (``s``: the servo
  is on, not now), ``CommandRejected`` (``x``), ``CommandNotSupported`` (the drive lacks the
  extension; nothing was sent). These are never retried and never count against the link.
"""

from __future__ import annotations


class LinkError(Exception):
    """Base of every error of the drive link."""


class LinkFailure(LinkError):
    """The link did not carry a usable exchange."""


class LinkTimeout(LinkFailure):
    """No complete, well-formed reply within the timeout, after all retries."""


class LinkSilent(LinkTimeout):
    """Not a byte arrived during the whole exchange: the cable, the port or the drive's power."""


class LinkGarbled(LinkTimeout):
    """Bytes arrived, but never a complete reply: a wrong baud rate, or another device on the port."""


class LinkLost(LinkFailure):
    """The port is gone (unplugged, peer closed) or failed too many times in a row.

    ``port`` names it. The client stays unusable until it is opened again.
    """

    def __init__(self, message: str, port: str = ""):
        super().__init__(message)
        self.port = port


class ReadAborted(LinkError):
    """A long read-out gave up between exchanges because the caller asked it to (``should_abort``).

    ``done`` and ``total`` count what was read and what there was (samples for a trace).
    """

    def __init__(self, message: str, done: int = 0, total: int = 0):
        super().__init__(message)
        self.done = done
        self.total = total


class DriveRefused(LinkError):
    """The drive answered and refused: the link itself is fine."""


class ServoOnRefused(DriveRefused):
    """The drive answered ``s``: the servo is on, the command was not processed (not a link fault)."""


class CommandRejected(DriveRefused):
    """The drive answered ``x``: unknown, malformed, not allowed now, or out of range."""


class CommandNotSupported(DriveRefused):
    """The drive does not have this extension command (from its CAP reply); nothing was sent."""
