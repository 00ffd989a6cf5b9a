"""How the scope gets its samples, and how honestly it says what it has. No Qt.

Two paths through the same view (docs/protocol.md):

- ``PollingAcquisition``: one ``MMR`` per sample for the selected monitor items, as fast as the
  line allows, time-stamped on the host (midpoint of request and reply), rows
  ``[t_s, values...]`` pushed into a ``RingBuffer``. The line is the bound: 10 request
  characters plus the reply's characters at 10 bits each at 19200 bit/s
  (``sample_line_time_s``); ``theoretical_rate_hz`` is that bound for the values just read.
  A drive that speaks only the documented commands gets position by ``DGR`` (servo off only);
  its ``s`` while the servo is on makes the state "not live" with the reason, never stale data.
- ``TraceAcquisition``: the drive samples up to 4 monitor items at the servo rate / divider,
  with a trigger (level, I/O bit edge, alarm) and pre-trigger; read out in 64-sample blocks.

The trace capture is trace.py, the configuration and the line's budget budget.py; their names
are taken from here too.

``MoveTest`` commands a move (or a step: a short move at the highest acceleration) and captures
it with a trace when the drive has one, else by polling; then computes ``move_metrics``. It is
stepped (``step()`` from a timer), so the link thread never blocks for the length of a move.

Every call here talks to the drive: run it in the link thread, never in a GUI thread.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from enum import Enum

import numpy as np

from fha_studio import clock
from fha_studio.hardware import protocol as p
from fha_studio.hardware.api import Capabilities, CapabilityLevel, DriveApi
from fha_studio.hardware.errors import (
    CommandNotSupported,
    CommandRejected,
    DriveRefused,
    LinkError,
    LinkLost,
    LinkTimeout,
    ReadAborted,
    ServoOnRefused,
)
from fha_studio.logic.scope.analysis import MoveMetrics, move_metrics
from fha_studio.logic.scope.budget import (
    READOUT_CHARS_PER_VALUE,
    ScopeConfig,
    dgr_line_time_s,
    estimated_rate_hz,
    load_scope_config,
    mmr_reply_chars,
    readout_time_s,
    sample_line_time_s,
    theoretical_rate_hz,
)
from fha_studio.logic.scope.channels import IO_STATE_ITEM, ScopeChannel, items_to_poll
from fha_studio.logic.scope.ring import RingBuffer
from fha_studio.logic.scope.trace import TraceAcquisition, TraceResult, TraceSettings, Trigger, convert_rows

#: Monitor items of the channels the move test captures (feedback, command, speed, current).
FEEDBACK_KEY = "feedback_position"
COMMAND_KEY = "command_position"
DGR_ITEM = -1  # the pseudo monitor item of the DGR position channel


# --- live state ------------------------------------------------------------------------------------


class LiveMode(Enum):
    MONITORS = "monitors"  # monitor items, polled (MMR, or MON one by one)
    POSITION = "position"  # DGR only: a drive of the manual's command set, servo off
    NONE = "none"  # nothing to read


@dataclass(frozen=True)
class LiveStatus:
    """What the view may claim. ``live`` is False whenever the newest sample is not current."""

    live: bool
    reason: str  # why not live ("" when live)
    mode: LiveMode
    samples: int
    rate_hz: float  # measured over the last seconds
    limit_hz: float  # the line's bound for the current replies
    dropped: int
    age_s: float | None  # time since the newest sample (None: no sample yet)

    @property
    def label(self) -> str:
        if self.live and self.mode is LiveMode.POSITION:
            return "LIVE: position only (DGR, servo off)"
        return "LIVE" if self.live else f"NOT LIVE: {self.reason}"


def dgr_channel(ratio: int) -> ScopeChannel:
    """Output position from DGR (motor encoder counts, ``protocol.ABSOLUTE_COUNTS_PER_TURN`` per
    motor turn; physical sense, CW from the flange up)."""
    return ScopeChannel(FEEDBACK_KEY, "Position (DGR, absolute encoder)", "deg", DGR_ITEM,
                        360.0 / (p.ABSOLUTE_COUNTS_PER_TURN * ratio))


def plan_live(capabilities: Capabilities, channels: Sequence[ScopeChannel], ratio: int | None,
              config: ScopeConfig) -> tuple[LiveMode, list[ScopeChannel], str]:
    """(mode, the channels that mode delivers, a sentence for the user when it is not monitors)."""
    level = capabilities.level
    if level in (CapabilityLevel.TRACE, CapabilityLevel.POLLING):
        return LiveMode.MONITORS, list(channels), ""
    if level is CapabilityLevel.ABSOLUTE_POSITION and ratio:
        return (LiveMode.POSITION, [dgr_channel(ratio)],
                "this drive answers only the documented commands: position by DGR, with the servo off; "
                "no speed, current or I/O")
    if level is CapabilityLevel.ABSOLUTE_POSITION:
        return LiveMode.NONE, [], "this drive answers only DGR, and the actuator's ratio is not known"
    return LiveMode.NONE, [], "this drive offers nothing to read (no monitor items, no DGR)"


class PollingAcquisition:
    """Polls the drive for the chosen channels into ``ring`` (rows ``[t_s, values...]``).

    ``t_s`` is host time (``clock``, s) since ``start``. ``step(budget_s)`` reads samples
    back to back until the budget is spent and returns how many it got; call it again at once
    while live, and every few hundred ms while not (``retry_interval_s``).
    """

    retry_interval_s = 0.25
    #: After an "s" (servo on, a drive of the manual's commands) the next try waits this long: the
    #: drive answers nothing over CN3 until the controller switches the servo off.
    servo_on_retry_s = 1.0

    def __init__(self, client: DriveApi, channels: Sequence[ScopeChannel], *, ratio: int | None = None,
                 capacity: int = 65536, config: ScopeConfig | None = None,
                 clock: Callable[[], float] = time.monotonic):
        self.client = client
        self.config = config or load_scope_config()
        self.clock = clock
        self.mode, self.channels, self._mode_note = plan_live(client.capabilities, channels, ratio,
                                                              self.config)
        self.items = [DGR_ITEM] if self.mode is LiveMode.POSITION else items_to_poll(self.channels)
        self.ring = RingBuffer(1 + max(1, len(self.channels)), capacity)
        self.t0 = clock()
        self.samples = 0
        self.line_time_s = 0.0  # line time of the replies so far (for the bound)
        self._recent: deque[float] = deque(maxlen=400)
        self._last_sample: float | None = None
        self._reason = self._mode_note or "starting"
        self._live = False
        self.lost = False
        self._limit_hz = (estimated_rate_hz(len(self.items)) if self.mode is LiveMode.MONITORS
                          else 1.0 / dgr_line_time_s(10 ** 6))
        self._columns = self._converters()

    def _converters(self) -> list[tuple[int, int | None, float]]:
        """(index into the reply values, I/O bit or None, scale) per channel."""
        index = {item: i for i, item in enumerate(self.items)}
        return [(index[c.monitor_item], c.io_bit, c.scale) for c in self.channels]

    # -- reading --------------------------------------------------------------------------------
    def _read_once(self) -> list[int]:
        if self.mode is LiveMode.POSITION:
            return [self.client.absolute_position()]
        values = self.client.read_monitors(self.items)
        return [values[i] for i in self.items]

    def _row(self, wire: list[int]) -> list[float]:
        row = []
        for index, bit, scale in self._columns:
            v = wire[index]
            row.append(float((v >> bit) & 1) if bit is not None else v * scale)
        return row

    def step(self, budget_s: float = 0.05) -> int:
        """Read samples for up to ``budget_s`` (at least one attempt); rows go into the ring."""
        if self.mode is LiveMode.NONE or self.lost:
            self._live = False
            return 0
        end = self.clock() + budget_s
        rows: list[list[float]] = []
        while True:
            before = self.clock()
            try:
                wire = self._read_once()
            except ServoOnRefused:
                self._not_live("servo on (controller): the drive does not answer over CN3 until servo "
                               "off; the position (DGR) comes back then")
                self.retry_interval_s = self.servo_on_retry_s
                break
            except (CommandNotSupported, CommandRejected) as exc:
                self._not_live(f"the drive refused the read: {exc}")
                break
            except LinkLost as exc:
                self.lost = True
                self._not_live(f"link lost: {exc}")
                break
            except (LinkTimeout, LinkError) as exc:
                self._not_live(f"no answer from the drive ({exc})")
                break
            after = self.clock()
            self.retry_interval_s = type(self).retry_interval_s
            rows.append([(before + after) / 2 - self.t0, *self._row(wire)])
            self._last_sample = after
            self._recent.append(after)
            self.line_time_s += (sample_line_time_s(wire) if self.mode is LiveMode.MONITORS
                                 else dgr_line_time_s(wire[0]))
            self._live = True
            if after >= end:
                break
        if rows:
            self.samples += len(rows)
            self.ring.write(np.asarray(rows))
            self._limit_hz = self.samples / self.line_time_s
        return len(rows)

    def _not_live(self, reason: str) -> None:
        self._live = False
        self._reason = reason

    # -- state ----------------------------------------------------------------------------------
    @property
    def answering(self) -> bool:
        """True when the last read got a sample (False after a refusal, a timeout, a lost link)."""
        return self._live

    @property
    def rate_hz(self) -> float:
        """Samples per second over the recent samples (host time)."""
        r = self._recent
        if len(r) < 2 or r[-1] == r[0]:
            return 0.0
        return (len(r) - 1) / (r[-1] - r[0])

    @property
    def limit_hz(self) -> float:
        """The line's bound (19200 bit/s) for the replies seen so far (an estimate before any)."""
        return self._limit_hz

    def age_s(self, now: float | None = None) -> float | None:
        if self._last_sample is None:
            return None
        return (self.clock() if now is None else now) - self._last_sample

    def stale_after_s(self) -> float:
        """Age beyond which the newest sample is not current any more."""
        rate = self.rate_hz or self._limit_hz
        return max(self.config.stale_after_s, self.config.stale_after_periods / rate if rate else 0.0)

    def status(self, now: float | None = None) -> LiveStatus:
        age = self.age_s(now)
        live, reason = self._live, self._reason
        if live and (age is None or age > self.stale_after_s()):
            live, reason = False, f"no new sample for {age:.1f} s" if age is not None else "no sample yet"
        # DGR works only for the position of a stopped servo: the label says so (LiveStatus.label).
        # Nothing polled (not live): no rate figure, not the last one
        return LiveStatus(live, "" if live else reason, self.mode, self.samples,
                          self.rate_hz if live else 0.0, self._limit_hz, self.ring.dropped, age)


# --- the built-in tests: move and step response ------------------------------------------------------


@dataclass(frozen=True)
class MoveTestResult:
    """What a move or step test produced; ``error`` says why there are no metrics."""

    kind: str  # "move" or "step"
    angle_deg: float
    speed_rpm: float
    capture: TraceResult | None
    metrics: MoveMetrics | None
    in_position_range_deg: float | None
    error: str = ""

    def describe(self) -> str:
        if self.metrics is None:
            return f"{self.kind} test: {self.error}"
        how = self.capture.method if self.capture else "?"
        return f"{self.kind} test ({how}): {self.metrics.describe('deg')}"


class _Phase(Enum):
    """Where a move test is: setting up, waiting for the trace's pre-trigger, capturing, polling."""

    START = "start"
    ARMING = "arming"
    CAPTURING = "capturing"
    POLLING = "polling"


class MoveTest:
    """Command a move of ``angle_deg`` at ``speed_rpm`` and capture it; ``step()`` until True.

    ``kind="step"`` raises the JOG acceleration (test item 1) to its maximum for the move and
    puts it back afterwards, so the command is as close to a step as the drive allows.
    Capture: the drive's trace when it has one (trigger: the ``moving`` I/O bit rises, 10 %
    pre-trigger), else polling until the axis is in position and still for ``settle_s``.
    The servo must be on (the test does not switch it on).
    """

    trace_samples = 1024

    def __init__(self, client: DriveApi, channels: Sequence[ScopeChannel], angle_deg: float,
                 speed_rpm: float, *, kind: str = "move", output_resolution_ppr: int | None = None,
                 use_trace: bool | None = None,
                 settle_s: float = 0.3, config: ScopeConfig | None = None,
                 clock: Callable[[], float] = time.monotonic,
                 should_abort: Callable[[], bool] | None = None,
                 progress: Callable[[int, int], None] | None = None):
        if kind not in ("move", "step"):
            raise ValueError(f"test kind {kind!r}: 'move' or 'step'")
        if angle_deg == 0 or speed_rpm <= 0:
            raise ValueError("a move test needs an angle != 0 and a speed > 0")
        by_key = {c.key: c for c in channels}
        if FEEDBACK_KEY not in by_key or COMMAND_KEY not in by_key:
            raise ValueError("a move test needs the feedback and command position channels")
        wanted = [FEEDBACK_KEY, COMMAND_KEY, "output_speed", "motor_current", "in_position", "moving"]
        self.channels = tuple(by_key[k] for k in wanted if k in by_key)
        self.client, self.kind = client, kind
        self.angle_deg, self.speed_rpm = float(angle_deg), float(speed_rpm)
        self.ppr = output_resolution_ppr
        self.settle_s = settle_s
        self.config = config or load_scope_config()
        self.clock = clock
        self.should_abort = should_abort  # asked between trace blocks (a STOP)
        self.progress = progress  # (samples read, samples in all) after every trace block
        self.trace = TraceAcquisition(client, self.config)
        self.use_trace = self.trace.available()[0] if use_trace is None else use_trace
        if self.use_trace:
            self.channels = tuple(c for c in self.channels if c.monitor_item != IO_STATE_ITEM)[:4]
        self.result: MoveTestResult | None = None
        self._phase = _Phase.START
        #: What each phase of the test runs (every _Phase has one; a test checks it).
        self._phases: dict[_Phase, Callable[[], None]] = {
            _Phase.START: self._phase_start,
            _Phase.ARMING: self._phase_arming,
            _Phase.CAPTURING: self._phase_capturing,
            _Phase.POLLING: self._phase_polling,
        }
        self._deadline = 0.0
        self._rows: list[list[float]] = []
        self._poller: PollingAcquisition | None = None
        self._settled_since: float | None = None
        self._restore_accel: int | None = None
        self._in_pos_deg: float | None = None
        self.state_text = "starting"

    @property
    def done(self) -> bool:
        return self.result is not None

    def expected_duration_s(self, accel_rpm_per_s: float) -> float:
        """Profile time of the move: cruise plus one acceleration (trapezoid)."""
        v = self.speed_rpm * 6.0  # deg/s
        a = max(accel_rpm_per_s * 6.0, 1e-6)  # deg/s^2
        d = abs(self.angle_deg)
        if d < v * v / a:  # triangle
            return 2.0 * math.sqrt(d / a)
        return d / v + v / a

    def step(self) -> bool:
        """Advance the test by one short exchange or a few; True when ``result`` is set."""
        if self.result is not None:
            return True
        try:
            self._phases[self._phase]()
        except (LinkError, ValueError) as exc:
            self._finish(error=self._explain(exc))
        return self.result is not None

    def abort(self, why: str = "stopped") -> None:
        if self.result is None:
            with contextlib.suppress(LinkError):
                self.client.stop()
            self._finish(error=why)

    @staticmethod
    def _explain(exc: Exception) -> str:
        if isinstance(exc, ReadAborted):
            return f"abandoned by STOP: {exc}"
        if isinstance(exc, ServoOnRefused):
            return "the drive refuses commands while the servo is on (a drive of the manual's command set)"
        if isinstance(exc, CommandNotSupported):
            return f"this drive cannot run the test: {exc}"
        if isinstance(exc, DriveRefused):
            return f"the drive refused: {exc}"
        return str(exc)

    # -- phases ---------------------------------------------------------------------------------
    def _param(self, mode: str, number: int) -> int | None:
        try:
            return self.client.read_parameter(mode, number)
        except (DriveRefused, LinkTimeout):
            return None

    def _phase_start(self) -> None:
        io = self.client.io_state()
        if not io.servo_on:
            raise ValueError("the servo is off: switch it on, then run the test")
        if io.alarm:
            raise ValueError("the drive is in alarm: clear it first")
        if self.ppr:
            in_pos = self._param("tune", 4)
            self._in_pos_deg = None if in_pos is None else in_pos * 360.0 / self.ppr
        accel = self._param("test", 1)
        accel_item = self.client.model.item("test", 1)
        if self.kind == "step" and accel is not None:
            self.client.write_parameter("test", 1, accel_item.maximum)
            self._restore_accel = accel
            accel = accel_item.maximum
        accel_rpm_s = accel_item.to_unit(accel if accel is not None else accel_item.default or 200)
        duration = self.expected_duration_s(accel_rpm_s)
        self.client.set_move_speed(self.speed_rpm)
        if self.use_trace:
            window = 0.1 * duration + duration + max(0.5, 3 * self.settle_s)
            samples = self.trace_samples  # enough for the metrics; every sample costs line time
            rate = min(self.config.servo_rate_hz, samples / window)
            moving = ScopeChannel("moving", "Moving", "bit", IO_STATE_ITEM, 1.0, int(p.IoBit.MOVING))
            self.trace.configure(TraceSettings(self.channels, rate, samples, samples // 10,
                                               Trigger(p.TriggerKind.IO_BIT_RISES, moving)))
            self.trace.arm()
            self._phase = _Phase.ARMING
            self.state_text = "trace armed, filling the pre-trigger"
        else:
            self._poller = PollingAcquisition(self.client, self.channels, config=self.config,
                                              clock=self.clock)
            self._poller.step(0.1)  # a few samples before the move
            self.client.move_by(self.angle_deg)
            self._phase = _Phase.POLLING
            self.state_text = f"moving {self.angle_deg:g} deg, polling"
        self._deadline = self.clock() + 3 * duration + 5.0

    def _phase_arming(self) -> None:
        if self.trace.ready_for_trigger(self.trace.status()):
            self.client.move_by(self.angle_deg)
            self._phase = _Phase.CAPTURING
            self.state_text = f"moving {self.angle_deg:g} deg, capturing"
        elif self.clock() > self._deadline:
            raise ValueError("the trace did not get ready (pre-trigger never filled)")

    def _phase_capturing(self) -> None:
        status = self.trace.status()
        if status.state is p.TraceState.DONE and self.state_text.startswith("moving"):
            self.state_text = (f"reading out {status.count} samples (about "
                               f"{self.trace.readout_estimate_s(status.count):.0f} s at {p.BAUDRATE} bit/s)")
        elif status.state is p.TraceState.DONE:
            self._analyse(self.trace.read(self.should_abort, self.progress))
        elif self.clock() > self._deadline:
            raise ValueError(f"the move did not trigger or finish the trace in time (state "
                             f"{status.state.name.lower()}, {status.count} samples)")

    def _phase_polling(self) -> None:
        poller = self._poller
        assert poller is not None
        poller.step(0.05)
        if not poller.status().live and poller.samples == 0:
            raise ValueError(poller.status().reason)
        io = self.client.io_state()
        now = self.clock()
        if io.in_position and not io.moving:
            self._settled_since = self._settled_since or now
        else:
            self._settled_since = None
        settled = self._settled_since is not None and now - self._settled_since >= self.settle_s
        if settled or now > self._deadline:
            rows = poller.ring.window(copy=True)
            t = rows[:, 0] - rows[0, 0]
            capture = TraceResult(tuple(poller.channels), t, rows[:, 1:], poller.rate_hz, 0,
                                  "polled around the MOV", clock.now_s(), "polling")
            self._analyse(capture)

    def _analyse(self, capture: TraceResult) -> None:
        try:
            metrics = move_metrics(capture.t_s, capture.column(COMMAND_KEY), capture.column(FEEDBACK_KEY),
                                   in_position_range=self._in_pos_deg)
        except ValueError as exc:
            self._finish(capture=capture, error=f"no move in the capture: {exc}")
            return
        self._finish(capture=capture, metrics=metrics)

    def _finish(self, capture: TraceResult | None = None, metrics: MoveMetrics | None = None,
                error: str = "") -> None:
        if self._restore_accel is not None:
            try:
                self.client.write_parameter("test", 1, self._restore_accel)
            except (LinkError, ValueError) as exc:
                error = (error + "; " if error else "") + f"the JOG acceleration was not restored: {exc}"
            self._restore_accel = None
        self.result = MoveTestResult(self.kind, self.angle_deg, self.speed_rpm, capture, metrics,
                                     self._in_pos_deg, error)


__all__ = [
    "COMMAND_KEY",
    "DGR_ITEM",
    "FEEDBACK_KEY",
    "READOUT_CHARS_PER_VALUE",
    "LiveMode",
    "LiveStatus",
    "MoveTest",
    "MoveTestResult",
    "PollingAcquisition",
    "ScopeConfig",
    "TraceAcquisition",
    "TraceResult",
    "TraceSettings",
    "Trigger",
    "convert_rows",
    "dgr_channel",
    "dgr_line_time_s",
    "estimated_rate_hz",
    "load_scope_config",
    "mmr_reply_chars",
    "plan_live",
    "readout_time_s",
    "sample_line_time_s",
    "theoretical_rate_hz",
]
