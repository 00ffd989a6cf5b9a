"""What a session with a drive does over its interface, without Qt: the status poll, the idle
probe of a drive of the manual's commands only, and the parameter read-out and write-in.

The GUI's link worker runs these in its thread (a single-shot timer re-armed at the end of each
pass, as Qudi's polling loop); a test runs them straight over the simulated drive. Each takes the
drive by the protocols of ``hardware.api`` it needs, so a stand-in implements only what it plays.

Link failures: ``LinkLost`` (the transaction layer's one verdict that the link is gone) always
comes out; any other link failure of a poll is logged and leaves the fields it would have filled
empty; a refusal of one parameter item is that item's sentence and the read or write goes on.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Protocol, TypedDict

from fha_studio import clock
from fha_studio.hardware.api import (
    CommandNotSupported,
    CommandRejected,
    DriveLink,
    DriveRefused,
    ExtensionCommands,
    LinkError,
    LinkLost,
    LinkTimeout,
    ManualCommands,
    ServoOnRefused,
)
from fha_studio.hardware.parameters import Mode, MonitorItem
from fha_studio.hardware.protocol import Command, IoBit
from fha_studio.logic.absolute import SERVO_ON_TEXT, refusal_text

__all__ = [
    "POLL_INTERVAL_MS",
    "PROBE_INTERVAL_MS",
    "SERVO_ON_NOTE",
    "SERVO_ON_PROBE_MS",
    "STATUS_MONITORS",
    "DriveStatus",
    "ParameterKey",
    "ParameterReadout",
    "ParameterWrite",
    "PolledDrive",
    "StatusPoller",
    "WriteEntry",
    "failure_text",
    "read_parameters",
    "write_parameters",
]

log = logging.getLogger(__name__)

#: Poll period of status, alarm, I/O and monitors while connected, in ms.
POLL_INTERVAL_MS = 100
#: Idle probe period of a drive without status commands (a drive of the manual's DGR and OWW),
#: in ms: one DGR about every 0.7 s, so a drive switched off or unplugged shows within 2 s
#: (this period plus one failed exchange with its retry, about 1 s).
PROBE_INTERVAL_MS = 700
#: While the drive answers "servo on" (s), it is asked at most once a second.
SERVO_ON_PROBE_MS = 1000
#: What the technician is told while a drive answers s (the words of the DGR checks and the CLI).
SERVO_ON_NOTE = SERVO_ON_TEXT
#: The monitor items of the status poll: output position, output speed, motor current (its mean
#: over 10 ms: one instantaneous sample per poll shows the quantised encoder's dither, tenths of an
#: ampere, as if it were a standing current).
STATUS_MONITORS = (MonitorItem.FEEDBACK_POSITION, MonitorItem.OUTPUT_SPEED, MonitorItem.MOTOR_CURRENT_MEAN)

#: One parameter item: its front-panel mode and number.
ParameterKey = tuple[Mode, int]
#: One write: mode, number, wire value.
ParameterWrite = tuple[Mode, int, int]

_PLAIN_FAILURES: tuple[tuple[type[Exception], str], ...] = (
    (LinkLost, "the link is lost"),
    (LinkTimeout, "the drive did not answer"),
    (ServoOnRefused, "refused: the servo is on"),
    (DriveRefused, "refused by the drive"),
)


def failure_text(exc: Exception, plain: Iterable[tuple[type[Exception], str]] = ()) -> str:
    """One line for the user: the exception's text, or what its kind means when it has none
    (``plain`` first: a caller's own kinds)."""
    text = str(exc)
    if text:
        return text
    kinds = (*plain, *_PLAIN_FAILURES)
    return next((words for kind, words in kinds if isinstance(exc, kind)), "failed")


@dataclass(frozen=True)
class DriveStatus:
    """One poll of the drive. Fields are None when the drive could not tell (servo-on refusal,
    no monitor support)."""

    time_s: float
    servo_on: bool | None = None
    alarm_code: int | None = None
    io_bits: int | None = None
    speed_rpm: float | None = None
    position_pulse: int | None = None
    current_a: float | None = None
    jogging: bool = False
    refused: bool = False  # the drive answered "servo on: not now"
    absolute_counts: int | None = None  # DGR's position (servo off, absolute encoder)
    note: str = ""  # one line for the technician about this poll (servo on, DGR refused)

    def bit(self, bit: IoBit) -> bool | None:
        return None if self.io_bits is None else bool(self.io_bits >> bit & 1)

    @property
    def moving(self) -> bool:
        return bool(self.jogging or self.bit(IoBit.MOVING))


class PolledDrive(DriveLink, ManualCommands, ExtensionCommands, Protocol):
    """What the status poll asks of a drive: what it is, DGR, alarm, I/O and monitors."""


class _Fields(TypedDict, total=False):
    """The fields of one poll as they are learnt, by DriveStatus's own names (the rest keep its
    defaults); a TypedDict so the type checker holds each name and type to DriveStatus's."""

    servo_on: bool | None
    alarm_code: int | None
    io_bits: int | None
    speed_rpm: float | None
    position_pulse: int | None
    current_a: float | None
    refused: bool
    absolute_counts: int | None
    note: str


class StatusPoller:
    """The status poll of one open drive. ``poll()`` is one pass: it returns the status and the
    delay until the next pass (ms). A drive with status commands is asked alarm, I/O and the
    monitors (until it turns out to lack the monitor extension); a drive of the manual's commands
    only is probed with one DGR, less often. ``LinkLost`` comes out; other link failures leave
    the fields empty."""

    def __init__(self, drive: PolledDrive, interval_ms: int = POLL_INTERVAL_MS):
        self.drive = drive
        self.interval_ms = interval_ms
        self.monitors_ok = True

    def set_interval(self, interval_ms: int) -> int:
        """The poll period, never faster than ``POLL_INTERVAL_MS``; returns what was set."""
        self.interval_ms = max(POLL_INTERVAL_MS, int(interval_ms))
        return self.interval_ms

    def poll(self, jogging: bool = False, time_s: float | None = None) -> tuple[DriveStatus, int]:
        """One pass: (the status, ms until the next pass). ``jogging``: a jog is being held."""
        stamp = time.monotonic() if time_s is None else time_s
        got: _Fields = {}
        interval_ms = self.interval_ms
        try:
            if not self.drive.capabilities.supports(Command.IOS):
                interval_ms = self._probe(got)
            else:
                try:
                    got["alarm_code"] = self.drive.alarm()
                    io = self.drive.io_state()
                    got["io_bits"] = io.raw
                    got["servo_on"] = io.servo_on
                    if self.monitors_ok:
                        self._poll_monitors(got)
                except ServoOnRefused:
                    got["refused"] = True
                    got["servo_on"] = True  # a drive refuses CN3 commands while the servo is on
                    got["note"] = SERVO_ON_NOTE
                    interval_ms = max(interval_ms, SERVO_ON_PROBE_MS)
        except LinkLost:
            raise
        except LinkError as exc:
            log.info("poll failed: %s", exc)
        return DriveStatus(time_s=stamp, jogging=jogging, **got), interval_ms

    def _probe(self, got: _Fields) -> int:
        """The idle probe of a drive without status commands: one DGR. Data, s and x all prove
        the drive is there; silence is the link's failure. Returns the next pass's delay."""
        try:
            got["absolute_counts"] = self.drive.absolute_position()
            got["servo_on"] = False
        except ServoOnRefused:
            got["servo_on"] = True
            got["refused"] = True
            got["note"] = SERVO_ON_NOTE
            return max(self.interval_ms, SERVO_ON_PROBE_MS)
        except CommandRejected as exc:
            # s comes to everything while the servo is on, so x means: servo off, no DGR
            got["servo_on"] = False
            got["note"] = refusal_text(exc, Command.DGR)
        return max(self.interval_ms, PROBE_INTERVAL_MS)

    def _poll_monitors(self, got: _Fields) -> None:
        """Output position (pulse), output speed (r/min) and motor current (A, the 10 ms mean),
        scaled by the parameter model's monitor items."""
        try:
            values = self.drive.read_monitors(STATUS_MONITORS)
        except (CommandNotSupported, CommandRejected) as exc:
            self.monitors_ok = False  # a drive without the monitor extension: stop asking
            log.info("monitors not available: %s", exc)
            return

        def scaled(item: MonitorItem) -> float | None:
            wire = values.get(item)
            return None if wire is None else self.drive.model.item(Mode.MONITOR, item).to_unit(wire)

        got["position_pulse"] = values.get(MonitorItem.FEEDBACK_POSITION)
        got["speed_rpm"] = scaled(MonitorItem.OUTPUT_SPEED)
        got["current_a"] = scaled(MonitorItem.MOTOR_CURRENT_MEAN)


@dataclass(frozen=True)
class ParameterReadout:
    """What a read of parameter items gave: wire values, and a sentence per item that could not
    be read (refused, unknown, or not read because STOP came first)."""

    values: dict[ParameterKey, int] = field(default_factory=dict)
    errors: dict[ParameterKey, str] = field(default_factory=dict)


def read_parameters(
    drive: ExtensionCommands, items: Iterable[ParameterKey], stopped: Callable[[], bool] = lambda: False
) -> ParameterReadout:
    """Read ``items`` one by one. A refusal (or a bad item) is that item's sentence; a link
    failure ends the read (it comes out). Once ``stopped()`` says so the rest are "stopped"."""
    readout = ParameterReadout()
    for mode, number in items:
        key = (Mode(mode), number)
        if stopped():
            readout.errors[key] = "stopped"
            continue
        try:
            readout.values[key] = drive.read_parameter(*key)
        except (DriveRefused, ValueError) as exc:  # this item; the link failures end the read
            readout.errors[key] = failure_text(exc)
    return readout


class WriteEntry(TypedDict, total=False):
    """One parameter write, as the session log keeps it: old, new, read back, verified or why not."""

    time: float
    mode: Mode
    number: int
    new: int
    old: int | None
    read_back: int | None
    verified: bool
    error: str | None
    restart_required: bool
    message: str


def write_parameters(
    drive: ExtensionCommands,
    writes: Iterable[ParameterWrite],
    stopped: Callable[[], bool] = lambda: False,
    on_write: Callable[[WriteEntry], None] = lambda entry: None,
) -> list[WriteEntry]:
    """Write one by one, each verified by read-back (``write_parameter``); every entry is also
    given to ``on_write`` as it is done (the session log). A refusal is that entry's error and
    the writes go on; a link failure is the entry's error and comes out. Once ``stopped()`` says
    so the rest are "not written: stopped"."""
    done: list[WriteEntry] = []
    for mode, number, value in writes:
        entry: WriteEntry = {
            "time": clock.now_s(), "mode": Mode(mode), "number": number, "new": value,
            "old": None, "read_back": None, "verified": False, "error": None,
        }
        if stopped():
            entry["error"] = "not written: stopped"
            done.append(entry)
            on_write(entry)
            continue
        try:
            result = drive.write_parameter(mode, number, value)
        except (DriveRefused, ValueError) as exc:
            entry["error"] = failure_text(exc)
        except LinkError as exc:
            entry["error"] = failure_text(exc)
            on_write(entry)
            raise
        else:
            entry["old"] = result.previous
            entry["read_back"] = result.value
            entry["verified"] = result.verified
            entry["restart_required"] = result.needs_restart
            entry["message"] = result.message
            if not result.verified:
                entry["error"] = result.message or "read-back differs"
        done.append(entry)
        on_write(entry)
    return done
