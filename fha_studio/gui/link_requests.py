"""The messages to and from the link thread: one frozen dataclass per request, a typed reply.

As PyMoDAQ's hardware worker takes one small command object through one queued signal, the link
worker takes a ``LinkRequest``; each request says what its reply carries (``LinkRequest[R]``: a
``Servo`` is answered with the state asked for, a ``ReadParameters`` with a ``ParameterReadout``).
The reply goes back to whoever sent the request (``LinkController.send(request, on_reply)``);
the controller also shows every reply to its one observer (the window's message area).

Qt-free: the requests are plain data; the worker (``link.py``) runs them.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, Generic, TypeVar, cast

from fha_studio.hardware.api import AlarmRecord, DriveApi, DriveRefused, LinkError
from fha_studio.hardware.protocol import BAUDRATE
from fha_studio.logic.drive_session import ParameterKey, ParameterReadout, ParameterWrite, WriteEntry

R = TypeVar("R")


class NotConnected(LinkError):
    """A request that needs a drive came while no link was open."""


class PanelRefused(DriveRefused):
    """The simulated drive's panel could not do it (servo on for turning by hand, ...)."""


class SimPanelAction(enum.Enum):
    """What the embedded simulated drive's panel does: the controller's side (CN2) and the
    technician's hands, which a real drive gets from outside CN3."""

    SERVO = "servo"  # value: on (the controller's servo-ON input, CN2)
    COMMAND = "command"  # value: output degrees, FWD positive (a command pulse train, servo on)
    TURN_BY_HAND = "turn"  # value: output degrees, CW positive (servo off, brake released)
    BRAKE_RELEASED = "brake"  # value: True = 24 V on the brake coil


@dataclass(frozen=True)
class LinkInfo:
    """What is known about a freshly opened link."""

    url: str
    driver_model: str = ""
    adjusted_for: str = ""
    firmware: str = ""
    capabilities: str = ""  # the client's plain description of what the drive supports
    capabilities_summary: str = ""  # the same in a few words (the status bar's)
    can_move: bool = True  # jog/move/servo extension commands are there
    can_monitor: bool = True
    can_parameters: bool = True
    is_simulated: bool = False
    documented_only: bool = False  # the drive answers only the manual's DGR and OWW
    absolute_position: bool | None = None  # DGR answered (True), x (False), unknown (None: s)
    embedded_sim: bool = False  # an embedded simulated drive: its panel (SimPanelRequest) can be used


@dataclass(frozen=True)
class LinkRequest(Generic[R]):
    """One thing the link worker is asked to do; its reply carries an ``R``.

    ``words``: what the person asked for, as a failure names it ("Move failed: ...").
    ``needs_link``: without an open link it is answered "not connected" (else it runs anyway).
    ``counts_as_busy``: the window shows the link busy until it is answered."""

    words: ClassVar[str] = "The drive request"
    needs_link: ClassVar[bool] = True
    counts_as_busy: ClassVar[bool] = True


@dataclass(frozen=True)
class Open(LinkRequest[LinkInfo]):
    """Open the drive at ``url`` (another one open is closed first)."""

    url: str
    baud_rate: int = BAUDRATE
    words: ClassVar[str] = "Connecting"
    needs_link: ClassVar[bool] = False


@dataclass(frozen=True)
class Close(LinkRequest[None]):
    """Stop the axis and close the port."""

    words: ClassVar[str] = "Disconnecting"
    needs_link: ClassVar[bool] = False


@dataclass(frozen=True)
class Identify(LinkRequest[LinkInfo]):
    words: ClassVar[str] = "Identifying the drive"


@dataclass(frozen=True)
class ReadParameters(LinkRequest[ParameterReadout]):
    """Read these items (mode, number), one by one; STOP ends the rest."""

    items: tuple[ParameterKey, ...]
    words: ClassVar[str] = "Reading the parameters"


@dataclass(frozen=True)
class WriteParameters(LinkRequest[list[WriteEntry]]):
    """Write these (mode, number, wire value), each verified by read-back; STOP ends the rest."""

    writes: tuple[ParameterWrite, ...]
    words: ClassVar[str] = "Writing the parameters"


@dataclass(frozen=True)
class Servo(LinkRequest[bool]):
    """Servo on or off; the reply is the state asked for."""

    on: bool
    words: ClassVar[str] = "Servo on/off"


@dataclass(frozen=True)
class Jog(LinkRequest[float]):
    """Jog at ``speed_rpm`` (output side, FWD positive), renewed by the worker while the GUI
    renews its lease; 0 lets go (the axis stops)."""

    speed_rpm: float
    words: ClassVar[str] = "Jog"
    needs_link: ClassVar[bool] = False


@dataclass(frozen=True)
class JogLease(LinkRequest[None]):
    """The jog button is still held."""

    words: ClassVar[str] = "Jog"
    needs_link: ClassVar[bool] = False
    counts_as_busy: ClassVar[bool] = False


@dataclass(frozen=True)
class SetMoveSpeed(LinkRequest[float]):
    speed_rpm: float
    words: ClassVar[str] = "Setting the move speed"


@dataclass(frozen=True)
class MoveBy(LinkRequest[float]):
    """Move the output by ``angle_deg`` (FWD positive) at the move speed."""

    angle_deg: float
    words: ClassVar[str] = "Move"


@dataclass(frozen=True)
class Stop(LinkRequest[None]):
    """STOP: ends a held jog and a long read or write at the next item, and stops the axis."""

    words: ClassVar[str] = "STOP"
    needs_link: ClassVar[bool] = False


@dataclass(frozen=True)
class ClearAlarm(LinkRequest[int]):
    """Clear the alarm; the reply is the alarm still active (0: none)."""

    words: ClassVar[str] = "Clearing the alarm"


@dataclass(frozen=True)
class ReadAlarmHistory(LinkRequest[list[AlarmRecord]]):
    words: ClassVar[str] = "Reading the alarm history"


@dataclass(frozen=True)
class PowerCycle(LinkRequest[None]):
    """Switch the (simulated) drive's control power off and on."""

    words: ClassVar[str] = "Power cycle"


@dataclass(frozen=True)
class SetInputs(LinkRequest[int]):
    """Simulated CN2 inputs by name (``brake_released=True``, ...); the reply is the I/O word."""

    inputs: Mapping[str, bool] = field(default_factory=dict)
    words: ClassVar[str] = "Setting the simulated inputs"


@dataclass(frozen=True)
class Call(LinkRequest[R]):
    """Run ``function`` with the open drive in the link thread (a procedure of another page);
    the reply carries what it returns."""

    function: Callable[[DriveApi], R]


@dataclass(frozen=True)
class SimPanelRequest(LinkRequest[str]):
    """What the embedded simulated drive's panel does (its CN2 and the technician's hands); the
    reply is one line saying what happened."""

    action: SimPanelAction
    value: float | bool
    words: ClassVar[str] = "The simulated drive's panel"


@dataclass(frozen=True)
class SetPollInterval(LinkRequest[int]):
    """Ms between status polls (the scope slows them while live); the reply is what was set."""

    interval_ms: int
    words: ClassVar[str] = "Setting the poll interval"
    needs_link: ClassVar[bool] = False


@dataclass(frozen=True)
class Shutdown(LinkRequest[None]):
    """Stop the axis, close the port, end the link thread (the last request)."""

    needs_link: ClassVar[bool] = False
    counts_as_busy: ClassVar[bool] = False


#: Every request the worker runs (a test checks each has its handler).
REQUESTS: tuple[type[LinkRequest[Any]], ...] = (
    Open, Close, Identify, ReadParameters, WriteParameters, Servo, Jog, JogLease, SetMoveSpeed,
    MoveBy, Stop, ClearAlarm, ReadAlarmHistory, PowerCycle, SetInputs, Call, SimPanelRequest,
    SetPollInterval, Shutdown,
)


@dataclass(frozen=True)
class Sent(Generic[R]):
    """A request on its way into the link thread; ``token`` ties its reply to it."""

    token: int
    request: LinkRequest[R]


@dataclass(frozen=True)
class LinkReply(Generic[R]):
    """What came of one request: ``value`` on success, else ``error`` (one line for the user) and
    ``error_type``, the class of the exception (``ServoOnRefused``, ``LinkLost``, ``NotConnected``...).
    ``token`` 0: the worker's own (a held jog it renewed, or let go when its lease ran out)."""

    token: int
    request: LinkRequest[R]
    value: R | None = None
    error: str | None = None
    error_type: type[Exception] | None = None

    @property
    def ok(self) -> bool:
        return self.error is None

    @property
    def answer(self) -> R:
        """The value of a reply that is ``ok``; a failed one has none (``LinkError`` with its error)."""
        if self.error is not None:
            raise LinkError(f"{self.request.words}: no answer ({self.error})")
        return cast(R, self.value)

    def answers(self, kind: type[LinkRequest[Any]]) -> bool:
        """True when this is the reply to a request of ``kind``: ``answers(Servo)``."""
        return isinstance(self.request, kind)

    def failed_with(self, kind: type[Exception]) -> bool:
        """True when the request failed with ``kind`` (or a subclass): ``failed_with(DriveRefused)``."""
        return self.error_type is not None and issubclass(self.error_type, kind)


#: Where a reply goes: the sender's own function.
OnReply = Callable[[LinkReply[R]], None]

__all__ = [
    "REQUESTS",
    "Call",
    "ClearAlarm",
    "Close",
    "Identify",
    "Jog",
    "JogLease",
    "LinkInfo",
    "LinkReply",
    "LinkRequest",
    "MoveBy",
    "NotConnected",
    "OnReply",
    "Open",
    "PanelRefused",
    "PowerCycle",
    "ReadAlarmHistory",
    "ReadParameters",
    "Sent",
    "Servo",
    "SetInputs",
    "SetMoveSpeed",
    "SetPollInterval",
    "Shutdown",
    "SimPanelAction",
    "SimPanelRequest",
    "Stop",
    "WriteParameters",
]
