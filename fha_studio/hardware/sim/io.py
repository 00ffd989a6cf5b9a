"""The simulated drive's I/O and sensors: the CN2 inputs set by INP, the option-L origin slit and
limit-switch dogs, the holding brake's coil, and the I/O bit mask of IOS / monitor 106."""

from __future__ import annotations

import math

from fha_studio.hardware.api import SensorName
from fha_studio.hardware.sim.constants import SimConstants
from fha_studio.hardware.sim.reply import rejected

# I/O bits (docs/protocol.md, I/O table)
BIT_SERVO_ON = 0
BIT_READY = 1
BIT_ALARM = 2
BIT_IN_POSITION = 3
BIT_FWD_INHIBIT = 4
BIT_REV_INHIBIT = 5
BIT_ORIGIN = 6
BIT_LIMIT_1 = 7
BIT_LIMIT_2 = 8
BIT_BRAKE_RELEASED = 9
BIT_ERROR_CLEAR = 10
BIT_ALM_A = 11
BIT_MOVING = 15
INPUT_MASK = sum(1 << b for b in (4, 5, 6, 7, 8, 9, 10))
SENSOR_MASK = sum(1 << b for b in (BIT_ORIGIN, BIT_LIMIT_1, BIT_LIMIT_2))

SENSORS = tuple(SensorName)
#: More than one output encoder pulse of any FHA-C (the coarsest, 409600 pulses per turn, is 0.00088 deg)
DOG_EDGE_TOLERANCE_DEG = 0.001


def _wrap_deg(angle: float) -> float:
    return (angle + 180.0) % 360.0 - 180.0


class SimIo:
    """Inputs, sensors and brake of one drive. Angles are physical (CW positive seen from the
    flange), in degrees of the output; the sensor disk turns with the output."""

    def __init__(
        self,
        constants: SimConstants,
        *,
        has_sensors: bool,
        has_brake: bool,
        origin_deg: float,
        ls1_deg: float,
        ls2_deg: float,
        brake_supply: bool = True,
    ):
        self.constants = constants
        self.has_sensors = has_sensors
        self.has_brake = has_brake
        # False: the brake's 24 V supply is missing (a wiring fault): the coil never gets its
        # voltage, whatever the controller switches
        self.brake_supply = brake_supply
        self.inputs = 0  # the INP bits
        self.origin_deg = origin_deg
        self.ls1_deg = ls1_deg
        self.ls2_deg = ls2_deg

    def set_inputs(self, mask: int) -> bool:
        """Set the simulated CN2 inputs (see :meth:`SimDrive.set_inputs`). Returns True when the
        ERROR CLEAR input (bit 10) has just risen. Raises SimRefused (``x``) for other bits."""
        if mask < 0 or mask & ~INPUT_MASK:
            raise rejected(f"INP {mask}: only input bits 4-10 can be set (mask {INPUT_MASK})")
        if self.has_sensors:
            mask &= ~SENSOR_MASK
        was_clear = self.inputs >> BIT_ERROR_CLEAR & 1
        self.inputs = mask
        return bool(mask >> BIT_ERROR_CLEAR & 1 and not was_clear)

    @property
    def brake_holding(self) -> bool:
        """True while the brake holds: fitted and its 24 V coil unpowered (non-excitation brake)."""
        return self.has_brake and not self.coil_powered

    @property
    def coil_powered(self) -> bool:
        """24 V is on the brake coil: the controller switched it on and the supply is there."""
        return bool(self.inputs >> BIT_BRAKE_RELEASED & 1) and self.brake_supply

    def set_sensor_angle(self, which: SensorName | str, angle_deg: float) -> None:
        """Move the origin slit (``"origin"``) or a limit-switch dog (``"ls1"``, ``"ls2"``)."""
        if which not in SENSORS:
            raise ValueError(f"sensor {which!r}: origin, ls1 or ls2")
        which = SensorName(which)
        if not self.has_sensors:
            raise rejected("this actuator has no option-L sensor set")
        if not math.isfinite(angle_deg):
            raise rejected("sensor angle must be finite")
        if which is SensorName.ORIGIN:
            self.origin_deg = float(angle_deg)
        elif which is SensorName.LS1:
            self.ls1_deg = float(angle_deg)
        else:
            self.ls2_deg = float(angle_deg)

    def sensor_bits(self, angle_deg: float) -> int:
        """Origin and limit-switch bits with the output at ``angle_deg``."""
        bits = 0
        if not self.has_sensors:
            return bits
        c = self.constants
        if abs(_wrap_deg(angle_deg - self.origin_deg)) <= c.origin_slit_width_deg / 2:
            bits |= 1 << BIT_ORIGIN
        # a dog holds its switch from its edge on, over its arc, towards its stroke end; the edge
        # takes DOG_EDGE_TOLERANCE_DEG, so a dog set "here" from the angle the drive reports
        # (whole encoder pulses) switches with the output resting a fraction of a pulse before it
        if -DOG_EDGE_TOLERANCE_DEG <= _wrap_deg(self.ls1_deg - angle_deg) <= c.limit_dog_arc_deg:
            bits |= 1 << BIT_LIMIT_1
        if -DOG_EDGE_TOLERANCE_DEG <= _wrap_deg(angle_deg - self.ls2_deg) <= c.limit_dog_arc_deg:
            bits |= 1 << BIT_LIMIT_2
        return bits

    def blocked(self, angle_deg: float, direction: float) -> tuple[bool, bool]:
        """(FWD blocked, REV blocked) by an inhibit input or a limit switch, with ``direction``
        the rotary-direction sign (+1: FWD = CW)."""
        return (
            self.blocks(angle_deg, forward=True, physical_cw=direction > 0),
            self.blocks(angle_deg, forward=False, physical_cw=direction < 0),
        )

    def blocks(self, angle_deg: float, *, forward: bool, physical_cw: bool) -> bool:
        """An inhibit input (command sense) or a limit switch (physical sense) stops a motion
        going ``forward`` (FWD) and ``physical_cw`` (CW seen from the flange)."""
        inputs = self.inputs | self.sensor_bits(angle_deg)
        return bool(
            (forward and inputs >> BIT_FWD_INHIBIT & 1)
            or (not forward and inputs >> BIT_REV_INHIBIT & 1)
            or (physical_cw and inputs >> BIT_LIMIT_2 & 1)
            or (not physical_cw and inputs >> BIT_LIMIT_1 & 1)
        )

    def bits(
        self,
        angle_deg: float,
        *,
        servo_on: bool,
        alarm: int,
        alm_bits: int,
        in_position: bool,
        moving: bool,
    ) -> int:
        """The I/O bit mask of IOS / monitor 106; ``alm_bits`` is the active alarm's ALM code."""
        bits = self.inputs | self.sensor_bits(angle_deg)
        if not self.coil_powered:
            bits &= ~(1 << BIT_BRAKE_RELEASED)
        if servo_on:
            bits |= 1 << BIT_SERVO_ON
        if not alarm:
            bits |= 1 << BIT_READY
        else:
            bits |= 1 << BIT_ALARM
            bits |= alm_bits << BIT_ALM_A
        if servo_on and in_position and not moving:
            bits |= 1 << BIT_IN_POSITION
        if moving:
            bits |= 1 << BIT_MOVING
        return bits
