"""The sensor-dog wizard of the rotary position sensor set (option L), FHA-C manual 4-7-2 and 4-7-3.

The wizard watches the output angle (deg) and the three sensors (limit switch 1 at the CCW end,
limit switch 2 at the CW end, the origin sensor) as the axis moves, remembers the angle where each
sensor switched on, and refuses any move past the movable range of 4-7-3 (from
``resources/procedures/sensor-set.toml``). It does no I/O: the caller feeds it what the drive
reports (:meth:`SensorDogWizard.observe`) and asks it before commanding a move.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any


class Sensor(StrEnum):
    """A sensor of the rotary position sensor set (option L, 4-7), as procedures and session files
    name it."""

    LIMIT_SWITCH_1 = "limit_switch_1"  # at the CCW end
    LIMIT_SWITCH_2 = "limit_switch_2"  # at the CW end
    ORIGIN_SENSOR = "origin_sensor"


SENSORS = tuple(Sensor)
SENSOR_NAMES: dict[str, str] = {
    Sensor.LIMIT_SWITCH_1: "limit switch 1 (CCW end)",
    Sensor.LIMIT_SWITCH_2: "limit switch 2 (CW end)",
    Sensor.ORIGIN_SENSOR: "origin sensor",
}


class MoveRefused(ValueError):
    """A move the wizard will not command: it would pass the movable range (4-7-3)."""


def limits_deg(context: Mapping[str, Any]) -> tuple[float, float]:
    """(CCW limit, CW limit) of the movable range in output degrees, from the actuator's context."""
    sensor_set = context["sensor_set"]
    return float(sensor_set["ccw_limit_deg"]), float(sensor_set["cw_limit_deg"])


def angle_problem(
    sensor: str, angle_deg: float, context: Mapping[str, Any], recorded: Mapping[str, float]
) -> str:
    """Why ``angle_deg`` cannot be the switching angle of ``sensor`` ('' when it can)."""
    ccw, cw = limits_deg(context)
    name = SENSOR_NAMES.get(sensor, sensor)
    if not ccw <= angle_deg <= cw:
        return f"{name} at {angle_deg:+.2f}° is outside the movable range {ccw:+.1f}° … {cw:+.1f}° (4-7-3)"
    ls1, ls2 = recorded.get(Sensor.LIMIT_SWITCH_1), recorded.get(Sensor.LIMIT_SWITCH_2)
    if sensor == Sensor.LIMIT_SWITCH_1 and ls2 is not None and angle_deg >= ls2:
        return f"limit switch 1 (CCW end) at {angle_deg:+.2f}° must be CCW of limit switch 2 at {ls2:+.2f}°"
    if sensor == Sensor.LIMIT_SWITCH_2 and ls1 is not None and angle_deg <= ls1:
        return f"limit switch 2 (CW end) at {angle_deg:+.2f}° must be CW of limit switch 1 at {ls1:+.2f}°"
    if sensor == Sensor.ORIGIN_SENSOR and ls1 is not None and ls2 is not None and not ls1 < angle_deg < ls2:
        return f"the origin at {angle_deg:+.2f}° must lie between the stroke ends {ls1:+.2f}° and {ls2:+.2f}°"
    return ""


@dataclass
class SensorDogWizard:
    """Live state of the dog adjustment: angle, sensor states, switching angles found."""

    ccw_limit_deg: float
    cw_limit_deg: float
    tolerance_deg: float = 2.0
    angle_deg: float | None = None
    states: dict[str, bool] = field(default_factory=lambda: dict.fromkeys(SENSORS, False))
    # Angle where each sensor last switched on, and the direction of travel then (+1 CW, -1 CCW).
    edges_deg: dict[str, float] = field(default_factory=dict)
    edge_direction: dict[str, int] = field(default_factory=dict)
    # The sensor was off at the previous sample: it switched somewhere between the two angles.
    edge_intervals_deg: dict[str, tuple[float, float]] = field(default_factory=dict)

    @classmethod
    def for_context(cls, context: Mapping[str, Any]) -> SensorDogWizard:
        ccw, cw = limits_deg(context)
        tolerance = float(context["sensor_set"].get("test_tolerance_deg", 2.0))
        return cls(ccw_limit_deg=ccw, cw_limit_deg=cw, tolerance_deg=tolerance)

    def observe(self, angle_deg: float, states: Mapping[str, bool]) -> list[Sensor]:
        """Feed one sample; returns the sensors that switched on at it (their angle is remembered)."""
        switched_on = []
        previous = self.angle_deg
        for sensor in SENSORS:
            now = bool(states.get(sensor, False))
            if now and not self.states[sensor]:
                self.edges_deg[sensor] = angle_deg
                low = angle_deg if previous is None else min(previous, angle_deg)
                self.edge_intervals_deg[sensor] = (
                    low,
                    angle_deg if previous is None else max(previous, angle_deg),
                )
                self.edge_direction[sensor] = 0 if previous is None else (1 if angle_deg >= previous else -1)
                switched_on.append(sensor)
            self.states[sensor] = now
        self.angle_deg = angle_deg
        return switched_on

    def check_move(self, target_deg: float) -> None:
        """Raise :class:`MoveRefused` if the output should not be sent to ``target_deg``."""
        if not self.ccw_limit_deg <= target_deg <= self.cw_limit_deg:
            raise MoveRefused(
                f"{target_deg:+.2f}° is past the movable range {self.ccw_limit_deg:+.1f}° … "
                f"{self.cw_limit_deg:+.1f}° (4-7-3): do not overrun beyond the moveable range"
            )

    def check_jog(self, direction: int, margin_deg: float = 1.0) -> None:
        """Raise :class:`MoveRefused` if a jog in ``direction`` (+1 CW, -1 CCW) would leave the range."""
        if self.angle_deg is None:
            raise MoveRefused("the output angle is not known yet: no jog before the drive reports it")
        if direction > 0 and self.angle_deg >= self.cw_limit_deg - margin_deg:
            raise MoveRefused(f"at {self.angle_deg:+.2f}°: a CW jog would pass the movable range (4-7-3)")
        if direction < 0 and self.angle_deg <= self.ccw_limit_deg + margin_deg:
            raise MoveRefused(f"at {self.angle_deg:+.2f}°: a CCW jog would pass the movable range (4-7-3)")

    def clamp_target(self, target_deg: float) -> float:
        """The nearest angle inside the movable range."""
        return min(max(target_deg, self.ccw_limit_deg), self.cw_limit_deg)

    def found(self, sensor: str) -> float | None:
        """Where ``sensor`` last switched on (deg), or None if it has not been seen."""
        return self.edges_deg.get(sensor)

    def test_run_plan(self, recorded: Mapping[str, float]) -> list[float]:
        """Targets (deg) of the test run of 4-7-2 Note 3: CW past limit switch 2, then CCW past switch 1.

        Each target lies ``tolerance_deg`` beyond the recorded angle, clamped to the movable range.
        """
        missing = [SENSOR_NAMES[s] for s in SENSORS if s not in recorded]
        if missing:
            raise MoveRefused(f"no test run before these are recorded: {', '.join(missing)}")
        return [
            self.clamp_target(recorded[Sensor.LIMIT_SWITCH_2] + self.tolerance_deg),
            self.clamp_target(recorded[Sensor.LIMIT_SWITCH_1] - self.tolerance_deg),
        ]

    def test_run_result(
        self, recorded: Mapping[str, float], seen: Mapping[str, Sequence[float | tuple[float, float]]]
    ) -> tuple[bool, str]:
        """Compare the switching angles seen during the test run with the recorded ones.

        ``seen[sensor]`` lists where the sensor switched on during the run: an angle, or the
        interval ``(low, high)`` between the sample where it was still off and the one where it was
        on (so a slow poll does not count as a misplaced sensor). Returns ``(passed, detail)``.
        """
        problems, lines = [], []

        def distance(edge: float | tuple[float, float], want: float) -> float:
            low, high = edge if isinstance(edge, tuple) else (edge, edge)
            return 0.0 if low <= want <= high else min(abs(low - want), abs(high - want))

        def where(edge: float | tuple[float, float]) -> float:
            return edge[-1] if isinstance(edge, tuple) else edge

        for sensor in SENSORS:
            edges = seen.get(sensor, [])
            want = recorded[sensor]
            if not edges:
                problems.append(f"{SENSOR_NAMES[sensor]} never switched on (recorded at {want:+.2f}°)")
                continue
            best = min(edges, key=lambda e: distance(e, want))
            nearest = where(best)
            lines.append(f"{SENSOR_NAMES[sensor]} at {nearest:+.2f}° (recorded {want:+.2f}°)")
            if distance(best, want) > self.tolerance_deg:
                problems.append(
                    f"{SENSOR_NAMES[sensor]} switched at {nearest:+.2f}°, recorded {want:+.2f}° "
                    f"(more than {self.tolerance_deg:g}° apart)"
                )
        return not problems, "; ".join(problems or lines)
