"""The monitor items on the wire (MON, MMR and the trace; docs/protocol.md, monitor table): the
simulated drive's quantities in units, scaled to the integers the drive sends."""

from __future__ import annotations

from typing import Protocol

from fha_studio.hardware.parameters import MonitorItem, split_low_high
from fha_studio.hardware.sim.reply import rejected
from fha_studio.physics import RAD_S_PER_RPM, AxisModel, ServoAxis


class MonitorSource(Protocol):
    """What the monitor items show, in units (command sense unless said): a :class:`SimDrive`."""

    model: AxisModel
    ratio: float
    axis: ServoAxis

    @property
    def feedback_pulses(self) -> int: ...
    @property
    def command_pulses(self) -> int: ...
    @property
    def error_pulses(self) -> int: ...
    @property
    def input_pulses(self) -> int: ...
    @property
    def load_pulses(self) -> int: ...
    @property
    def output_speed_rpm(self) -> float: ...
    @property
    def motor_current_a(self) -> float: ...
    @property
    def motor_current_mean_a(self) -> float: ...
    @property
    def output_torque_nm(self) -> float: ...
    @property
    def flange_torque_nm(self) -> float: ...
    @property
    def overload_rate(self) -> float: ...
    def io_bits(self) -> int: ...


def monitor_wire(drive: MonitorSource, item: int) -> int:
    """Wire value of monitor item ``item``; SimRefused (``x``) for an item the drive does not have."""
    if item == MonitorItem.FEEDBACK_POSITION:
        return drive.feedback_pulses
    if item == MonitorItem.COMMAND_POSITION:
        return drive.command_pulses
    if item == MonitorItem.ERROR_PULSES:
        return drive.error_pulses
    if item == MonitorItem.OUTPUT_SPEED:
        return round(drive.output_speed_rpm * 100)
    if item == MonitorItem.MOTOR_CURRENT:
        return round(drive.motor_current_a * 1000)
    if item == MonitorItem.MOTOR_CURRENT_MEAN:
        return round(drive.motor_current_mean_a * 1000)
    if item == MonitorItem.OVERLOAD_RATE:
        return round(drive.overload_rate * 1000)
    if item == MonitorItem.IO_STATE:
        return drive.io_bits()
    if item == MonitorItem.LOAD_POSITION:
        return drive.load_pulses
    if item == MonitorItem.OUTPUT_TORQUE:
        return round(drive.output_torque_nm * 100)
    if item == MonitorItem.SPEED_COMMAND:  # the speed loop's reference (command sense)
        axis = drive.axis
        return round(axis.speed_command_rad_s / RAD_S_PER_RPM * 10000) if axis.servo_is_on else 0
    if item == MonitorItem.OUTPUT_SPEED_FINE:
        return round(drive.output_speed_rpm * 10000)
    if item == MonitorItem.FLANGE_TORQUE:
        return round(drive.flange_torque_nm * 100)
    if item == 0:  # motor speed, r/min
        return round(drive.output_speed_rpm * drive.ratio)
    if item == 1:  # current, % of the maximum
        return round(100 * drive.motor_current_a / drive.model.max_current_a)
    if item in (3, 4, 7, 8, 9, 10):  # 32-bit counters as (low, high) item pairs
        if item in (3, 4):
            count = drive.error_pulses
        elif item in (7, 8):
            count = drive.feedback_pulses
        else:
            count = drive.input_pulses
        low, high = split_low_high(count)
        return low if item in (3, 7, 9) else high
    raise rejected(f"no monitor item {item}")
