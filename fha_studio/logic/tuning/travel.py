"""Does the excitation's travel fit the axis's movable range, in the direction chosen?

On a bias speed the axis turns up to ``ExcitationPlan.bias_travel_deg`` one way (FWD or REV),
and the excitation swings about the jog's path by at most the travel limit where the drive stops
it, either way (about standstill: that limit alone, either way). Where the limit switches'
angles are known (the sensor dogs' switching angles recorded in the procedures, 4-7-2 and 4-7-3)
and the present position too, each way's travel must fit the room to its limit, or the start is
refused in one line that names the travel, the room and what else fits. Where they are not known
the plan says so beside the travel, and the person confirms that the axis may turn that far.

Angles are the output's feedback position (monitor 100, as the procedures record the switching
angles: ``procedures.live.output_angle_deg``), in the command's sense: a FWD command increases it.
So the FWD end of the range is the larger of the two switching angles, whatever the rotary
direction (1-10) makes of FWD on the flange. With an incremental encoder the feedback position starts at 0
at power-on: angles recorded before the drive was last switched on do not hold.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace

from fha_studio.logic.procedures.sensor_dogs import SENSOR_NAMES, Sensor
from fha_studio.logic.tuning.excitation import BiasDirection, ExcitationPlan, NotExcitable, rotation_words


class TravelRefused(NotExcitable):
    """The excitation would turn the axis past its movable range: the message says how far it would
    turn, how far there is to the limit, and what fits instead."""


@dataclass(frozen=True)
class MovableRange:
    """The movable range and the present position (output degrees, command sense: FWD increases)."""

    rev_end_deg: float
    fwd_end_deg: float
    position_deg: float
    rev_end_name: str = "the REV end of the movable range"
    fwd_end_name: str = "the FWD end of the movable range"

    @classmethod
    def from_switch_angles(cls, angles_deg: Mapping[str, float], position_deg: float) -> MovableRange | None:
        """From the two limit switches' switching angles (``limit_switch_1`` / ``limit_switch_2`` as
        the procedures record them), or None where either is not recorded."""
        one, two = angles_deg.get(Sensor.LIMIT_SWITCH_1), angles_deg.get(Sensor.LIMIT_SWITCH_2)
        if one is None or two is None:
            return None
        (low, low_key), (high, high_key) = sorted(((float(one), Sensor.LIMIT_SWITCH_1),
                                                   (float(two), Sensor.LIMIT_SWITCH_2)))
        return cls(low, high, float(position_deg), SENSOR_NAMES[low_key], SENSOR_NAMES[high_key])

    def room_deg(self, sign: int) -> float:
        """How far the axis may turn from where it is, FWD (``sign`` +1) or REV (-1)."""
        return self.fwd_end_deg - self.position_deg if sign > 0 else self.position_deg - self.rev_end_deg

    def end_name(self, sign: int) -> str:
        return self.fwd_end_name if sign > 0 else self.rev_end_name


def travel_deg(plan: ExcitationPlan, sign: int) -> float:
    """How far ``plan`` may turn the axis FWD (``sign`` +1) or REV (-1) at most: the bias speed's
    angle that way, and the excitation's swing up to where the drive stops it, either way."""
    along = plan.bias_travel_deg if plan.bias_rpm > 0 and sign == plan.bias_sign else 0.0
    return along + plan.travel_limit_deg


def check_travel(plan: ExcitationPlan, movable: MovableRange | None, fwd_is_cw: bool | None = None,
                 manual_units: bool = True) -> str:
    """The line the plan states about the room: how far each way it turns the axis and, where the
    range is known, how far there is to the limit. Raises TravelRefused (one line) when it does not
    fit; that line names which other choice fits, if one does (``alternatives``). ``manual_units``:
    "°" (a page), else "deg" (a terminal)."""
    direction = plan.bias_direction
    deg = _degrees(manual_units)

    def way(sign: int) -> str:
        return rotation_words(sign, fwd_is_cw)

    if movable is None:
        return "the movable range is not known: confirm that the axis may turn that far"
    short = [(sign, travel_deg(plan, sign), movable.room_deg(sign))
             for sign in (plan.bias_sign, -plan.bias_sign) if travel_deg(plan, sign) > movable.room_deg(sign)]
    if not short:
        sign = plan.bias_sign
        ahead, behind = (deg(max(movable.room_deg(s), 0.0)) for s in (sign, -sign))
        return (f"within the movable range: {ahead} to {movable.end_name(sign)}, {behind} to "
                f"{movable.end_name(-sign)}")
    sign, needed, room = short[0]
    biased = direction is not BiasDirection.NONE
    what = f"on a {way(plan.bias_sign)} jog the excitation" if biased else "in place the excitation"
    towards = "that way" if biased and sign == plan.bias_sign else way(sign)
    raise TravelRefused(f"{what} would turn the axis up to about {deg(needed)} {towards}, and there are "
                        f"only {deg(max(room, 0.0))} to {movable.end_name(sign)}: "
                        f"{alternatives(plan, movable, fwd_is_cw, manual_units)}")


def _degrees(manual_units: bool) -> Callable[[float], str]:
    def deg(value: float) -> str:
        return f"{value:.3g}°" if manual_units else f"{value:.3g} deg"

    return deg


def alternatives(plan: ExcitationPlan, movable: MovableRange, fwd_is_cw: bool | None,
                 manual_units: bool = True) -> str:
    """What else to choose: the other direction or in place, where the range has room for it (the
    bias travel is the same either way; in place, the excitation's swing either way)."""
    fits = []
    deg = _degrees(manual_units)
    if plan.bias_rpm > 0:  # the other way: the same speed and travel (the loop is the same)
        other = replace(plan, bias_sign=-plan.bias_sign)
        if all(travel_deg(other, s) <= movable.room_deg(s) for s in (1, -1)):
            fits.append(f"choose {rotation_words(other.bias_sign, fwd_is_cw)}, "
                        f"{deg(max(movable.room_deg(other.bias_sign), 0.0))} free that way")
        if all(plan.travel_limit_deg <= movable.room_deg(s) for s in (1, -1)):
            fits.append("measure in place (the friction then spoils the low frequencies)")
    if not fits:
        return "move the axis towards the middle of its range first"
    return ", or ".join(fits)
