"""The drive link off the GUI thread: a worker QObject in its own QThread owns the DriveClient.

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

log = logging.getLogger(__name__)

#: Poll period of status, alarm, I/O and monitors while connected, in ms.
POLL_INTERVAL_MS = 100
#: Jog keep-alive period, in ms: the drive's watchdog stops the axis 100 ms after the last JOG.
JOG_KEEPALIVE_MS = 40
#: A held jog button renews its lease this often (GUI side), in ms ...
JOG_LEASE_RENEW_MS = 150
#: ... and the worker stops jogging if the lease is older than this (a frozen GUI must not
#: leave the axis running), in s.
JOG_LEASE_S = 0.5
#: Consecutive timeouts after which the link is declared lost (the client has retried already).
TIMEOUTS_TO_LOST = 1


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
    SET_INPUTS = enum.auto()  # args: bit mask (simulated drive only)
    CALL = enum.auto()  # args: a callable taking the client (for procedures of other pages)
    SET_POLL_INTERVAL = enum.auto()  # args: ms between status polls (the scope slows them while live)
    SHUTDOWN = enum.auto()  # stop the axis, close the port, end the link thread


@dataclass(frozen=True)
class LinkCommand:
    """One command for the worker. `token` ties the result to the request."""

    cmd: Cmd
    args: tuple = ()
    token: int = 0


@dataclass(frozen=True)
class CommandResult:
    """What came of one command: `value` on success, else `error` (one line for the user)."""

    token: int
    cmd: Cmd
    value: Any = None
    error: str | None = None
    error_kind: str | None = None  # the exception's class name, e.g. "ServoOnRefused"

    @property
    def ok(self) -> bool:
        return self.error is None


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


# I/O bits (docs/protocol.md, IOS)
IO_SERVO_ON = 0
IO_READY = 1
IO_ALARM = 2
IO_IN_POSITION = 3
IO_FWD_INHIBIT = 4
IO_REV_INHIBIT = 5
IO_ORIGIN = 6
IO_LIMIT_CCW = 7
IO_LIMIT_CW = 8
IO_BRAKE_RELEASED = 9
IO_CLEAR = 10
IO_MOVING = 15


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

    def bit(self, number: int) -> bool | None:
        return None if self.io_bits is None else bool(self.io_bits >> number & 1)

    @property
    def moving(self) -> bool:
        return bool(self.jogging or self.bit(IO_MOVING))


def _default_open(url: str, baud_rate: int):
    from fha_studio.hardware.client import DriveClient, LinkSettings

    # short timeouts: a dead link must show within a second (one retry of 0.25 s each)
    settings = LinkSettings(baudrate=baud_rate, response_timeout_s=0.25, retries=1)
    return DriveClient.open(url, settings)


def _error_kind(exc: BaseException) -> str:
    return type(exc).__name__


def _is_lost(exc: BaseException) -> bool:
    return _error_kind(exc) in {"LinkLost", "SerialException", "OSError", "BrokenPipeError"} or isinstance(
        exc, OSError
    )


def _is_timeout(exc: BaseException) -> bool:
    return _error_kind(exc) == "LinkTimeout" or isinstance(exc, TimeoutError)


def _is_refusal(exc: BaseException) -> bool:
    return _error_kind(exc) == "ServoOnRefused"


class LinkWorker(QObject):
    """Owns the DriveClient; lives in the link thread. Talk to it only through signals."""

    sigConnected = Signal(object)  # LinkInfo
    sigDisconnected = Signal(str, bool)  # reason, lost (True: the link died, not closed by us)
    sigStatus = Signal(object)  # DriveStatus
    sigResult = Signal(object)  # CommandResult
    sigWrite = Signal(object)  # one write, as a dict for the session log

    def __init__(self, abort: threading.Event, open_client: Callable[[str, int], Any] | None = None):
        super().__init__()
        self._abort = abort
        self._poll_interval_ms = POLL_INTERVAL_MS
        self._open_client = open_client or _default_open
        self._client = None
        self._url = ""
        self._poll_timer: QTimer | None = None
        self._jog_timer: QTimer | None = None
        self._jog_speed_rpm = 0.0
        self._jog_lease_s = 0.0
        self._timeouts = 0
        self._monitor_ok = True
        self._last_servo_on: bool | None = None

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

    @Slot(object)
    def handle(self, command: LinkCommand) -> None:
        if command.cmd is Cmd.SHUTDOWN:
            self._shutdown()
            return
        handler = getattr(self, f"_do_{command.cmd.name.lower()}")
        if command.cmd is Cmd.STOP:
            self._abort.clear()
        if command.cmd is not Cmd.OPEN and self._client is None:
            if command.cmd not in (Cmd.CLOSE, Cmd.STOP, Cmd.JOG, Cmd.JOG_LEASE):
                self._emit(command, error="not connected", kind="NotConnected")
            return
        try:
            value = handler(*command.args)
        except Exception as exc:
            if self._client is not None and (_is_lost(exc) or (_is_timeout(exc) and self._count_timeout())):
                self._emit(command, error=str(exc) or _error_kind(exc), kind=_error_kind(exc))
                self._lose(exc)
                return
            self._emit(command, error=str(exc) or _error_kind(exc), kind=_error_kind(exc))
            return
        self._timeouts = 0
        self._emit(command, value=value)

    def _emit(
        self, command: LinkCommand, value: Any = None, error: str | None = None, kind: str | None = None
    ):
        self.sigResult.emit(CommandResult(command.token, command.cmd, value, error, kind))

    def _count_timeout(self) -> bool:
        self._timeouts += 1
        return self._timeouts >= TIMEOUTS_TO_LOST

    def _lose(self, exc: BaseException) -> None:
        reason = f"link lost: {exc or _error_kind(exc)}"
        self._shut(stop_axis=False)
        self.sigDisconnected.emit(reason, True)

    def _shut(self, stop_axis: bool) -> None:
        if self._jog_timer is not None:
            self._jog_timer.stop()
        if self._poll_timer is not None:
            self._poll_timer.stop()
        self._jog_speed_rpm = 0.0
        client, self._client = self._client, None
        if client is None:
            return
        if stop_axis:
            try:
                client.stop()
            except Exception as exc:  # the port may already be gone; closing goes on
                log.info("stop on close failed: %s", exc)
        try:
            client.close()
        except Exception as exc:
            log.info("close failed: %s", exc)

    def _shutdown(self) -> None:
        """The last command: runs in the link thread, so the timers die in their own thread."""
        self._shut(stop_axis=True)
        for timer in (self._poll_timer, self._jog_timer):
            if timer is not None:
                timer.stop()
                timer.deleteLater()
        self._poll_timer = self._jog_timer = None
        _forget_dummy_thread()
        QThread.currentThread().quit()

    # -- commands -----------------------------------------------------------------------------
    def _do_open(self, url: str, baud_rate: int = 19200) -> LinkInfo:
        if self._client is not None:
            self._shut(stop_axis=True)
            self.sigDisconnected.emit("switched to another drive", False)
        self._client = self._open_client(url, baud_rate)
        self._url = url
        self._timeouts = 0
        self._monitor_ok = True
        self._last_servo_on = None
        info = self._describe(url)
        self.sigConnected.emit(info)
        assert self._poll_timer is not None
        self._poll_timer.start(0)
        return info

    def _describe(self, url: str) -> LinkInfo:
        client = self._client
        driver_model = adjusted_for = firmware = ""
        try:
            ident = client.identify()  # None on a drive without IDN
            driver_model = getattr(ident, "driver_model", "") or ""
            adjusted_for = getattr(ident, "adjusted_for", "") or ""
            firmware = getattr(ident, "firmware", "") or ""
        except Exception as exc:
            if _is_lost(exc):
                raise
            log.info("identify failed: %s", exc)
        caps = getattr(client, "capabilities", None)
        if callable(caps):
            caps = caps()
        describe = getattr(caps, "describe", None)
        text = describe() if callable(describe) else (str(caps) if caps is not None else "")
        return LinkInfo(
            url=url,
            driver_model=driver_model,
            adjusted_for=adjusted_for,
            firmware=firmware,
            capabilities=text,
            can_move=_capability(caps, ("JOG", "SVO"), "can_jog", True),
            can_monitor=_capability(caps, ("MON",), "can_monitor", True),
            can_parameters=bool(getattr(caps, "parameters", True)),
            is_simulated=bool(getattr(caps, "simulated", url.startswith("sim://"))),
        )

    def _do_close(self) -> None:
        was_open = self._client is not None
        self._shut(stop_axis=True)
        if was_open:
            self.sigDisconnected.emit("closed", False)

    def _do_identify(self) -> LinkInfo:
        return self._describe(self._url)

    def _do_read_parameters(self, items) -> dict:
        values: dict[tuple[str, int], int] = {}
        errors: dict[tuple[str, int], str] = {}
        for mode, number in items:
            if self._abort.is_set():
                errors[(mode, number)] = "stopped"
                continue
            try:
                values[(mode, number)] = self._client.read_parameter(mode, number)
            except Exception as exc:
                if _is_lost(exc) or _is_timeout(exc):
                    raise
                errors[(mode, number)] = str(exc) or _error_kind(exc)
        return {"values": values, "errors": errors}

    def _do_write_parameters(self, writes) -> list[dict]:
        """Writes one by one; each entry says old, new, verified (by read-back) or the error."""
        done: list[dict] = []
        for mode, number, value in writes:
            entry = {
                "time": time.time(),
                "mode": mode,
                "number": number,
                "new": value,
                "old": None,
                "read_back": None,
                "verified": False,
                "error": None,
            }
            if self._abort.is_set():
                entry["error"] = "not written: stopped"
                done.append(entry)
                self.sigWrite.emit(entry)
                continue
            try:
                result = self._client.write_parameter(mode, number, value)
                entry["old"] = _field(result, ("old", "old_value", "previous"))
                entry["read_back"] = _field(result, ("read_back", "value"))
                entry["verified"] = bool(_field(result, ("verified",)))
                entry["restart_required"] = bool(_field(result, ("needs_restart", "restart_required")))
                entry["message"] = _field(result, ("message",)) or ""
                if not entry["verified"]:
                    entry["error"] = _field(result, ("message", "error")) or "read-back differs"
            except Exception as exc:
                if _is_lost(exc) or _is_timeout(exc):
                    entry["error"] = str(exc) or _error_kind(exc)
                    self.sigWrite.emit(entry)
                    raise
                entry["error"] = str(exc) or _error_kind(exc)
            done.append(entry)
            self.sigWrite.emit(entry)
        return done

    def _do_servo(self, on: bool) -> bool:
        self._client.servo(bool(on))
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
        except Exception as exc:
            self._jog_speed_rpm = 0.0
            self._jog_timer.stop()
            self.sigResult.emit(
                CommandResult(0, Cmd.JOG, None, str(exc) or _error_kind(exc), _error_kind(exc))
            )
            if _is_lost(exc) or (_is_timeout(exc) and self._count_timeout()):
                self._lose(exc)

    def _do_set_move_speed(self, speed_rpm: float) -> float:
        self._client.set_move_speed(float(speed_rpm))
        return float(speed_rpm)

    def _do_move_by(self, angle_deg: float) -> float:
        self._client.move_by(float(angle_deg))
        return float(angle_deg)

    def _do_stop(self) -> None:
        self._jog_speed_rpm = 0.0
        if self._jog_timer is not None:
            self._jog_timer.stop()
        if self._client is not None:
            self._client.stop()

    def _do_clear_alarm(self) -> int:
        self._client.clear_alarm()
        return int(self._client.alarm())

    def _do_alarm_history(self) -> list:
        return list(self._client.alarm_history())

    def _do_power_cycle(self) -> None:
        self._client.power_cycle()

    def _do_set_inputs(self, inputs: dict) -> int:
        """Simulated CN2 inputs by name (fwd_inhibit=True, ...); the simulated drive only."""
        state = self._client.set_inputs(**inputs)
        return int(getattr(state, "raw", state))

    def _do_set_poll_interval(self, interval_ms: int) -> int:
        self._poll_interval_ms = max(POLL_INTERVAL_MS, int(interval_ms))
        return self._poll_interval_ms

    def _do_call(self, function: Callable[[Any], Any]) -> Any:
        return function(self._client)

    # -- polling ------------------------------------------------------------------------------
    @Slot()
    def _poll(self) -> None:
        client = self._client
        if client is None:
            return
        status = {"time_s": time.monotonic(), "jogging": bool(self._jog_speed_rpm)}
        try:
            try:
                status["alarm_code"] = int(client.alarm())
                bits = client.io_state()
                status["io_bits"] = int(getattr(bits, "raw", bits))
                status["servo_on"] = bool(status["io_bits"] & 1)
                if self._monitor_ok:
                    self._poll_monitors(client, status)
            except Exception as exc:
                if not _is_refusal(exc):
                    raise
                status["refused"] = True
                status["servo_on"] = True  # a real drive refuses CN3 commands while the servo is on
        except Exception as exc:
            if _is_lost(exc) or (_is_timeout(exc) and self._count_timeout()):
                self._lose(exc)
                return
            log.info("poll failed: %s", exc)
        else:
            self._timeouts = 0
        self.sigStatus.emit(DriveStatus(**status))
        if self._client is not None and self._poll_timer is not None:
            self._poll_timer.start(self._poll_interval_ms)

    def _poll_monitors(self, client, status: dict) -> None:
        """Output position (pulse), output speed (r/min) and motor current (A), scaled by the
        parameter model's monitor items (100, 103, 104)."""
        items = (100, 103, 104)
        try:
            reader = getattr(client, "read_monitors", None)
            values = reader(items) if reader else {i: client.read_monitor(i) for i in items}
        except Exception as exc:
            if _is_lost(exc) or _is_timeout(exc) or _is_refusal(exc):
                raise
            self._monitor_ok = False  # a drive without the monitor extension: stop asking
            log.info("monitors not available: %s", exc)
            return
        model = getattr(client, "model", None)

        def scaled(number: int) -> float | None:
            wire = values.get(number)
            if wire is None:
                return None
            try:
                return model.item("monitor", number).to_unit(wire) if model is not None else float(wire)
            except (KeyError, ValueError):
                return float(wire)

        position = values.get(100)
        status["position_pulse"] = None if position is None else int(position)
        status["speed_rpm"] = scaled(103)
        status["current_a"] = scaled(104)


def _forget_dummy_thread() -> None:
    """Python registers a QThread as a "_DummyThread" the first time code in it asks for the
    current thread (threading.Thread() does, to inherit daemon); Python < 3.12 never removes such
    entries, so the ended link thread would look alive forever. Called in the thread, at its end."""
    current = threading.current_thread()
    if isinstance(current, threading._DummyThread):
        with threading._active_limbo_lock:
            threading._active.pop(threading.get_ident(), None)


def _field(obj: Any, names: tuple[str, ...]) -> Any:
    for name in names:
        if isinstance(obj, dict) and name in obj:
            return obj[name]
        if hasattr(obj, name):
            return getattr(obj, name)
    return None


def _capability(caps: Any, commands: tuple[str, ...], attribute: str, default: bool) -> bool:
    if caps is None:
        return default
    if hasattr(caps, attribute):
        return bool(getattr(caps, attribute))
    supported = getattr(caps, "commands", None) or getattr(caps, "supported", None)
    if supported is not None:
        names = {getattr(c, "value", c) for c in supported}
        return all(c in names for c in commands)
    return default


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

    def __init__(self, parent: QObject | None = None, open_client=None):
        super().__init__(parent)
        self._tokens = itertools.count(1)
        self._abort = threading.Event()
        self._thread = QThread()
        self._thread.setObjectName("fha-link")
        self._worker = LinkWorker(self._abort, open_client)
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

    def open(self, url: str, baud_rate: int = 19200) -> int:
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

    def shutdown(self, timeout_ms: int = 3000) -> bool:
        """Stops the axis, closes the port, ends the thread. True when the thread ended in time."""
        self._jog_lease_timer.stop()
        if not self._thread.isRunning():
            return True
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


__all__ = [
    "Cmd",
    "CommandResult",
    "DriveStatus",
    "LinkCommand",
    "LinkController",
    "LinkInfo",
    "LinkWorker",
]
