"""Trace capture of the simulated drive (TCH/TDV/TTG/TTC/TTL/TPR/TAR/TST/TRB, docs/protocol.md).

Up to four monitor items are sampled every ``divider`` servo periods. While armed, the last
``pretrigger`` samples are kept; when the trigger fires the capture continues until ``count``
samples are held (pre-trigger ones included), then it is done and readable in blocks of 64.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Sequence

# The protocol's own definitions: the drive and the client must never disagree on them.
from fha_studio.hardware.parameters import MonitorItem
from fha_studio.hardware.protocol import (
    MONITOR_MASK_BASE,
    MONITOR_MASK_ITEMS,
    TraceState,
    TriggerKind,
)
from fha_studio.hardware.protocol import TRACE_BLOCK_SAMPLES as BLOCK_SAMPLES
from fha_studio.hardware.protocol import TRACE_MAX_CHANNELS as MAX_CHANNELS
from fha_studio.hardware.protocol import TRACE_MAX_SAMPLES as MAX_SAMPLES

MONITOR_FIRST = MONITOR_MASK_BASE
MONITOR_LAST = MONITOR_MASK_BASE + MONITOR_MASK_ITEMS - 1


class TraceError(ValueError):
    """A trace setting is not allowed (the protocol answers ``x``)."""


def channels_from_mask(mask: int) -> list[int]:
    """Monitor items selected by a bit mask (bit k = item 100 + k), in item order."""
    if mask <= 0 or mask >= 1 << (MONITOR_LAST - MONITOR_FIRST + 1):
        raise TraceError(f"channel mask {mask} selects no monitor item 100-115")
    return [MONITOR_FIRST + k for k in range(16) if mask >> k & 1]


class SimTrace:
    """Settings and buffer of one trace. ``sample(read)`` is called every servo period by the
    drive; ``read(item)`` returns the wire value of a monitor item (I/O bits: item 106)."""

    def __init__(self) -> None:
        self.channels: list[int] = []
        self.divider = 1
        self.trigger = TriggerKind.IMMEDIATE
        self.trigger_channel = MONITOR_FIRST
        self.trigger_level = 0
        self.pretrigger = 0
        self.count = 0
        self.state = TraceState.IDLE
        self._samples: list[tuple[int, ...]] = []
        self._pre: deque[tuple[int, ...]] = deque()
        self._phase = 0
        self._previous: int | None = None

    # --- settings (each refused with TraceError, leaving the old value) ---
    def set_channels(self, mask: int) -> None:
        channels = channels_from_mask(mask)
        if len(channels) > MAX_CHANNELS:
            raise TraceError(f"{len(channels)} channels selected, at most {MAX_CHANNELS}")
        self.channels = channels

    def set_divider(self, divider: int) -> None:
        if not 1 <= divider <= 99999:
            raise TraceError(f"divider {divider} outside 1 ... 99999")
        self.divider = divider

    def set_trigger(self, kind: int) -> None:
        try:
            self.trigger = TriggerKind(kind)
        except ValueError:
            raise TraceError(f"unknown trigger kind {kind} (0 ... 5)") from None

    def set_trigger_channel(self, channel: int) -> None:
        if not (0 <= channel <= 15 or MONITOR_FIRST <= channel <= MONITOR_LAST):
            raise TraceError(f"trigger channel {channel}: an I/O bit 0-15 or a monitor item 100-115")
        self.trigger_channel = channel

    def set_trigger_level(self, level: int) -> None:
        self.trigger_level = level

    def set_pretrigger(self, samples: int) -> None:
        if not 0 <= samples <= MAX_SAMPLES - 1:
            raise TraceError(f"pre-trigger {samples} outside 0 ... {MAX_SAMPLES - 1}")
        self.pretrigger = samples

    def arm(self, count: int) -> None:
        if not self.channels:
            raise TraceError("no trace channels selected (TCH)")
        if not 1 <= count <= MAX_SAMPLES:
            raise TraceError(f"sample count {count} outside 1 ... {MAX_SAMPLES}")
        self.count = count
        self._samples = []
        self._pre = deque(maxlen=max(1, min(self.pretrigger, count - 1) or 1))
        self._phase = 0
        self._previous = None
        self.state = TraceState.CAPTURING if self.trigger == TriggerKind.IMMEDIATE else TraceState.ARMED

    # --- running ---
    @property
    def active(self) -> bool:
        return self.state in (TraceState.ARMED, TraceState.CAPTURING)

    def needed_items(self) -> list[int]:
        """Monitor items the drive must supply on each sample (channels + trigger source)."""
        items = list(self.channels)
        if self.trigger in (TriggerKind.RISING_LEVEL, TriggerKind.FALLING_LEVEL):
            items.append(self.trigger_channel)
        elif self.trigger in (TriggerKind.IO_BIT_RISES, TriggerKind.IO_BIT_FALLS):
            items.append(MonitorItem.IO_STATE)
        return items

    def steps_until_sample(self) -> int:
        """Servo periods until the next sample is due (>= 1)."""
        return max(1, self.divider - self._phase)

    def after_steps(self, steps: int) -> bool:
        """Count ``steps`` servo periods (never past the next sample); True when a sample is due now."""
        if not self.active:
            return False
        self._phase += steps
        if self._phase >= self.divider:
            self._phase = 0
            return True
        return False

    def sample(self, read: Callable[[int], int], alarm_code: int = 0) -> None:
        """Take one sample (call when :meth:`due` said so)."""
        row = tuple(read(item) for item in self.channels)
        if self.state == TraceState.ARMED:
            if self._fired(read, alarm_code):
                pre = list(self._pre)[-self.pretrigger:] if self.pretrigger else []
                self._samples = pre
                self.state = TraceState.CAPTURING
            else:
                self._pre.append(row)
                return
        if self.state == TraceState.CAPTURING:
            self._samples.append(row)
            if len(self._samples) >= self.count:
                self.state = TraceState.DONE

    def _fired(self, read: Callable[[int], int], alarm_code: int) -> bool:
        kind = self.trigger
        if kind == TriggerKind.ALARM:
            return alarm_code != 0
        if kind in (TriggerKind.RISING_LEVEL, TriggerKind.FALLING_LEVEL):
            value = read(self.trigger_channel)
        else:
            value = read(MonitorItem.IO_STATE) >> self.trigger_channel & 1 if self.trigger_channel < 16 else 0
        previous, self._previous = self._previous, value
        if previous is None:
            return False
        if kind == TriggerKind.RISING_LEVEL:
            return previous < self.trigger_level <= value
        if kind == TriggerKind.FALLING_LEVEL:
            return previous > self.trigger_level >= value
        if kind == TriggerKind.IO_BIT_RISES:
            return previous == 0 and value == 1
        return previous == 1 and value == 0

    # --- reading ---
    def status(self) -> tuple[int, int]:
        """(state, samples held) as TST answers."""
        held = len(self._pre) if self.state == TraceState.ARMED else len(self._samples)
        return int(self.state), held

    def block(self, number: int) -> Sequence[tuple[int, ...]]:
        """Samples of block ``number`` (64 each) of a finished capture."""
        if self.state != TraceState.DONE:
            raise TraceError("no finished capture to read")
        start = number * BLOCK_SAMPLES
        if number < 0 or start >= len(self._samples):
            raise TraceError(f"block {number} is past the end of {len(self._samples)} samples")
        return self._samples[start : start + BLOCK_SAMPLES]
