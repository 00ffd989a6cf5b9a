"""The scope's channels: the drive's monitor items (docs/protocol.md, items 100-108) and I/O bits.

A channel turns a wire integer into a value in its display unit. Positions are shown in degrees
of the output flange (pulses x 360 / output resolution), everything else in the parameter
model's unit.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from fha_studio.hardware.parameters import Mode, MonitorItem, ParameterModel
from fha_studio.hardware.protocol import MONITOR_MASK_BASE, IoBit

#: The I/O bits the scope offers (protocol.IoBit, the bits of IOS / monitor item 106), with their names.
IO_BITS: dict[str, tuple[IoBit, str]] = {
    "servo_on": (IoBit.SERVO_ON, "Servo on"),
    "in_position": (IoBit.IN_POSITION, "In-position"),
    "alarm": (IoBit.ALARM, "Alarm"),
    "fwd_inhibit": (IoBit.FWD_INHIBIT, "FWD inhibit"),
    "rev_inhibit": (IoBit.REV_INHIBIT, "REV inhibit"),
    "origin_sensor": (IoBit.ORIGIN_SENSOR, "Origin sensor"),
    "limit_switch_1": (IoBit.LIMIT_SWITCH_1, "Limit switch 1 (CCW)"),
    "limit_switch_2": (IoBit.LIMIT_SWITCH_2, "Limit switch 2 (CW)"),
    "brake_released": (IoBit.BRAKE_RELEASED, "Brake released"),
}
IO_STATE_ITEM = MonitorItem.IO_STATE
POSITION_KEYS = ("feedback_position", "command_position", "load_position")


@dataclass(frozen=True)
class ScopeChannel:
    """One plottable signal. ``value = wire * scale`` (analog) or bit ``io_bit`` of item 106."""

    key: str
    name: str
    unit: str
    monitor_item: int
    scale: float = 1.0
    io_bit: int | None = None

    @property
    def is_bit(self) -> bool:
        return self.io_bit is not None

    def convert(self, wire: int) -> float:
        """Display value of a wire integer from this channel's monitor item."""
        if self.io_bit is not None:
            return float((int(wire) >> self.io_bit) & 1)
        return wire * self.scale


def scope_channels(model: ParameterModel, output_resolution_ppr: int | None) -> list[ScopeChannel]:
    """Every channel the drive offers through its extension monitor items, in item order.

    Positions are converted to degrees when the output resolution is known (else kept in pulses).
    """
    channels: list[ScopeChannel] = []
    for item in model.in_mode(Mode.MONITOR):
        if item.number < MONITOR_MASK_BASE:  # the front panel's items, not on the link
            continue
        if item.number == IO_STATE_ITEM:
            for key, (bit, name) in IO_BITS.items():
                channels.append(ScopeChannel(key, name, "bit", IO_STATE_ITEM, 1.0, bit))
            continue
        if item.key in POSITION_KEYS and output_resolution_ppr:
            channels.append(ScopeChannel(item.key, item.name, "deg", item.number,
                                         360.0 / output_resolution_ppr))
        else:
            channels.append(ScopeChannel(item.key, item.name, item.unit, item.number, item.scale))
    return channels


def items_to_poll(channels: Sequence[ScopeChannel]) -> list[int]:
    """The distinct monitor items the given channels need, ascending (one MMR request)."""
    return sorted({c.monitor_item for c in channels})
