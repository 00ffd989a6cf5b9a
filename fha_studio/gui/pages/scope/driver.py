"""The scope's acquisition driver: a QObject that lives in the link thread and uses its client.

It never opens a port. It is moved to the thread of the link worker that owns the
``DriveClient`` and is given that client (``ScopeController.attach``), so every exchange runs
in the link thread, interleaved with the worker's own commands (a STOP waits at most one
polling pass, ``PASS_BUDGET_S``). Requests come in through one queued signal carrying a
``ScopeRequest``; results go out through signals. Samples go into the acquisition's
``RingBuffer``, which the GUI timer drains (friture's pattern). The link thread never waits for
the GUI: no signal per sample (the state goes out five times a second, a read-out's progress once
a block), and the ring's lock is held only to copy rows in or out, never while the GUI draws.
"""

from __future__ import annotations

import enum
import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from PySide6.QtCore import QObject, QThread, QTimer, Signal, Slot

from fha_studio.hardware.api import DriveApi
from fha_studio.hardware.errors import LinkError, ReadAborted
from fha_studio.hardware.protocol import BAUDRATE, TraceState
from fha_studio.logic.scope.acquisition import (
    LiveMode,
    LiveStatus,
    MoveTest,
    PollingAcquisition,
    ScopeConfig,
    TraceAcquisition,
    TraceSettings,
    load_scope_config,
)

log = logging.getLogger(__name__)

#: Longest time one polling pass holds the link thread [s]: 0 = one sample per pass, so the
#: worker's queued commands (a JOG keep-alive, a STOP) wait at most one exchange (~20 ms).
PASS_BUDGET_S = 0.0
#: Shortest polling pass [s]. A drive in this process (the unpaced simulated drive) answers in
#: microseconds, and a link thread polling it back to back holds Python's GIL almost all the time:
#: the GUI thread then waits ~5 ms for every call into Python and a frame takes seconds. A pass
#: shorter than this waits out the rest; a real line (a few ms per exchange) never waits.
MIN_PASS_S = 0.002
#: How often the state goes out to the GUI [s].
STATUS_INTERVAL_S = 0.2
#: Period of the trace-status and move-test steps [ms].
STEP_INTERVAL_MS = 20


class ScopeCmd(enum.Enum):
    SET_CLIENT = enum.auto()  # args: client or None, ratio (int | None)
    SET_RATIO = enum.auto()  # args: ratio (int | None): the actuator on the axis changed
    START = enum.auto()  # args: channels (sequence of ScopeChannel), capacity
    STOP = enum.auto()
    ARM_TRACE = enum.auto()  # args: TraceSettings
    CANCEL_TRACE = enum.auto()
    RUN_TEST = enum.auto()  # args: MoveTest keyword arguments (dict)
    ABORT_TEST = enum.auto()
    CALL = enum.auto()  # args: callable(client) -> value, for a one-off exchange (e.g. jog in tests)
    SHUTDOWN = enum.auto()  # args: quit_thread (bool): stop everything, delete the driver in its thread


@dataclass(frozen=True)
class ScopeRequest:
    cmd: ScopeCmd
    args: tuple = ()


@dataclass(frozen=True)
class LiveStarted:
    """A live acquisition started: its channels (what each ring column is) and the ring."""

    mode: LiveMode
    channels: tuple
    ring: Any  # RingBuffer: rows [t_s, values...]
    t0: float  # host clock (time.monotonic) of t_s = 0


class ScopeDriver(QObject):
    """Runs polling, trace capture and the move test in the thread it lives in."""

    sigLiveStarted = Signal(object)  # LiveStarted
    sigStatus = Signal(object)  # LiveStatus
    sigTraceState = Signal(str)  # a sentence: armed, capturing n, reading out ..., done
    sigTraceDone = Signal(object)  # TraceResult
    sigTestDone = Signal(object)  # MoveTestResult
    sigTestState = Signal(str)  # what the running test is doing
    sigError = Signal(str)
    sigCallDone = Signal(object)  # the value of a CALL
    #: a trace read-out: samples read, samples in all, seconds left (< 0: not known yet)
    sigReadoutProgress = Signal(int, int, float)

    def __init__(self, config: ScopeConfig | None = None, abort: threading.Event | None = None):
        super().__init__()
        self.config = config or load_scope_config()
        # The link's STOP event (set in the GUI thread before the STOP is queued): a trace
        # read-out gives up between blocks when it is set, so the STOP does not wait behind it.
        self._should_abort = abort.is_set if abort is not None else None
        self._client: DriveApi | None = None
        self._ratio: int | None = None
        self._poller: PollingAcquisition | None = None
        self._trace: TraceAcquisition | None = None
        self._test: MoveTest | None = None
        self._poll_timer: QTimer | None = None
        self._step_timer: QTimer | None = None
        self._last_status = 0.0
        self._paused_for_test = False
        self._readout_started = 0.0
        #: What each request runs (every ScopeCmd has one; a test checks it).
        self.handlers: dict[ScopeCmd, Callable[..., None]] = {
            ScopeCmd.SET_CLIENT: self._do_set_client,
            ScopeCmd.SET_RATIO: self._do_set_ratio,
            ScopeCmd.START: self._do_start,
            ScopeCmd.STOP: self._do_stop,
            ScopeCmd.ARM_TRACE: self._do_arm_trace,
            ScopeCmd.CANCEL_TRACE: self._do_cancel_trace,
            ScopeCmd.RUN_TEST: self._do_run_test,
            ScopeCmd.ABORT_TEST: self._do_abort_test,
            ScopeCmd.CALL: self._do_call,
            ScopeCmd.SHUTDOWN: self._do_shutdown,
        }

    def _timers(self) -> None:
        # Timers are made on first use, so they belong to the thread the driver lives in.
        if self._poll_timer is None:
            self._poll_timer = QTimer(self)
            self._poll_timer.setSingleShot(True)
            self._poll_timer.timeout.connect(self._poll)
            self._step_timer = QTimer(self)
            self._step_timer.setInterval(STEP_INTERVAL_MS)
            self._step_timer.timeout.connect(self._step)

    @Slot(object)
    def handle(self, request: ScopeRequest) -> None:
        self._timers()
        try:
            self.handlers[request.cmd](*request.args)
        except (LinkError, ValueError) as exc:
            self.sigError.emit(str(exc))

    # -- commands -------------------------------------------------------------------------------
    def _do_set_client(self, client: DriveApi | None, ratio: int | None = None) -> None:
        self._do_stop()
        self._abort_test("the drive was disconnected")
        self._trace = None
        self._client, self._ratio = client, ratio

    def _do_set_ratio(self, ratio: int | None) -> None:
        # the next START scales DGR counts with it; a running acquisition was stopped by the view
        self._ratio = ratio

    def _do_start(self, channels, capacity: int = 65536) -> None:
        if self._client is None:
            raise ValueError("not connected to a drive")
        self._poller = PollingAcquisition(self._client, channels, ratio=self._ratio, capacity=capacity,
                                          config=self.config)
        p = self._poller
        self.sigLiveStarted.emit(LiveStarted(p.mode, tuple(p.channels), p.ring, p.t0))
        self._last_status = 0.0
        self._poll_timer.start(0)

    def _do_stop(self) -> None:
        if self._poll_timer is not None:
            self._poll_timer.stop()
        self._poller = None

    def _do_arm_trace(self, settings: TraceSettings) -> None:
        if self._client is None:
            raise ValueError("not connected to a drive")
        trace = TraceAcquisition(self._client, self.config)
        ok, why = trace.available()
        if not ok:
            raise ValueError(why)
        trace.configure(settings)
        trace.arm()
        self._trace = trace
        self.sigTraceState.emit(f"armed: {settings.trigger.describe()}, {settings.samples} samples at "
                                f"{trace.actual_rate_hz(settings):g} Hz")
        self._step_timer.start()

    def _do_cancel_trace(self) -> None:
        if self._trace is not None:
            self._trace = None
            self.sigTraceState.emit("cancelled")

    def _do_run_test(self, kwargs: dict) -> None:
        if self._client is None:
            raise ValueError("not connected to a drive")
        if self._test is not None:
            raise ValueError("a test is already running")
        self._test = MoveTest(self._client, config=self.config, should_abort=self._should_abort,
                              progress=self._report_progress, **kwargs)
        if not self._test.use_trace and self._poller is not None:
            self._paused_for_test = True  # the test polls itself: give it the whole line
            self._poll_timer.stop()
        self._step_timer.start()

    def _do_abort_test(self) -> None:
        self._abort_test("stopped by the user")

    def _do_shutdown(self, quit_thread: bool) -> None:
        self._do_set_client(None)
        for timer in (self._poll_timer, self._step_timer):
            timer.stop()
        self.deleteLater()  # timers die in the thread they belong to
        if quit_thread:
            self.thread().quit()

    def _do_call(self, function: Callable[[DriveApi | None], Any]) -> None:
        self.sigCallDone.emit(function(self._client))

    def _report_progress(self, done: int, total: int) -> None:
        """A trace read-out's progress (runs in the link thread, between blocks): out to the GUI
        with the time left at the rate of the blocks so far."""
        now = time.monotonic()
        if done == 0:
            self._readout_started = now
            left = -1.0
        else:
            left = (now - self._readout_started) / done * (total - done)
        self.sigReadoutProgress.emit(done, total, left)

    def _abort_test(self, why: str) -> None:
        test = self._test
        if test is not None:
            test.abort(why)
            self._test_finished()

    # -- timers ---------------------------------------------------------------------------------
    @Slot()
    def _poll(self) -> None:
        p = self._poller
        if p is None:
            return
        started = time.monotonic()
        p.step(PASS_BUDGET_S)
        now = time.monotonic()
        status = p.status(now)
        if now - self._last_status >= STATUS_INTERVAL_S:
            self._last_status = now
            self.sigStatus.emit(status)
        if p.mode is LiveMode.NONE or p.lost:
            self.sigStatus.emit(status)
            return
        # back to back while samples come (a pass of at least MIN_PASS_S); a slow retry while the
        # drive refuses or is silent
        if not p.answering:
            self._poll_timer.start(int(p.retry_interval_s * 1000))
            return
        rest_s = MIN_PASS_S - (now - started)
        self._poll_timer.start(0 if rest_s <= 0 else max(1, round(rest_s * 1000)))

    @Slot()
    def _step(self) -> None:
        try:
            if self._test is not None:
                before = self._test.state_text
                if self._test.step():
                    self._test_finished()
                elif self._test.state_text != before:
                    self.sigTestState.emit(self._test.state_text)
            if self._trace is not None:
                self._step_trace()
        except LinkError as exc:
            self._trace = None
            self.sigError.emit(str(exc))
        if self._test is None and self._trace is None:
            self._step_timer.stop()

    def _step_trace(self) -> None:
        trace = self._trace
        status = trace.status()
        if status.state is TraceState.DONE:
            seconds = trace.readout_estimate_s(status.count)
            self.sigTraceState.emit(f"reading out {status.count} samples (about {seconds:.0f} s at "
                                    f"{BAUDRATE} bit/s)")
            self._trace = None
            try:
                result = trace.read(self._should_abort, self._report_progress)
            except ReadAborted as exc:
                self.sigTraceState.emit(f"abandoned by STOP during the read-out ({exc.done} of {exc.total} "
                                        "samples read, none shown); arm again to capture")
                return
            self.sigTraceDone.emit(result)
            self.sigTraceState.emit(f"done: {len(result.t_s)} samples at {result.sample_rate_hz:g} Hz")
        elif status.state is TraceState.ARMED and trace.ready_for_trigger(status):
            self.sigTraceState.emit(f"armed, waiting for the trigger ({status.count} pre-trigger samples)")
        else:
            self.sigTraceState.emit(f"{status.state.name.lower()}: {status.count} samples")

    def _test_finished(self) -> None:
        test, self._test = self._test, None
        if self._paused_for_test and self._poller is not None:
            self._poll_timer.start(0)
        self._paused_for_test = False
        self.sigTestDone.emit(test.result)


class ScopeController(QObject):
    """The GUI-thread face of the driver: sends requests, re-emits results; never blocks.

    ``thread``: the link worker's QThread (the driver is moved there). Without one, the
    controller starts its own (tests, or before the main window provides its link thread).
    ``abort``: the link's STOP event (``LinkController.abort_event``); a trace read-out gives up
    between blocks when it is set.
    """

    sigRequest = Signal(object)
    # the driver's signals, re-emitted in the GUI thread
    sigLiveStarted = Signal(object)
    sigStatus = Signal(object)
    sigTraceState = Signal(str)
    sigTraceDone = Signal(object)
    sigTestDone = Signal(object)
    sigTestState = Signal(str)
    sigError = Signal(str)
    sigCallDone = Signal(object)
    sigReadoutProgress = Signal(int, int, float)

    def __init__(self, thread: QThread | None = None, parent: QObject | None = None,
                 config: ScopeConfig | None = None, abort: threading.Event | None = None):
        super().__init__(parent)
        self._own_thread = thread is None
        if thread is None:
            thread = QThread()
            thread.setObjectName("fha-scope")
            thread.start()
        self.link_thread = thread
        self.driver = ScopeDriver(config, abort)
        self.driver.moveToThread(thread)
        self.sigRequest.connect(self.driver.handle)
        driver = self.driver
        for theirs, ours in (
            (driver.sigLiveStarted, self.sigLiveStarted), (driver.sigStatus, self.sigStatus),
            (driver.sigTraceState, self.sigTraceState), (driver.sigTraceDone, self.sigTraceDone),
            (driver.sigTestDone, self.sigTestDone), (driver.sigTestState, self.sigTestState),
            (driver.sigError, self.sigError), (driver.sigCallDone, self.sigCallDone),
            (driver.sigReadoutProgress, self.sigReadoutProgress),
        ):
            theirs.connect(ours)  # queued: into this thread
        self.connected = False
        self._shut = False

    def send(self, cmd: ScopeCmd, *args) -> None:
        self.sigRequest.emit(ScopeRequest(cmd, tuple(args)))

    def attach(self, client: DriveApi | None, ratio: int | None = None) -> None:
        """Hand the driver a client (it uses it only in its thread); None detaches."""
        self.connected = client is not None
        self.send(ScopeCmd.SET_CLIENT, client, ratio)

    def set_ratio(self, ratio: int | None) -> None:
        """The actuator's ratio (None = not known), for scaling DGR counts from the next start."""
        self.send(ScopeCmd.SET_RATIO, ratio)

    def shutdown(self, timeout_ms: int = 3000) -> bool:
        """Stop acquiring and delete the driver in its thread; end the thread when it is the
        controller's own (True when it ended in time)."""
        if self._shut:
            return True
        self._shut = True
        self.send(ScopeCmd.SHUTDOWN, self._own_thread)
        if not self._own_thread:
            return True
        ended = self.link_thread.wait(timeout_ms)
        if not ended:
            log.error("the scope thread did not end within %d ms", timeout_ms)
        return ended


__all__ = ["LiveStarted", "LiveStatus", "ScopeCmd", "ScopeController", "ScopeDriver", "ScopeRequest"]
