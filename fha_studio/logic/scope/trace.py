"""The drive-side trace capture: trigger, settings, the read-out result, and ``TraceAcquisition``
(TCH/TDV/TTG/TTC/TTL/TPR/TAR/TST/TRB or TRP through the client). No Qt; every call talks to the
drive (run it in the link thread)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from fha_studio import clock
from fha_studio.hardware import protocol as p
from fha_studio.hardware.api import CapabilityLevel, DriveApi, TraceStatus
from fha_studio.logic.scope.budget import ScopeConfig, load_scope_config, readout_time_s
from fha_studio.logic.scope.channels import ScopeChannel, items_to_poll

# --- drive-side trace capture ----------------------------------------------------------------------


@dataclass(frozen=True)
class Trigger:
    """When a trace starts. ``channel``: for level triggers an analog channel (``level`` in its
    display unit); for edge triggers an I/O bit channel. Alarm and immediate need no channel."""

    kind: p.TriggerKind = p.TriggerKind.IMMEDIATE
    channel: ScopeChannel | None = None
    level: float = 0.0

    def wire(self) -> tuple[int, int, int]:
        """(TTG kind, TTC channel, TTL level) as sent."""
        k = self.kind
        if k in (p.TriggerKind.RISING_LEVEL, p.TriggerKind.FALLING_LEVEL):
            if self.channel is None or self.channel.is_bit or self.channel.monitor_item < p.MONITOR_MASK_BASE:
                raise ValueError("a level trigger needs an analog monitor channel")
            return int(k), self.channel.monitor_item, round(self.level / self.channel.scale)
        if k in (p.TriggerKind.IO_BIT_RISES, p.TriggerKind.IO_BIT_FALLS):
            if self.channel is None or not self.channel.is_bit:
                raise ValueError("an edge trigger needs an I/O bit channel")
            bit = self.channel.io_bit
            assert bit is not None  # is_bit
            return int(k), int(bit), 0
        return int(k), 0, 0

    def describe(self) -> str:
        k = self.kind
        if k is p.TriggerKind.IMMEDIATE:
            return "immediate"
        if k is p.TriggerKind.ALARM:
            return "on an alarm"
        name = self.channel.name if self.channel else "?"
        if k in (p.TriggerKind.RISING_LEVEL, p.TriggerKind.FALLING_LEVEL):
            edge = "rises through" if k is p.TriggerKind.RISING_LEVEL else "falls through"
            return f"{name} {edge} {self.level:g} {self.channel.unit if self.channel else ''}".rstrip()
        return f"{name} {'rises' if k is p.TriggerKind.IO_BIT_RISES else 'falls'}"


@dataclass(frozen=True)
class TraceSettings:
    """A capture: channels (their monitor items, at most 4 distinct), rate, length, trigger."""

    channels: tuple[ScopeChannel, ...]
    sample_rate_hz: float = 1000.0
    samples: int = 2048
    pre_trigger: int = 0
    trigger: Trigger = field(default_factory=Trigger)

    def items(self) -> list[int]:
        return items_to_poll(self.channels)

    def divider(self, servo_rate_hz: float) -> int:
        return max(1, round(servo_rate_hz / self.sample_rate_hz))

    def check(self) -> None:
        items = self.items()
        if not self.channels:
            raise ValueError("a trace needs at least one channel")
        if any(i < p.MONITOR_MASK_BASE for i in items):
            raise ValueError("a trace takes monitor items 100-115 only")
        if len(items) > p.TRACE_MAX_CHANNELS:
            raise ValueError(f"a trace takes at most {p.TRACE_MAX_CHANNELS} monitor items; these channels "
                             f"need {len(items)} ({', '.join(map(str, items))}); I/O bits share item 106")
        if not 1 <= self.samples <= p.TRACE_MAX_SAMPLES:
            raise ValueError(f"a trace has 1 ... {p.TRACE_MAX_SAMPLES} samples, got {self.samples}")
        if not 0 <= self.pre_trigger < self.samples:
            raise ValueError(f"pre-trigger {self.pre_trigger} must be 0 ... {self.samples - 1}")
        if self.sample_rate_hz <= 0:
            raise ValueError("the trace sample rate must be > 0")
        self.trigger.wire()


@dataclass(frozen=True)
class TraceResult:
    """A read-out capture in display units; ``t_s`` is 0 at the trigger (pre-trigger negative)."""

    channels: tuple[ScopeChannel, ...]
    t_s: np.ndarray
    values: np.ndarray  # shape (samples, channels)
    sample_rate_hz: float
    pre_trigger: int
    trigger: str
    captured_at: float  # wall clock (clock.now_s()) of the read-out
    method: str = "trace"  # "trace" (drive-side) or "polling" (host-side, uneven)

    def column(self, key: str) -> np.ndarray:
        for j, c in enumerate(self.channels):
            if c.key == key:
                return self.values[:, j]
        raise KeyError(f"no channel {key!r} in this capture ({', '.join(c.key for c in self.channels)})")

    def has(self, key: str) -> bool:
        return any(c.key == key for c in self.channels)

    def rows(self) -> np.ndarray:
        """``[t_s, values...]`` rows: the scope's sample layout (recorder, CSV)."""
        return np.column_stack([self.t_s, self.values])


def convert_rows(channels: Sequence[ScopeChannel], items: Sequence[int],
                 rows: Sequence[Sequence[int]]) -> np.ndarray:
    """Wire rows (one value per item, in ``items`` order) -> display values per channel."""
    wire = np.asarray(rows, dtype=np.int64).reshape(len(rows), len(items))
    out = np.empty((len(rows), len(channels)))
    for j, c in enumerate(channels):
        col = wire[:, list(items).index(c.monitor_item)]
        out[:, j] = ((col >> c.io_bit) & 1) if c.io_bit is not None else col * c.scale
    return out


class TraceAcquisition:
    """Drive-side capture (TCH/TDV/TTG/TTC/TTL/TPR/TAR/TST/TRB) through the client."""

    def __init__(self, client: DriveApi, config: ScopeConfig | None = None):
        self.client = client
        self.config = config or load_scope_config()
        self.settings: TraceSettings | None = None
        self._items: tuple[int, ...] = ()

    def available(self) -> tuple[bool, str]:
        """(True, "") when the drive can trace, else (False, why in a sentence)."""
        if self.client.capabilities.level is CapabilityLevel.TRACE:
            return True, ""
        return False, "this drive has no trace capture: " + self.client.capabilities.describe()

    def actual_rate_hz(self, settings: TraceSettings) -> float:
        return self.config.servo_rate_hz / settings.divider(self.config.servo_rate_hz)

    def configure(self, settings: TraceSettings) -> None:
        settings.check()
        kind, channel, level = settings.trigger.wire()
        self._items = self.client.configure_trace(
            settings.items(), divider=settings.divider(self.config.servo_rate_hz),
            trigger=p.TriggerKind(kind), trigger_channel=channel, trigger_level=level,
            pre_trigger=settings.pre_trigger)
        self.settings = settings

    def arm(self) -> None:
        if self.settings is None:
            raise ValueError("configure the trace before arming it")
        self.client.arm_trace(self.settings.samples)

    def status(self) -> TraceStatus:
        """The drive's ``TraceStatus`` (state, samples held)."""
        return self.client.trace_status()

    def ready_for_trigger(self, status: TraceStatus) -> bool:
        """True once the pre-trigger part is full (a trigger before that would shorten it)."""
        if status.state is p.TraceState.ARMED:
            return bool(status.count >= (self.settings.pre_trigger if self.settings else 0))
        return status.state in (p.TraceState.CAPTURING, p.TraceState.DONE)

    @property
    def encoding(self) -> str:
        """How the blocks come: "packed" (TRP, listed in CAP) or "text" (TRB)."""
        return "packed" if self.client.capabilities.supports(p.Command.TRP) else "text"

    def readout_estimate_s(self, samples: int) -> float:
        """Line time of reading ``samples`` of the configured channels out."""
        items = len(self.settings.items()) if self.settings else p.TRACE_MAX_CHANNELS
        return readout_time_s(samples, items, self.encoding)

    def read(self, should_abort: Callable[[], bool] | None = None,
             progress: Callable[[int, int], None] | None = None) -> TraceResult:
        """Read the finished capture out (TRP or TRB blocks of 64 samples). ``should_abort`` is
        asked between blocks; True gives up with ``ReadAborted`` (a STOP must not wait for the
        whole read-out). ``progress(done, total)`` after every block (samples)."""
        settings = self.settings
        if settings is None:
            raise ValueError("no trace configured")
        capture = self.client.read_trace(should_abort=should_abort, progress=progress)
        values = convert_rows(settings.channels, capture.channels, capture.samples)
        rate = self.actual_rate_hz(settings)
        t = (np.arange(len(values)) - settings.pre_trigger) / rate
        return TraceResult(settings.channels, t, values, rate, settings.pre_trigger,
                           settings.trigger.describe(), clock.now_s())
