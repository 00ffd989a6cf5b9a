"""The drive link off the GUI thread: a worker QObject in its own QThread owns the drive (a DriveApi).

PyMoDAQ's pattern: commands go in through one queued signal carrying a small `LinkCommand`
(an Enum name and its arguments); results and status come out through signals. Qudi's polling
loop: a single-shot QTimer re-armed at the end of each pass, so passes never overlap.

The GUI thread never waits on the port. The only thing it shares with the worker directly is a
`threading.Event` that asks a long operation (read all, write all) to give up between items, so
that a STOP is not queued behind it.
"""

from __future__ import annotations

import enum
import itertools
import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from PySide6.QtCore import QObject, QThread, QTimer, Signal, Slot

from fha_studio.hardware.api import AlarmRecord, DriveApi, DriveRefused, LinkError, LinkLost, SimPanel
from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.protocol import BAUDRATE, EXTENSION_COMMANDS
from fha_studio.hardware.sim.options import public_url
from fha_studio.hardware.transaction import LinkSettings
from fha_studio.logic.drive_session import (
    POLL_INTERVAL_MS,
    PROBE_INTERVAL_MS,
    SERVO_ON_NOTE,
    SERVO_ON_PROBE_MS,
    STATUS_MONITORS,
    DriveStatus,
    ParameterKey,
    ParameterReadout,
    ParameterWrite,
    StatusPoller,
    WriteEntry,
    failure_text,
    read_parameters,
    write_parameters,
)

log = logging.getLogger(__name__)

#: Jog keep-alive period, in ms: the drive's watchdog stops the axis 100 ms after the last JOG.
JOG_KEEPALIVE_MS = 40
#: A held jog button renews its lease this often (GUI side), in ms ...
JOG_LEASE_RENEW_MS = 150
#: ... and the worker stops jogging if the lease is older than this (a frozen GUI must not
#: leave the axis running), in s.
JOG_LEASE_S = 0.5
#: Failed transactions in a row after which the transaction layer marks the link lost (its one
#: rule, ``LinkSettings.max_consecutive_failures``): one exchange left unanswered after its retry
#: shows the technician a dead link at once. Set once the drive is open (``lose_link_after``).
LINK_LOST_AFTER_FAILURES = 1


class Cmd(enum.Enum):
    """What the worker is asked to do."""

    OPEN = enum.auto()  # args: url, baud_rate
    CLOSE = enum.auto()  # stop the axis, close the port
    IDENTIFY = enum.auto()
    READ_PARAMETERS = enum.auto()  # args: items [(mode, number), ...]
    WRITE_PARAMETERS = enum.auto()  # args: writes [(mode, number, value), ...]
    SERVO = enum.auto()  # args: on
    JOG = enum.auto()  # args: speed_rpm (0 = release: stop)
    JOG_LEASE = enum.auto()  # the jog button is still held
    SET_MOVE_SPEED = enum.auto()  # args: speed_rpm
    MOVE_BY = enum.auto()  # args: angle_deg
    STOP = enum.auto()
    CLEAR_ALARM = enum.auto()
    ALARM_HISTORY = enum.auto()
    POWER_CYCLE = enum.auto()
    SET_INPUTS = enum.auto()  # args: {input name: on} (simulated drive only)
    CALL = enum.auto()  # args: a callable taking the DriveApi (for procedures of other pages)
    SIM_PANEL = enum.auto()  # args: SimPanelAction, value (the embedded simulated drive's CN2 and hands)
    SET_POLL_INTERVAL = enum.auto()  # args: ms between status polls (the scope slows them while live)
    SHUTDOWN = enum.auto()  # stop the axis, close the port, end the link thread


#: Commands that need no open link (the rest answer "not connected" without one).
_WITHOUT_LINK = frozenset({Cmd.OPEN, Cmd.CLOSE, Cmd.STOP, Cmd.JOG, Cmd.JOG_LEASE, Cmd.SET_POLL_INTERVAL})


class NotConnected(LinkError):
    """A command that needs a drive came while no link was open."""


class SimPanelAction(enum.Enum):
    """What the embedded simulated drive's panel does: the controller's side (CN2) and the
    technician's hands, which a real drive gets from outside CN3."""

    SERVO = "servo"  # value: on (the controller's servo-ON input, CN2)
    COMMAND = "command"  # value: output degrees, FWD positive (a command pulse train, servo on)
    TURN_BY_HAND = "turn"  # value: output degrees, CW positive (servo off, brake released)
    BRAKE_RELEASED = "brake"  # value: True = 24 V on the brake coil


class PanelRefused(DriveRefused):
    """The simulated drive's panel could not do it (servo on for turning by hand, ...)."""


@dataclass(frozen=True)
class LinkCommand:
    """One command for the worker. `token` ties the result to the request."""

    cmd: Cmd
    args: tuple[Any, ...] = ()
    token: int = 0


@dataclass(frozen=True)
class CommandResult:
    """What came of one command: `value` on success, else `error` (one line for the user) and
    `error_type`, the class of the exception (``ServoOnRefused``, ``LinkLost``, ``NotConnected``...)."""

    token: int
    cmd: Cmd
    value: Any = None
    error: str | None = None
    error_type: type[Exception] | None = None

    @property
    def ok(self) -> bool:
        return self.error is None

    def failed_with(self, kind: type[Exception]) -> bool:
        """True when the command failed with ``kind`` (or a subclass): ``failed_with(DriveRefused)``."""
        return self.error_type is not None and issubclass(self.error_type, kind)


@dataclass(frozen=True)
class LinkInfo:
    """What is known about a freshly opened link."""

    url: str
    driver_model: str = ""
    adjusted_for: str = ""
    firmware: str = ""
    capabilities: str = ""  # the client's plain description of what the drive supports
    can_move: bool = True  # jog/move/servo extension commands are there
    can_monitor: bool = True
    can_parameters: bool = True
    is_simulated: bool = False
    documented_only: bool = False  # the drive answers only the manual's DGR and OWW
    absolute_position: bool | None = None  # DGR answered (True), x (False), unknown (None: s)
    embedded_sim: bool = False  # an embedded simulated drive: its panel (SIM_PANEL) can be used


#: Opens a drive: (url, baud rate) -> an open DriveApi. Raises LinkError when it cannot.
OpenClient = Callable[[str, int], DriveApi]


def link_settings(baud_rate: int = BAUDRATE) -> LinkSettings:
    """The link worker's settings: short timeouts, so a dead link shows within a second or two
    (one retry of 0.25 s); every call ends within ``transaction_limit_s`` whatever the line does."""
    return LinkSettings(baudrate=baud_rate, response_timeout_s=0.25, retries=1)


def _message(exc: Exception) -> str:
    """One line for the user: the exception's text, or what its kind means when it has none."""
    return failure_text(exc, ((NotConnected, "not connected"),))


class LinkWorker(QObject):
    """Owns the DriveApi; lives in the link thread. Talk to it only through signals."""

    sigConnected = Signal(object)  # LinkInfo
    sigDisconnected = Signal(str, bool)  # reason, lost (True: the link died, not closed by us)
    sigStatus = Signal(object)  # DriveStatus
    sigResult = Signal(object)  # CommandResult
    sigWrite = Signal(object)  # WriteEntry: one write, for the session log

    def __init__(
        self,
        abort: threading.Event,
        open_client: OpenClient | None = None,
        closing: threading.Event | None = None,
    ):
        super().__init__()
        self._abort = abort
        # Set (in the GUI thread) when the window closes: every exchange but the final STOP gives
        # up at its next read, so the thread ends at once even while connecting to a babbling line.
        self._closing = closing or threading.Event()
        self._final = False
        self._poll_interval_ms = POLL_INTERVAL_MS
        self._poller: StatusPoller | None = None
        self._open_client: OpenClient = open_client or self._open_drive
        self._client: DriveApi | None = None
        self._url = ""
        self._poll_timer: QTimer | None = None
        self._jog_timer: QTimer | None = None
        self._jog_speed_rpm = 0.0
        self._jog_lease_s = 0.0
        #: What each command runs (every Cmd has one; a test checks it).
        self.handlers: dict[Cmd, Callable[..., Any]] = {
            Cmd.OPEN: self._do_open,
            Cmd.CLOSE: self._do_close,
            Cmd.IDENTIFY: self._do_identify,
            Cmd.READ_PARAMETERS: self._do_read_parameters,
            Cmd.WRITE_PARAMETERS: self._do_write_parameters,
            Cmd.SERVO: self._do_servo,
            Cmd.JOG: self._do_jog,
            Cmd.JOG_LEASE: self._do_jog_lease,
            Cmd.SET_MOVE_SPEED: self._do_set_move_speed,
            Cmd.MOVE_BY: self._do_move_by,
            Cmd.STOP: self._do_stop,
            Cmd.CLEAR_ALARM: self._do_clear_alarm,
            Cmd.ALARM_HISTORY: self._do_alarm_history,
            Cmd.POWER_CYCLE: self._do_power_cycle,
            Cmd.SET_INPUTS: self._do_set_inputs,
            Cmd.CALL: self._do_call,
            Cmd.SIM_PANEL: self._do_sim_panel,
            Cmd.SET_POLL_INTERVAL: self._do_set_poll_interval,
            Cmd.SHUTDOWN: self._shutdown,
        }

    # -- life ---------------------------------------------------------------------------------
    @Slot()
    def start(self) -> None:
        """Runs in the link thread once it starts: the timers belong to this thread."""
        self._poll_timer = QTimer(self)
        self._poll_timer.setSingleShot(True)
        self._poll_timer.timeout.connect(self._poll)
        self._jog_timer = QTimer(self)
        self._jog_timer.setInterval(JOG_KEEPALIVE_MS)
        self._jog_timer.timeout.connect(self._jog_keepalive)

    @property
    def client(self) -> DriveApi:
        """The open drive; ``NotConnected`` without one."""
        if self._client is None:
            raise NotConnected("not connected")
        return self._client

    @Slot(object)
    def handle(self, command: LinkCommand) -> None:
        handler = self.handlers[command.cmd]
        if command.cmd is Cmd.SHUTDOWN:
            handler()
            return
        if command.cmd is Cmd.STOP:
            self._abort.clear()
        if self._client is None and command.cmd not in _WITHOUT_LINK:
            self._emit(command, error=NotConnected("not connected"))
            return
        try:
            value = handler(*command.args)
        except Exception as exc:
            self._emit(command, error=exc)
            if self._client is not None and isinstance(exc, LinkLost):
                self._lose(exc)
            return
        self._emit(command, value=value)

    def _emit(self, command: LinkCommand, value: Any = None, error: Exception | None = None) -> None:
        if error is None:
            self.sigResult.emit(CommandResult(command.token, command.cmd, value))
        else:
            self.sigResult.emit(CommandResult(command.token, command.cmd, None, _message(error), type(error)))

    def _lose(self, exc: Exception) -> None:
        reason = f"link lost: {_message(exc)}"
        self._shut(stop_axis=False)
        self.sigDisconnected.emit(reason, True)

    def _shut(self, stop_axis: bool) -> None:
        if self._jog_timer is not None:
            self._jog_timer.stop()
        if self._poll_timer is not None:
            self._poll_timer.stop()
        self._jog_speed_rpm = 0.0
        client, self._client = self._client, None
        self._poller = None
        if client is None:
            return
        if stop_axis:
            try:
                client.stop()
            except (LinkError, OSError) as exc:  # the port may already be gone; closing goes on
                log.info("stop on close failed: %s", exc)
        try:
            client.close()
        except (LinkError, OSError) as exc:
            log.info("close failed: %s", exc)

    def _shutdown(self) -> None:
        """The last command: runs in the link thread, so the timers die in their own thread."""
        self._final = True  # the STOP below must reach the drive although the window is closing
        self._shut(stop_axis=True)
        for timer in (self._poll_timer, self._jog_timer):
            if timer is not None:
                timer.stop()
                timer.deleteLater()
        self._poll_timer = self._jog_timer = None
        _forget_dummy_thread()
        QThread.currentThread().quit()

    def _abandon(self) -> bool:
        return self._closing.is_set() and not self._final

    def _open_drive(self, url: str, baud_rate: int) -> DriveApi:
        return DriveClient.open(url, link_settings(baud_rate), should_abort=self._abandon)

    # -- commands -----------------------------------------------------------------------------
    def _do_open(self, url: str, baud_rate: int = BAUDRATE) -> LinkInfo:
        if self._client is not None:
            self._shut(stop_axis=True)
            self.sigDisconnected.emit("switched to another drive", False)
        self._client = self._open_client(url, baud_rate)
        if isinstance(self._client, DriveClient):  # the transaction layer's verdict, made prompt
            self._client.lose_link_after(LINK_LOST_AFTER_FAILURES)
        self._url = url
        self._poller = StatusPoller(self._client, self._poll_interval_ms)
        info = self._describe(url)
        self.sigConnected.emit(info)
        assert self._poll_timer is not None
        self._poll_timer.start(0)
        return info

    def _describe(self, url: str) -> LinkInfo:
        client = self.client
        ident = None
        try:
            ident = client.identify()  # None on a drive without IDN
        except LinkLost:
            raise
        except LinkError as exc:
            log.info("identify failed: %s", exc)
        caps = client.capabilities
        extensions = set(caps.commands) & EXTENSION_COMMANDS
        return LinkInfo(
            url=public_url(url),  # a training drive's options name its hidden faults
            driver_model=ident.driver_model if ident else "",
            adjusted_for=ident.adjusted_for if ident else "",
            firmware=ident.firmware if ident else "",
            capabilities=caps.describe(),
            can_move=caps.can_move,
            can_monitor=caps.can_monitor,
            can_parameters=caps.parameters,
            is_simulated=caps.simulated,
            documented_only=not extensions,
            absolute_position=caps.absolute_position,
            embedded_sim=_embedded_sim(client) is not None,
        )

    def _do_close(self) -> None:
        was_open = self._client is not None
        self._shut(stop_axis=True)
        if was_open:
            self.sigDisconnected.emit("closed", False)

    def _do_identify(self) -> LinkInfo:
        return self._describe(self._url)

    def _do_read_parameters(self, items: list[ParameterKey]) -> ParameterReadout:
        return read_parameters(self.client, items, self._abort.is_set)

    def _do_write_parameters(self, writes: list[ParameterWrite]) -> list[WriteEntry]:
        """Writes one by one; each entry says old, new, verified (by read-back) or the error."""
        return write_parameters(self.client, writes, self._abort.is_set, self.sigWrite.emit)

    def _do_servo(self, on: bool) -> bool:
        self.client.servo(bool(on))
        return bool(on)

    def _do_jog(self, speed_rpm: float) -> float:
        speed_rpm = float(speed_rpm)
        assert self._jog_timer is not None
        if speed_rpm == 0.0:
            was = self._jog_speed_rpm
            self._jog_speed_rpm = 0.0
            self._jog_timer.stop()
            if self._client is not None and was:
                self._client.stop()
            return 0.0
        if self._client is None:
            return 0.0
        self._jog_lease_s = time.monotonic()
        try:
            self._client.jog(speed_rpm)
        except Exception:
            self._jog_speed_rpm = 0.0
            self._jog_timer.stop()
            raise
        self._jog_speed_rpm = speed_rpm
        self._jog_timer.start()
        return speed_rpm

    def _do_jog_lease(self) -> None:
        self._jog_lease_s = time.monotonic()

    @Slot()
    def _jog_keepalive(self) -> None:
        if self._jog_timer is None:
            return
        if self._client is None or not self._jog_speed_rpm:
            self._jog_timer.stop()
            return
        if time.monotonic() - self._jog_lease_s > JOG_LEASE_S:
            # The GUI stopped renewing (frozen, or the release got lost): stop, do not run on.
            self.handle(LinkCommand(Cmd.JOG, (0.0,)))
            return
        try:
            self._client.jog(self._jog_speed_rpm)
        except (LinkError, ValueError) as exc:
            self._jog_speed_rpm = 0.0
            self._jog_timer.stop()
            self._emit(LinkCommand(Cmd.JOG), error=exc)
            if isinstance(exc, LinkLost):
                self._lose(exc)

    def _do_set_move_speed(self, speed_rpm: float) -> float:
        self.client.set_move_speed(float(speed_rpm))
        return float(speed_rpm)

    def _do_move_by(self, angle_deg: float) -> float:
        self.client.move_by(float(angle_deg))
        return float(angle_deg)

    def _do_stop(self) -> None:
        self._jog_speed_rpm = 0.0
        if self._jog_timer is not None:
            self._jog_timer.stop()
        if self._client is not None:
            self._client.stop()

    def _do_clear_alarm(self) -> int:
        self.client.clear_alarm()
        return self.client.alarm()

    def _do_alarm_history(self) -> list[AlarmRecord]:
        return self.client.alarm_history()

    def _do_power_cycle(self) -> None:
        self.client.power_cycle()

    def _do_set_inputs(self, inputs: dict[str, bool]) -> int:
        """Simulated CN2 inputs by name (fwd_inhibit=True, ...); the simulated drive only."""
        return self.client.set_inputs(**inputs).raw

    def _do_set_poll_interval(self, interval_ms: int) -> int:
        self._poll_interval_ms = max(POLL_INTERVAL_MS, int(interval_ms))
        if self._poller is not None:
            self._poller.set_interval(self._poll_interval_ms)
        return self._poll_interval_ms

    def _do_call(self, function: Callable[[DriveApi], Any]) -> Any:
        return function(self.client)

    def _do_sim_panel(self, action: SimPanelAction, value: Any) -> str:
        """Do what the embedded simulated drive's panel asks; one line saying what happened."""
        sim = _embedded_sim(self.client)
        if sim is None:
            raise NotConnected("this is not an embedded simulated drive: it has no panel")
        from fha_studio.hardware.sim import SimRefused

        try:
            if action is SimPanelAction.SERVO:
                sim.set_servo(bool(value))
                return f"servo-ON input (CN2) {'on' if value else 'off'}"
            if action is SimPanelAction.COMMAND:
                sim.controller_command(float(value))
                return f"controller: {'FWD' if value > 0 else 'REV'} command of {abs(float(value)):g}°"
            if action is SimPanelAction.TURN_BY_HAND:
                sim.turn_by_hand(float(value))
                text = f"output turned by hand by {float(value):+g}°"
                if sim.has_sensors:  # what the technician would see on the sensors' indicators
                    state = sim.io_state()
                    lit = [name for on, name in ((state.limit_switch_1, "limit switch 1"),
                                                 (state.limit_switch_2, "limit switch 2"),
                                                 (state.origin_sensor, "origin sensor")) if on]
                    text += f"; sensor indicators on: {', '.join(lit) if lit else 'none'}"
                return text
            sim.release_brake(bool(value))
            return "brake released (24 V on the brake)" if value else "brake holds (no 24 V)"
        except SimRefused as exc:
            raise PanelRefused(exc.reason) from None

    # -- polling ------------------------------------------------------------------------------
    @Slot()
    def _poll(self) -> None:
        poller = self._poller
        if self._client is None or poller is None:
            return
        try:
            status, interval_ms = poller.poll(jogging=bool(self._jog_speed_rpm))
        except LinkLost as exc:
            self._lose(exc)
            return
        self.sigStatus.emit(status)
        if self._client is not None and self._poll_timer is not None:
            self._poll_timer.start(interval_ms)


def _embedded_sim(client: DriveApi) -> SimPanel | None:
    """The panel of an embedded ``sim://`` drive, None for any other drive (a test fake too). Only
    the link thread uses it, like the port itself."""
    return client.sim_panel if isinstance(client, DriveClient) else None


def _forget_dummy_thread() -> None:
    """Python registers a QThread as a "_DummyThread" the first time code in it asks for the
    current thread (threading.Thread() does, to inherit daemon); Python < 3.12 never removes such
    entries, so the ended link thread would look alive forever. Called in the thread, at its end."""
    current = threading.current_thread()
    if isinstance(current, threading._DummyThread):
        with threading._active_limbo_lock:  # type: ignore[attr-defined]
            threading._active.pop(threading.get_ident(), None)  # type: ignore[attr-defined]


class LinkController(QObject):
    """The GUI-thread face of the link: sends commands, re-emits what the worker says, and keeps
    the last known state for the pages. Never blocks."""

    sigCommand = Signal(object)  # LinkCommand, queued into the worker
    sigConnected = Signal(object)
    sigDisconnected = Signal(str, bool)
    sigStatus = Signal(object)
    sigResult = Signal(object)
    sigWrite = Signal(object)
    sigBusyChanged = Signal(bool)

    def __init__(self, parent: QObject | None = None, open_client: OpenClient | None = None):
        super().__init__(parent)
        self._tokens = itertools.count(1)
        self._abort = threading.Event()
        self._closing = threading.Event()
        self._thread = QThread()
        self._thread.setObjectName("fha-link")
        self._worker = LinkWorker(self._abort, open_client, self._closing)
        self._worker.moveToThread(self._thread)
        self._thread.started.connect(self._worker.start)
        self.sigCommand.connect(self._worker.handle)  # queued: the worker lives in the thread
        self._worker.sigConnected.connect(self._on_connected)
        self._worker.sigDisconnected.connect(self._on_disconnected)
        self._worker.sigStatus.connect(self._on_status)
        self._worker.sigResult.connect(self._on_result)
        self._worker.sigWrite.connect(self.sigWrite)
        self.info: LinkInfo | None = None
        self.status: DriveStatus | None = None
        self.last_disconnect_reason = ""
        self._pending: dict[int, Cmd] = {}
        self._jog_lease_timer = QTimer(self)
        self._jog_lease_timer.setInterval(JOG_LEASE_RENEW_MS)
        self._jog_lease_timer.timeout.connect(lambda: self.send(Cmd.JOG_LEASE))
        self._thread.start()

    # -- state ---------------------------------------------------------------------------------
    @property
    def connected(self) -> bool:
        return self.info is not None

    @property
    def servo_on(self) -> bool:
        return bool(self.status and self.status.servo_on)

    @property
    def moving(self) -> bool:
        return bool(self.status and self.status.moving) or self._jog_lease_timer.isActive()

    @property
    def busy(self) -> bool:
        return bool(self._pending)

    @property
    def abort_event(self) -> threading.Event:
        """Set by STOP (before the STOP is queued), cleared when the worker handles it: code
        running in the link thread checks it between items of a long operation."""
        return self._abort

    # -- commands ------------------------------------------------------------------------------
    def send(self, cmd: Cmd, *args) -> int:
        token = next(self._tokens)
        if cmd not in (Cmd.JOG_LEASE,):
            was_busy = self.busy
            self._pending[token] = cmd
            if not was_busy:
                self.sigBusyChanged.emit(True)
        self.sigCommand.emit(LinkCommand(cmd, tuple(args), token))
        return token

    def open(self, url: str, baud_rate: int = BAUDRATE) -> int:
        return self.send(Cmd.OPEN, url, baud_rate)

    def close_link(self) -> int:
        self._jog_lease_timer.stop()
        return self.send(Cmd.CLOSE)

    def stop_now(self) -> int:
        """STOP: abandons a long operation at the next item and stops the axis."""
        self._jog_lease_timer.stop()
        self._abort.set()
        return self.send(Cmd.STOP)

    def jog_press(self, speed_rpm: float) -> int:
        self._jog_lease_timer.start()
        return self.send(Cmd.JOG, float(speed_rpm))

    def jog_release(self) -> int:
        self._jog_lease_timer.stop()
        return self.send(Cmd.JOG, 0.0)

    def shutdown(self, timeout_ms: int = 10000) -> bool:
        """Stops the axis, closes the port, ends the thread. True when the thread ended in time.

        Whatever the worker is doing (connecting to a silent or babbling line, a long read-out)
        gives up at its next read; only the port's own opening (a TCP connect: at most 5 s) and
        the final STOP (``transaction_limit_s``) can hold it, both well inside ``timeout_ms``."""
        self._jog_lease_timer.stop()
        if not self._thread.isRunning():
            return True
        self._closing.set()
        self._abort.set()
        self.sigCommand.emit(LinkCommand(Cmd.SHUTDOWN, (), 0))  # the worker quits its thread when done
        ended = self._thread.wait(timeout_ms)
        if not ended:
            self._thread.quit()
            ended = self._thread.wait(500)
        if not ended:
            log.error("the link thread did not end within %d ms", timeout_ms)
        return ended

    # -- from the worker -----------------------------------------------------------------------
    @Slot(object)
    def _on_connected(self, info: LinkInfo) -> None:
        self.info = info
        self.last_disconnect_reason = ""
        self.sigConnected.emit(info)

    @Slot(str, bool)
    def _on_disconnected(self, reason: str, lost: bool) -> None:
        self.info = None
        self.status = None
        self._jog_lease_timer.stop()
        self.last_disconnect_reason = reason
        self.sigDisconnected.emit(reason, lost)

    @Slot(object)
    def _on_status(self, status: DriveStatus) -> None:
        self.status = status
        self.sigStatus.emit(status)

    @Slot(object)
    def _on_result(self, result: CommandResult) -> None:
        if self._pending.pop(result.token, None) is not None and not self._pending:
            self.sigBusyChanged.emit(False)
        if result.cmd is Cmd.JOG and not result.ok:
            self._jog_lease_timer.stop()
        self.sigResult.emit(result)


__all__ = [  # the poll's figures and types re-exported: the pages know them from here
    "POLL_INTERVAL_MS",
    "PROBE_INTERVAL_MS",
    "SERVO_ON_NOTE",
    "SERVO_ON_PROBE_MS",
    "STATUS_MONITORS",
    "Cmd",
    "CommandResult",
    "DriveStatus",
    "LinkCommand",
    "LinkController",
    "LinkInfo",
    "LinkWorker",
    "NotConnected",
    "OpenClient",
    "PanelRefused",
    "ParameterReadout",
    "SimPanelAction",
    "WriteEntry",
]
