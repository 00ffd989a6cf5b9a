"""The drive link off the GUI thread: a worker QObject in its own QThread owns the drive (a DriveApi).

PyMoDAQ's pattern: requests go in through one queued signal carrying a small frozen dataclass
(``link_requests``: one per request, each saying what its reply carries); the reply goes back to
whoever sent the request, status comes out through signals. Qudi's polling loop: a single-shot
QTimer re-armed at the end of each pass, so passes never overlap; the pass itself is
``logic.drive_session.StatusPoller``, without Qt.

The GUI thread never waits on the port. The only thing it shares with the worker directly is a
`threading.Event` that asks a long operation (read all, write all) to give up between items, so
that a STOP is not queued behind it.
"""

from __future__ import annotations

import itertools
import logging
import threading
import time
from collections.abc import Callable
from typing import Any, TypeVar

from PySide6.QtCore import QObject, QThread, QTimer, Signal, Slot

from fha_studio.gui.link_requests import (
    REQUESTS,
    Call,
    ClearAlarm,
    Close,
    Identify,
    Jog,
    JogLease,
    LinkInfo,
    LinkReply,
    LinkRequest,
    MoveBy,
    NotConnected,
    OnReply,
    Open,
    PanelRefused,
    PowerCycle,
    ReadAlarmHistory,
    ReadParameters,
    Sent,
    Servo,
    SetInputs,
    SetMoveSpeed,
    SetPollInterval,
    Shutdown,
    SimPanelAction,
    SimPanelRequest,
    Stop,
    WriteParameters,
)
from fha_studio.hardware.api import AlarmRecord, DriveApi, LinkError, LinkLost, SimPanel
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
    ParameterReadout,
    StatusPoller,
    WriteEntry,
    failure_text,
    read_parameters,
    write_parameters,
)

log = logging.getLogger(__name__)
R = TypeVar("R")

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
    sigResult = Signal(object)  # LinkReply
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
        #: What each request runs (every one of link_requests.REQUESTS has one; a test checks it).
        self.handlers: dict[type[LinkRequest[Any]], Callable[[Any], Any]] = {
            Open: self._do_open,
            Close: self._do_close,
            Identify: self._do_identify,
            ReadParameters: self._do_read_parameters,
            WriteParameters: self._do_write_parameters,
            Servo: self._do_servo,
            Jog: self._do_jog,
            JogLease: self._do_jog_lease,
            SetMoveSpeed: self._do_set_move_speed,
            MoveBy: self._do_move_by,
            Stop: self._do_stop,
            ClearAlarm: self._do_clear_alarm,
            ReadAlarmHistory: self._do_alarm_history,
            PowerCycle: self._do_power_cycle,
            SetInputs: self._do_set_inputs,
            Call: self._do_call,
            SimPanelRequest: self._do_sim_panel,
            SetPollInterval: self._do_set_poll_interval,
            Shutdown: self._shutdown,
        }
        assert set(self.handlers) == set(REQUESTS)

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
    def handle(self, sent: Sent[Any]) -> None:
        request = sent.request
        handler = self.handlers[type(request)]
        if isinstance(request, Shutdown):
            handler(request)
            return
        if isinstance(request, Stop):
            self._abort.clear()
        if self._client is None and request.needs_link:
            self._reply(sent, error=NotConnected("not connected"))
            return
        try:
            value = handler(request)
        except Exception as exc:
            self._reply(sent, error=exc)
            if self._client is not None and isinstance(exc, LinkLost):
                self._lose(exc)
            return
        self._reply(sent, value=value)

    def _reply(self, sent: Sent[Any], value: Any = None, error: Exception | None = None) -> None:
        if error is None:
            self.sigResult.emit(LinkReply(sent.token, sent.request, value))
        else:
            self.sigResult.emit(LinkReply(sent.token, sent.request, None, _message(error), type(error)))

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

    def _shutdown(self, _: Shutdown) -> None:
        """The last request: runs in the link thread, so the timers die in their own thread."""
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

    # -- requests -----------------------------------------------------------------------------
    def _do_open(self, request: Open) -> LinkInfo:
        url = request.url
        if self._client is not None:
            self._shut(stop_axis=True)
            self.sigDisconnected.emit("switched to another drive", False)
        self._client = self._open_client(url, request.baud_rate)
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
            capabilities_summary=caps.summary(),
            can_move=caps.can_move,
            can_monitor=caps.can_monitor,
            can_parameters=caps.parameters,
            is_simulated=caps.simulated,
            documented_only=not extensions,
            absolute_position=caps.absolute_position,
            embedded_sim=_embedded_sim(client) is not None,
        )

    def _do_close(self, _: Close) -> None:
        was_open = self._client is not None
        self._shut(stop_axis=True)
        if was_open:
            self.sigDisconnected.emit("closed", False)

    def _do_identify(self, _: Identify) -> LinkInfo:
        return self._describe(self._url)

    def _do_read_parameters(self, request: ReadParameters) -> ParameterReadout:
        return read_parameters(self.client, request.items, self._abort.is_set)

    def _do_write_parameters(self, request: WriteParameters) -> list[WriteEntry]:
        """Writes one by one; each entry says old, new, verified (by read-back) or the error."""
        return write_parameters(self.client, request.writes, self._abort.is_set, self.sigWrite.emit)

    def _do_servo(self, request: Servo) -> bool:
        self.client.servo(bool(request.on))
        return bool(request.on)

    def _do_jog(self, request: Jog) -> float:
        speed_rpm = float(request.speed_rpm)
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

    def _do_jog_lease(self, _: JogLease) -> None:
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
            self.handle(Sent(0, Jog(0.0)))
            return
        try:
            self._client.jog(self._jog_speed_rpm)
        except (LinkError, ValueError) as exc:
            speed_rpm, self._jog_speed_rpm = self._jog_speed_rpm, 0.0
            self._jog_timer.stop()
            self._reply(Sent(0, Jog(speed_rpm)), error=exc)  # to whoever holds the jog
            if isinstance(exc, LinkLost):
                self._lose(exc)

    def _do_set_move_speed(self, request: SetMoveSpeed) -> float:
        self.client.set_move_speed(float(request.speed_rpm))
        return float(request.speed_rpm)

    def _do_move_by(self, request: MoveBy) -> float:
        self.client.move_by(float(request.angle_deg))
        return float(request.angle_deg)

    def _do_stop(self, _: Stop) -> None:
        self._jog_speed_rpm = 0.0
        if self._jog_timer is not None:
            self._jog_timer.stop()
        if self._client is not None:
            self._client.stop()

    def _do_clear_alarm(self, _: ClearAlarm) -> int:
        self.client.clear_alarm()
        return self.client.alarm()

    def _do_alarm_history(self, _: ReadAlarmHistory) -> list[AlarmRecord]:
        return self.client.alarm_history()

    def _do_power_cycle(self, _: PowerCycle) -> None:
        self.client.power_cycle()

    def _do_set_inputs(self, request: SetInputs) -> int:
        """Simulated CN2 inputs by name (fwd_inhibit=True, ...); the simulated drive only."""
        return self.client.set_inputs(**request.inputs).raw

    def _do_set_poll_interval(self, request: SetPollInterval) -> int:
        self._poll_interval_ms = max(POLL_INTERVAL_MS, int(request.interval_ms))
        if self._poller is not None:
            self._poller.set_interval(self._poll_interval_ms)
        return self._poll_interval_ms

    def _do_call(self, request: Call[Any]) -> Any:
        return request.function(self.client)

    def _do_sim_panel(self, request: SimPanelRequest) -> str:
        """Do what the embedded simulated drive's panel asks; one line saying what happened."""
        sim = _embedded_sim(self.client)
        if sim is None:
            raise NotConnected("this is not an embedded simulated drive: it has no panel")
        from fha_studio.hardware.sim import SimRefused

        action, value = request.action, request.value

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


def end_worker_thread(worker: QObject) -> None:
    """Called in a worker's thread at its end (its stop slot): Python forgets the thread, and the
    thread's event loop quits."""
    _forget_dummy_thread()
    thread = worker.thread()
    if thread is not None:
        thread.quit()


class LinkController(QObject):
    """The GUI-thread face of the link: sends requests (each reply to its sender), re-emits what
    the worker says, and keeps the last known state for the pages. Never blocks."""

    sigCommand = Signal(object)  # Sent: a request, queued into the worker
    sigConnected = Signal(object)  # LinkInfo
    sigDisconnected = Signal(str, bool)
    sigStatus = Signal(object)  # DriveStatus
    #: Every LinkReply, for the one observer of them all (the window's message area); a request's
    #: sender gets its own reply through ``send(request, on_reply)``.
    sigResult = Signal(object)
    sigWrite = Signal(object)  # WriteEntry: one parameter write, for the session log
    sigBusyChanged = Signal(bool)
    #: The drive's control power was cycled (whoever asked): restart-required items are in effect.
    sigPowerCycled = Signal()
    #: A STOP was answered (whoever pressed it): its LinkReply.
    sigStopped = Signal(object)

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
        self._pending: set[int] = set()
        self._on_reply: dict[int, OnReply[Any]] = {}
        self._jog_owner: OnReply[float] | None = None
        self._jog_lease_timer = QTimer(self)
        self._jog_lease_timer.setInterval(JOG_LEASE_RENEW_MS)
        self._jog_lease_timer.timeout.connect(lambda: self.send(JogLease()))
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

    # -- requests ------------------------------------------------------------------------------
    def send(self, request: LinkRequest[R], on_reply: OnReply[R] | None = None) -> int:
        """Queue ``request`` into the link thread; its reply goes to ``on_reply`` (and to the
        observer, ``sigResult``). Returns the request's token."""
        token = next(self._tokens)
        if request.counts_as_busy:
            was_busy = self.busy
            self._pending.add(token)
            if not was_busy:
                self.sigBusyChanged.emit(True)
        if on_reply is not None:
            self._on_reply[token] = on_reply
        self.sigCommand.emit(Sent(token, request))
        return token

    def open(self, url: str, baud_rate: int = BAUDRATE) -> int:
        return self.send(Open(url, baud_rate))

    def close_link(self) -> int:
        self._let_go_of_jog()
        return self.send(Close())

    def stop_now(self) -> int:
        """STOP: abandons a long operation at the next item and stops the axis."""
        self._let_go_of_jog()
        self._abort.set()
        return self.send(Stop())

    def jog_press(self, speed_rpm: float, on_reply: OnReply[float] | None = None) -> int:
        """Jog while held (the lease is renewed until ``jog_release``). ``on_reply`` gets the
        jog's reply, and a failure of the worker's renewal of it later."""
        self._jog_lease_timer.start()
        self._jog_owner = on_reply
        return self.send(Jog(float(speed_rpm)), on_reply)

    def jog_release(self) -> int:
        self._let_go_of_jog()
        return self.send(Jog(0.0))

    def _let_go_of_jog(self) -> None:
        self._jog_lease_timer.stop()
        self._jog_owner = None

    def shutdown(self, timeout_ms: int = 10000) -> bool:
        """Stops the axis, closes the port, ends the thread. True when the thread ended in time.

        Whatever the worker is doing (connecting to a silent or babbling line, a long read-out)
        gives up at its next read; only the port's own opening (a TCP connect: at most 5 s) and
        the final STOP (``transaction_limit_s``) can hold it, both well inside ``timeout_ms``."""
        self._let_go_of_jog()
        if not self._thread.isRunning():
            return True
        self._closing.set()
        self._abort.set()
        self.sigCommand.emit(Sent(0, Shutdown()))  # the worker quits its thread when done
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
        self._let_go_of_jog()
        self.last_disconnect_reason = reason
        self.sigDisconnected.emit(reason, lost)

    @Slot(object)
    def _on_status(self, status: DriveStatus) -> None:
        self.status = status
        self.sigStatus.emit(status)

    @Slot(object)
    def _on_result(self, reply: LinkReply[Any]) -> None:
        request = reply.request
        if reply.token in self._pending:
            self._pending.discard(reply.token)
            if not self._pending:
                self.sigBusyChanged.emit(False)
        on_reply = self._on_reply.pop(reply.token, None)
        if isinstance(request, Jog) and not reply.ok:
            if reply.token == 0:  # the worker's renewal of a held jog failed: to the jog's sender
                on_reply = self._jog_owner
            self._let_go_of_jog()
        if on_reply is not None:
            on_reply(reply)
        if isinstance(request, PowerCycle) and reply.ok:
            self.sigPowerCycled.emit()
        elif isinstance(request, Stop):
            self.sigStopped.emit(reply)
        self.sigResult.emit(reply)


__all__ = [  # the poll's figures and the message types re-exported: the pages know them from here
    "POLL_INTERVAL_MS",
    "PROBE_INTERVAL_MS",
    "SERVO_ON_NOTE",
    "SERVO_ON_PROBE_MS",
    "STATUS_MONITORS",
    "Call",
    "ClearAlarm",
    "Close",
    "DriveStatus",
    "Identify",
    "Jog",
    "JogLease",
    "LinkController",
    "LinkInfo",
    "LinkReply",
    "LinkRequest",
    "LinkWorker",
    "MoveBy",
    "NotConnected",
    "OnReply",
    "Open",
    "OpenClient",
    "PanelRefused",
    "ParameterReadout",
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
    "WriteEntry",
    "WriteParameters",
]
