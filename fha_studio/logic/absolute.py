"""What a drive of the manual's command set gives: probe, absolute position (DGR), origin (OWW).

A real HA-655 answers over CN3 only ``DGR`` (the absolute position, absolute encoders, servo off)
and ``OWW`` (clear the multi-turn data): ``x`` to anything else, ``s`` to everything while the
servo is on (HA-655 manual p.21; servo-ON comes from the controller through CN2). These functions
work on any drive (the simulated drive's extensions only add to what they report) and run in the
caller's thread: a GUI calls them in its link thread.

Positions: DGR's value is multi-turn x 8192 + single-turn count of the motor encoder (FHA-C manual
1-8: 8192 counts per motor turn); the output flange turns ``1 / ratio`` of a motor turn.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

from fha_studio import clock
from fha_studio.catalog import ModelCodeError, parse_model_code
from fha_studio.hardware import protocol as p
from fha_studio.hardware.api import Capabilities, DriveApi
from fha_studio.hardware.errors import CommandRejected, DriveRefused, ServoOnRefused

#: What the technician is told when the drive answers ``s``.
SERVO_ON_TEXT = "servo on (controller): the drive does not answer over CN3 until servo off"


def output_deg(counts: int, ratio: int) -> float:
    """DGR counts -> output flange angle in degrees (CW positive seen from the flange)."""
    return counts * 360.0 / (p.ABSOLUTE_COUNTS_PER_TURN * ratio)


def counts_for_output_deg(angle_deg: float, ratio: int) -> float:
    """How many DGR counts the output turning by ``angle_deg`` makes."""
    return angle_deg * p.ABSOLUTE_COUNTS_PER_TURN * ratio / 360.0


def ratio_of(code: str | None) -> int | None:
    """The reduction ratio of an actuator model code, None when there is no code or it does not parse."""
    if not code:
        return None
    try:
        return parse_model_code(code).ratio
    except ModelCodeError:
        return None


def documented_only(capabilities: Capabilities) -> bool:
    """True when the drive listed no extension command (it speaks only the manual's DGR and OWW)."""
    return not (set(capabilities.commands) - p.DOCUMENTED_COMMANDS)


def refusal_text(exc: DriveRefused, command: p.Command) -> str:
    """One line for a person: why the drive said no to ``command`` (DGR or OWW)."""
    if isinstance(exc, ServoOnRefused):
        return SERVO_ON_TEXT + " (switch the servo off at the controller and try again)"
    if isinstance(exc, CommandRejected) and command is p.Command.DGR:
        return "the drive refuses DGR (x): it has no absolute position (an incremental encoder)"
    if isinstance(exc, CommandRejected) and command is p.Command.OWW:
        return ("the drive refused OWW (x): the manual allows it only with the servo off, on an absolute "
                "encoder, and not again before the first acknowledgement")
    return str(exc)


@dataclass(frozen=True)
class Probe:
    """What a drive said when asked (``fha-studio drive probe``); see ``as_dict`` for the keys."""

    driver: str | None
    parameter_access: bool
    documented_only: bool
    servo: str  # "off" | "on" | "unknown"
    encoder: str  # "absolute" | "incremental" | "unknown"
    position_counts: int | None
    position_deg: float | None
    adjusted_for: str | None = None

    def as_dict(self) -> dict[str, Any]:
        return {
            "link": "ok",
            "driver": self.driver,
            "parameter_access": self.parameter_access,
            "documented_only": self.documented_only,
            "servo": self.servo,
            "encoder": self.encoder,
            "position_counts": self.position_counts,
            "position_deg": self.position_deg,
        }

    def lines(self) -> list[str]:
        """The same for a person."""
        servo = {"on": "on (controller): " + SERVO_ON_TEXT.split(": ", 1)[1], "off": "off",
                 "unknown": "not known"}[self.servo]
        out = [
            "link: the drive answers",
            f"driver: {self.driver or 'not reported (the drive has no identification command)'}",
            "parameter access: " + ("yes" if self.parameter_access else "no: use the drive's front panel"),
            "commands: " + ("only the manual's DGR and OWW" if self.documented_only
                            else "the manual's DGR and OWW and FHA Studio's extensions"),
            f"servo: {servo}",
            f"encoder: {self.encoder if self.encoder != 'unknown' else 'not known'}",
        ]
        if self.position_counts is not None:
            out.append("position: " + position_text(self.position_counts, self.position_deg))
        return out


def position_text(counts: int, angle_deg: float | None) -> str:
    multi, single = p.split_absolute_position(counts)
    text = f"{counts} counts (multi-turn {multi}, single-turn {single})"
    if angle_deg is not None:
        text += f" = {angle_deg:.4f}° at the output flange"
    return text


def probe(client: DriveApi, ratio: int | None = None) -> Probe:
    """Ask the drive what it is and where it stands. ``ratio`` scales the position; without it the
    ratio of the actuator the drive says it is adjusted for (IDN) is used, if it says so."""
    caps = client.capabilities
    commands = set(caps.commands)
    driver = adjusted = None
    if p.Command.IDN in commands:
        identity = client.identify()
        if identity is not None:
            driver, adjusted = identity.driver_model, identity.adjusted_for
    ratio = ratio or ratio_of(adjusted)
    servo = "unknown"
    if p.Command.IOS in commands:
        servo = "on" if client.io_state().servo_on else "off"
    counts: int | None = None
    encoder = "unknown"
    try:
        counts = client.absolute_position()
        encoder, servo = "absolute", "off" if servo == "unknown" else servo
    except ServoOnRefused:
        servo = "on"
    except CommandRejected:
        # a drive answers s to everything while the servo is on, so x means: servo off, no DGR
        encoder = "incremental"
        servo = "off" if servo == "unknown" else servo
    return Probe(
        driver=driver,
        parameter_access=bool(caps.parameters),
        documented_only=documented_only(caps),
        servo=servo,
        encoder=encoder,
        position_counts=counts,
        position_deg=None if counts is None or not ratio else output_deg(counts, ratio),
        adjusted_for=adjusted,
    )


@dataclass(frozen=True)
class OriginResult:
    """The OWW wizard's record: position before and after clearing the multi-turn data."""

    before_counts: int
    after_counts: int
    after_deg: float | None
    oww_s: float  # how long the drive took to acknowledge OWW

    def as_dict(self) -> dict[str, Any]:
        return {
            "before_counts": self.before_counts,
            "position_counts": self.after_counts,
            "position_deg": self.after_deg,
            "oww_s": round(self.oww_s, 2),
        }


def set_absolute_origin(client: DriveApi, ratio: int | None = None) -> OriginResult:
    """The absolute-origin steps of the manual: DGR (proves servo off and an absolute encoder),
    OWW (clears the multi-turn data, ``q`` about 5 s later), DGR again (the new position).

    Raises ``ServoOnRefused`` / ``CommandRejected`` (use ``refusal_text``) when the drive says no;
    nothing is cleared then.
    """
    before = client.absolute_position()
    started = time.monotonic()
    client.clear_multiturn()
    took = time.monotonic() - started
    after = client.absolute_position()
    return OriginResult(before, after, None if not ratio else output_deg(after, ratio), took)


# --- checks with DGR while the servo is off (absolute encoders) ---------------------------------

#: How far the counts may differ from the expected change in the encoder check, as a fraction of
#: it: turning by hand to a mark is good to a few percent, a wrong ratio or encoder is off by far more.
ENCODER_CHECK_TOLERANCE = 0.1


@dataclass(frozen=True)
class DgrCheckRecord:
    """One check done with DGR (or answered by the technician where the drive cannot tell).

    ``passed`` None: recorded without a verdict. ``by_hand``: the values were given by the
    technician, not read from the drive (the reason is in ``detail``).
    """

    check: str  # "encoder", "rotary_direction", "sensor_dog", "absolute_origin"
    who: str
    at: str  # ISO 8601 local time
    values: dict[str, Any]
    passed: bool | None
    detail: str
    by_hand: bool = False

    def as_dict(self) -> dict[str, Any]:
        return {"check": self.check, "who": self.who, "at": self.at, "values": dict(self.values),
                "passed": self.passed, "detail": self.detail, "by_hand": self.by_hand}


CHECK_TITLES = {
    "encoder": "Encoder check (turned by hand)",
    "rotary_direction": "Rotary direction (1-10)",
    "sensor_dog": "Sensor dog angle (4-7-2, 4-7-3)",
    "absolute_origin": "Absolute origin (OWW)",
    # a move under the controller seen on CN2 (the Scope's Bench tab): servo on, CN3 silent
    "bench_encoder": "Encoder outputs follow the command (CN2, bench)",
    "bench_direction": "Rotary direction (1-10) as the encoder outputs count it (CN2, bench)",
    "bench_in_position": "IN-POS after a move (CN2-33, bench)",
    "bench_alarm": "ALARM during a move (CN2, bench)",
}


def now_text() -> str:
    return clock.local_iso()


def encoder_check(before: int, after: int, turned_deg: float, ratio: int
                  ) -> tuple[bool, str, dict[str, Any]]:
    """The output was turned by hand by ``turned_deg`` (CW positive seen from the flange): the
    counts must change by ratio x 8192 per motor turn, in the same sense. (passed, detail, values)."""
    expected = counts_for_output_deg(turned_deg, ratio)
    change = after - before
    close = abs(change - expected) <= ENCODER_CHECK_TOLERANCE * abs(expected)
    passed = expected != 0 and change * expected > 0 and close
    seen = output_deg(change, ratio)
    detail = (f"turned {turned_deg:+g}° by hand: the counts changed by {change:+d} ({seen:+.2f}° at the "
              f"output), expected {expected:+.0f} (ratio {ratio} x {p.ABSOLUTE_COUNTS_PER_TURN} counts "
              "per motor turn)")
    if not passed:
        detail += ("; wrong sense: check the encoder wiring (phases) and the model code"
                   if change * expected < 0
                   else "; the size differs by more than 10 %: check the ratio and the encoder")
    return passed, detail, {"before_counts": before, "after_counts": after, "turned_deg": turned_deg,
                            "expected_counts": round(expected), "ratio": ratio}


def turned_sense(change_counts: int) -> str | None:
    """"CW" / "CCW" seen from the output flange for a DGR change (the counts follow the physical
    sense, not the rotary-direction setting); None when it did not turn."""
    if change_counts == 0:
        return None
    return "CW" if change_counts > 0 else "CCW"


def rotary_direction_check(before: int, after: int, parameter_8: int | None, ratio: int | None
                           ) -> tuple[bool | None, str, dict[str, Any]]:
    """FHA-C manual 1-10: a FWD command turns the output CW with parameter 8 = 0 (default), CCW
    with 1. ``before`` / ``after``: DGR with the servo off before and after the controller's short
    FWD command. ``parameter_8`` as entered from the panel (None: not entered, no verdict)."""
    change = after - before
    sense = turned_sense(change)
    values: dict[str, Any] = {"before_counts": before, "after_counts": after, "turned": sense,
                              "rotary_direction": parameter_8}
    angle = f", {output_deg(change, ratio):+.2f}°" if ratio else ""  # one parenthesis, not two nested
    if sense is None:
        return False, ("the position did not change: no FWD command reached the axis (was the servo on? "
                       "did the controller send the command?)"), values
    seen = f"the FWD command turned the output {sense} seen from the flange ({change:+d} counts{angle})"
    if parameter_8 is None:
        return None, seen + "; parameter 8 was not entered, so there is nothing to compare with", values
    expected = "CW" if parameter_8 == 0 else "CCW"
    if sense == expected:
        return True, f"{seen}: as parameter 8 = {parameter_8} says", values
    return False, (f"{seen}, but parameter 8 = {parameter_8} says {expected}: check parameter 8 and "
                   "the motor wiring"), values


def wrap_deg(angle_deg: float) -> float:
    """An output angle folded into -180 ... +180°."""
    return (angle_deg + 180.0) % 360.0 - 180.0
